//! Deterministic surface sampling: area-uniform face samples, edge samples, vertex samples.
//!
//! * **Faces**: `n` samples are spread over the triangles in proportion to area by systematic
//!   sampling — the cumulative area is cut at `n` equally spaced positions with one random
//!   offset, so triangle `t` receives `floor` or `ceil` of `n * area_t / total` samples and the
//!   counts add up to exactly `n`. Inside a triangle each point is uniform (the square-root
//!   trick). The plain average over these samples is therefore an area-weighted average with
//!   much less variance than independent Monte Carlo placement. If the total area is zero (or
//!   overflows), every triangle gets the same weight, so nothing divides by zero.
//! * **Edges**: `n` evenly spaced points along the edges, spread in proportion to length
//!   with the remainder carried from edge to edge (vcglib's `EdgeUniform`, which MeshLab's
//!   Hausdorff filter uses), and at least the midpoint of every edge; see `EdgePlan`.
//! * **Vertices**: every vertex referenced by a triangle.
//!
//! Random numbers come from [`SplitMix64`] streams seeded per fixed-size chunk of triangles,
//! so the sample set depends only on the seed, never on how many threads process the chunks.

use glam::DVec3;
use rayon::prelude::*;
use whet_mesh::Mesh;

/// Triangles per face-sampling chunk (one random stream each).
pub(crate) const FACE_CHUNK: usize = 1024;
/// Edges per edge-sampling chunk.
pub(crate) const EDGE_CHUNK: usize = 4096;
/// Vertices per vertex-sampling chunk.
pub(crate) const VERTEX_CHUNK: usize = 4096;

/// SplitMix64 (Steele, Lea, Flood 2014): a tiny, fast, statistically good 64-bit generator,
/// used here so the samples are reproducible without an external RNG crate.
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator starting from `seed`.
    pub fn new(seed: u64) -> Self {
        SplitMix64 { state: seed }
    }

    /// The next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix64(self.state)
    }

    /// A uniform `f64` in `[0, 1)` (53 random bits).
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// The SplitMix64 output function (a strong 64-bit mixer).
#[inline]
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Seed of stream `stream` derived from `seed`.
#[inline]
pub(crate) fn derive_seed(seed: u64, stream: u64) -> u64 {
    mix64(seed ^ mix64(stream.wrapping_add(0x6A09_E667_F3BC_C909)))
}

/// Uniform point in the triangle `a b c` from two uniform numbers in `[0, 1)`.
#[inline]
pub fn uniform_in_triangle(a: DVec3, b: DVec3, c: DVec3, r1: f64, r2: f64) -> DVec3 {
    let s = r1.sqrt();
    a + (b - a) * (s * (1.0 - r2)) + (c - a) * (s * r2)
}

/// Sum of `f` over `0..n` computed in fixed chunks and added in chunk order, so the result is
/// the same for any number of threads.
fn deterministic_sum(n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    let parts: Vec<f64> = (0..n.div_ceil(4096))
        .into_par_iter()
        .map(|c| (c * 4096..((c + 1) * 4096).min(n)).map(&f).sum::<f64>())
        .collect();
    parts.iter().sum()
}

/// Area of triangle `t` (the mesh must be validated).
#[inline]
fn area(mesh: &Mesh, t: usize) -> f64 {
    let [a, b, c] = mesh.triangle_positions(t);
    0.5 * (b - a).cross(c - a).length()
}

/// Where each triangle's face samples start: `offsets[t]..offsets[t + 1]` are the indices of
/// the samples of triangle `t`, and `offsets[len]` is `n`. Systematic sampling over the
/// cumulative area with a random offset from `seed`.
pub(crate) fn face_sample_offsets(mesh: &Mesh, n: usize, seed: u64) -> Vec<usize> {
    let t_count = mesh.triangles.len();
    let areas: Vec<f64> = (0..t_count)
        .into_par_iter()
        .map(|t| area(mesh, t))
        .collect();
    let total: f64 = areas.iter().sum();
    let uniform = !(total > 0.0 && total.is_finite());
    let total = if uniform { t_count as f64 } else { total };
    let u = SplitMix64::new(derive_seed(seed, 0xFACE)).next_f64();
    let nf = n as f64;
    let mut offsets = Vec::with_capacity(t_count + 1);
    offsets.push(0usize);
    let mut cum = 0.0;
    let mut prev = 0usize;
    for (t, a) in areas.iter().enumerate() {
        cum += if uniform { 1.0 } else { *a };
        let g = if t + 1 == t_count {
            n
        } else {
            // cum <= total, so the ratio is <= 1; the clamp and the running maximum keep the
            // offsets monotone and within n whatever the rounding.
            ((nf * (cum / total) + u).floor() as usize).clamp(prev, n)
        };
        offsets.push(g);
        prev = g;
    }
    offsets
}

/// "No triangle".
pub(crate) const NONE: u32 = u32::MAX;

/// Every undirected edge once, sorted by (low, high) vertex index (coherent for the
/// queries), with the lowest-numbered triangle that has it. A bucket sort by low vertex, so
/// linear in the mesh size. The mesh must be validated.
pub(crate) fn unique_edges(mesh: &Mesh) -> (Vec<[u32; 2]>, Vec<u32>) {
    let nv = mesh.positions.len();
    // Half-edges per low vertex (counting sort in triangle order, so each bucket lists its
    // triangles in increasing order).
    let mut start = vec![0u32; nv + 1];
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b {
                start[a.min(b) as usize + 1] += 1;
            }
        }
    }
    for v in 0..nv {
        start[v + 1] += start[v];
    }
    let mut cursor = start.clone();
    let mut slots = vec![(0u32, 0u32); start[nv] as usize];
    for (ti, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b {
                let c = &mut cursor[a.min(b) as usize];
                slots[*c as usize] = (a.max(b), ti as u32);
                *c += 1;
            }
        }
    }
    drop(cursor);
    // Per bucket: sort by high vertex (stable: the lowest triangle comes first) and dedup.
    let parts: Vec<(Vec<[u32; 2]>, Vec<u32>)> = (0..nv.div_ceil(4096))
        .into_par_iter()
        .map(|chunk| {
            let mut edges = Vec::new();
            let mut tris = Vec::new();
            let mut bucket = Vec::new();
            for v in chunk * 4096..((chunk + 1) * 4096).min(nv) {
                bucket.clear();
                bucket.extend_from_slice(&slots[start[v] as usize..start[v + 1] as usize]);
                bucket.sort_by_key(|&(hi, _)| hi);
                let mut last = NONE;
                for &(hi, t) in &bucket {
                    if hi != last {
                        edges.push([v as u32, hi]);
                        tris.push(t);
                        last = hi;
                    }
                }
            }
            (edges, tris)
        })
        .collect();
    let total = parts.iter().map(|p| p.0.len()).sum();
    let mut edges = Vec::with_capacity(total);
    let mut tris = Vec::with_capacity(total);
    for (e, t) in parts {
        edges.extend(e);
        tris.extend(t);
    }
    (edges, tris)
}

/// Layout of the edge samples (vcglib's `EdgeUniform`, as used by MeshLab's Hausdorff
/// filter): `n` samples spread along the edges in proportion to length, with spacing
/// `total edge length / n`. Walking the edges in sorted order, an edge of length `len` gets
/// `k = floor((len + rest) / spacing)` evenly spaced interior samples and passes the
/// remainder `rest` on to the next edge, so the total is `n` (up to rounding). Unlike vcglib,
/// an edge that would get none still gets its midpoint, so every edge is probed even when
/// `n` is below the number of edges (the total then stays below `n` plus the edge count).
#[derive(Clone, Debug)]
pub(crate) struct EdgePlan {
    spacing: f64,
    /// Remainder carried into the first edge of each chunk of [`EDGE_CHUNK`] edges.
    chunk_rest: Vec<f64>,
}

impl EdgePlan {
    pub(crate) fn new(mesh: &Mesh, edges: &[[u32; 2]], n: usize) -> EdgePlan {
        let length =
            |e: &[u32; 2]| mesh.positions[e[0] as usize].distance(mesh.positions[e[1] as usize]);
        let total_len = deterministic_sum(edges.len(), |e| length(&edges[e]));
        let spacing = total_len / n.max(1) as f64;
        let spacing = if spacing > 0.0 && spacing.is_finite() {
            spacing
        } else {
            0.0
        };
        let mut chunk_rest = Vec::with_capacity(edges.len().div_ceil(EDGE_CHUNK));
        let mut rest = 0.0;
        for (i, e) in edges.iter().enumerate() {
            if i % EDGE_CHUNK == 0 {
                chunk_rest.push(rest);
            }
            (_, rest) = edge_step(length(e), rest, spacing);
        }
        EdgePlan {
            spacing,
            chunk_rest,
        }
    }

    /// Calls `f(e, p)` with every sample `p` of the edges of chunk `chunk` (`edges` are that
    /// chunk's, `e` indexes them).
    #[inline]
    pub(crate) fn for_each_sample(
        &self,
        mesh: &Mesh,
        chunk: usize,
        edges: &[[u32; 2]],
        mut f: impl FnMut(usize, DVec3),
    ) {
        let mut rest = self.chunk_rest.get(chunk).copied().unwrap_or(0.0);
        for (j, e) in edges.iter().enumerate() {
            let (a, b) = (mesh.positions[e[0] as usize], mesh.positions[e[1] as usize]);
            let (k, r) = edge_step(a.distance(b), rest, self.spacing);
            rest = r;
            let step = 1.0 / (k as f64 + 1.0);
            for i in 1..=k {
                f(j, a + (b - a) * (i as f64 * step));
            }
        }
    }
}

/// One edge of the carried-remainder walk: (interior samples, remainder passed on).
#[inline]
fn edge_step(len: f64, rest: f64, spacing: f64) -> (usize, f64) {
    if spacing.is_nan() || spacing <= 0.0 {
        return (1, 0.0);
    }
    let k = ((len + rest) / spacing).floor();
    let r = (len + rest) - k * spacing;
    // The float-to-int cast saturates; k <= total / spacing = n up to rounding.
    ((k as usize).max(1), r.max(0.0))
}

/// For every vertex the lowest-numbered triangle using it, [`NONE`] for an unreferenced
/// vertex (the mesh must be validated).
pub(crate) fn vertex_triangles(mesh: &Mesh) -> Vec<u32> {
    let mut tri = vec![NONE; mesh.positions.len()];
    for (t, corners) in mesh.triangles.iter().enumerate().rev() {
        for &v in corners {
            tri[v as usize] = t as u32;
        }
    }
    tri
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strip(n: usize) -> Mesh {
        // Triangles of very different areas, including zero-area ones.
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..n {
            let x = i as f64;
            let h = if i % 7 == 3 {
                0.0
            } else {
                1.0 + (i % 5) as f64
            };
            let base = positions.len() as u32;
            positions.extend([
                DVec3::new(x, 0.0, 0.0),
                DVec3::new(x + 1.0, 0.0, 0.0),
                DVec3::new(x, h, 0.0),
            ]);
            triangles.push([base, base + 1, base + 2]);
        }
        Mesh::new(positions, triangles)
    }

    #[test]
    fn face_counts_are_floor_or_ceil_and_sum_to_n() {
        let mesh = strip(200);
        let total = mesh.area();
        for n in [0, 1, 7, 1000, 12345] {
            for seed in 0..5 {
                let off = face_sample_offsets(&mesh, n, seed);
                assert_eq!(off.len(), 201);
                assert_eq!(off[200], n);
                for t in 0..200 {
                    let k = off[t + 1] - off[t];
                    let want = n as f64 * mesh.face_area(t) / total;
                    assert!(
                        k as f64 >= want.floor() - 1e-9 && k as f64 <= want.ceil() + 1e-9,
                        "n {n} t {t}: {k} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn zero_area_mesh_gets_uniform_counts() {
        let mesh = Mesh::new(vec![DVec3::ZERO, DVec3::X], vec![[0, 1, 1], [1, 0, 0]]);
        let off = face_sample_offsets(&mesh, 10, 3);
        assert_eq!(off, vec![0, 5, 10]);
        let (edges, tris) = unique_edges(&mesh);
        assert_eq!(
            (edges.as_slice(), tris.as_slice()),
            (&[[0, 1]][..], &[0][..])
        );
        let plan = EdgePlan::new(&mesh, &edges, 10);
        let mut pts = Vec::new();
        plan.for_each_sample(&mesh, 0, &edges, |_, p| pts.push(p.x));
        // Spacing 0.1 on a unit edge: 10 interior points (9 if 1 / 0.1 rounds below 10).
        assert!(pts.len() == 10 || pts.len() == 9, "{pts:?}");
        // All vertices at one point: no length, one midpoint per edge.
        let point = Mesh::new(vec![DVec3::ONE; 3], vec![[0, 1, 2]]);
        let (edges, _) = unique_edges(&point);
        let plan = EdgePlan::new(&point, &edges, 10);
        let mut count = 0;
        plan.for_each_sample(&point, 0, &edges, |_, p| {
            assert_eq!(p, DVec3::ONE);
            count += 1;
        });
        assert_eq!(count, 3);
    }

    #[test]
    fn unique_edges_matches_a_sort() {
        let mesh = Mesh::new(
            vec![DVec3::ZERO; 6],
            vec![[0, 1, 2], [2, 1, 3], [3, 3, 4], [5, 0, 2], [1, 0, 2]],
        );
        let (edges, tris) = unique_edges(&mesh);
        assert_eq!(
            edges,
            vec![
                [0, 1],
                [0, 2],
                [0, 5],
                [1, 2],
                [1, 3],
                [2, 3],
                [2, 5],
                [3, 4]
            ]
        );
        assert_eq!(tris, vec![0, 0, 3, 0, 1, 1, 3, 2]);
        assert_eq!(vertex_triangles(&mesh), vec![0, 0, 0, 1, 2, 3]);
        let lonely = Mesh::new(vec![DVec3::ZERO; 4], vec![[0, 1, 2]]);
        assert_eq!(vertex_triangles(&lonely), vec![0, 0, 0, NONE]);
    }

    #[test]
    fn uniform_in_triangle_stays_inside() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let mut rng = SplitMix64::new(1);
        let mut mean = DVec3::ZERO;
        let n = 100_000;
        for _ in 0..n {
            let p = uniform_in_triangle(a, b, c, rng.next_f64(), rng.next_f64());
            assert!(p.x >= 0.0 && p.y >= 0.0 && p.x + p.y <= 1.0 + 1e-15);
            mean += p;
        }
        mean /= n as f64;
        // Uniform in the triangle: the mean is the centroid.
        assert!((mean - DVec3::new(1.0 / 3.0, 1.0 / 3.0, 0.0)).length() < 5e-3);
    }

    #[test]
    fn edge_samples_total_n_and_are_interior() {
        let mesh = strip(300);
        let (edges, _) = unique_edges(&mesh);
        assert_eq!(edges.len(), 900);
        for n in [10_000, 100_000] {
            let plan = EdgePlan::new(&mesh, &edges, n);
            let mut count = 0;
            for (c, chunk) in edges.chunks(EDGE_CHUNK).enumerate() {
                plan.for_each_sample(&mesh, c, chunk, |_, p| {
                    assert!(p.is_finite());
                    count += 1;
                });
            }
            // n, up to one sample lost to rounding, plus the midpoints of the 43 zero-length
            // edges (of the zero-height triangles), which get no share of n.
            assert!(count + 1 >= n + 43 && count <= n + 43, "{count} vs {n}");
        }
        // Fewer samples than edges: every edge still gets its midpoint.
        let plan = EdgePlan::new(&mesh, &edges, 10);
        let mut pts = Vec::new();
        plan.for_each_sample(&mesh, 0, &edges, |_, p| pts.push(p));
        assert_eq!(pts.len(), edges.len());
        for (p, e) in pts.iter().zip(&edges) {
            let mid = (mesh.positions[e[0] as usize] + mesh.positions[e[1] as usize]) * 0.5;
            assert!(p.distance(mid) < 1e-12);
        }
    }
}
