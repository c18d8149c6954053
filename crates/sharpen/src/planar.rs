//! Planar-region projection: after sharpening a swing-decoded CAD mesh, the vertices inside
//! its flat faces still carry the swing angles' quantization noise, which EdgeSharpener
//! leaves alone (it moves only chamfer vertices). This pass finds the regions of nearly
//! parallel triangles, keeps those whose vertices a plane explains as well as a quadratic
//! height field does (noise, not curvature), and moves the vertices inside them onto their
//! least-squares plane. docs/sharpen.md, "Planar-region projection".

use glam::DVec3;
use whet_mesh::{CornerId, CornerTable, Mesh, VertexId};

use crate::Error;
use rayon::prelude::*;

/// Options of [`flatten_planar_regions`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct PlanarOptions {
    /// Largest angle, in degrees, between a triangle's normal and the mean normal of the
    /// region it joins (the region grows from the triangles whose neighbours agree best).
    pub max_normal_angle_degrees: f64,
    /// Largest RMS distance of a region's vertices to its plane, in mean edge lengths of
    /// the mesh (the noise a plane may absorb); the largest distance may be three times it.
    pub tolerance: f64,
    /// Largest share of the plane's residual variance, relative to a quadratic height
    /// field's, that curvature may explain: a region is planar when
    /// `rms_plane^2 - rms_quadric^2 <= curvature_ratio * rms_quadric^2`.
    pub curvature_ratio: f64,
    /// Fewest triangles of a region that is projected (smaller ones cannot tell noise from
    /// curvature).
    pub min_triangles: usize,
}

impl PlanarOptions {
    /// 10 degrees, tolerance 0.1 edge lengths, curvature ratio 0.1, 20 triangles.
    pub const DEFAULT: PlanarOptions = PlanarOptions {
        max_normal_angle_degrees: 10.0,
        tolerance: 0.1,
        curvature_ratio: 0.1,
        min_triangles: 20,
    };

    /// The options with RMS tolerance `tolerance` (mean edge lengths).
    pub const fn with_tolerance(self, tolerance: f64) -> PlanarOptions {
        PlanarOptions { tolerance, ..self }
    }

    /// The options with curvature ratio `curvature_ratio`.
    pub const fn with_curvature_ratio(self, curvature_ratio: f64) -> PlanarOptions {
        PlanarOptions {
            curvature_ratio,
            ..self
        }
    }

    /// The tolerance whet's swing decoder uses for a stream of `angle_bits` angle bits:
    /// `factor` times the angle step `2 pi / 2^bits` (the size, in edge lengths, of the
    /// displacement one quantization step makes).
    pub fn swing_tolerance(angle_bits: u32, factor: f64) -> f64 {
        factor * std::f64::consts::TAU / f64::from(1u32 << angle_bits.min(30))
    }

    /// The options for a swing stream of `angle_bits` angle bits whose header states the
    /// tolerance `factor` (`whet_codec::SharpenHint::planar_of`).
    pub fn for_swing(angle_bits: u32, factor: f64) -> PlanarOptions {
        Self::DEFAULT.with_tolerance(Self::swing_tolerance(angle_bits, factor))
    }

    fn validate(&self) -> Result<(), Error> {
        let ok = self.max_normal_angle_degrees > 0.0
            && self.max_normal_angle_degrees < 90.0
            && self.tolerance >= 0.0
            && self.tolerance.is_finite()
            && self.curvature_ratio >= 0.0
            && self.curvature_ratio.is_finite();
        if ok {
            Ok(())
        } else {
            Err(Error::Parameter(format!(
                "planar projection: angle {} (0..90), tolerance {} and curvature ratio {} \
                 (finite, >= 0)",
                self.max_normal_angle_degrees, self.tolerance, self.curvature_ratio
            )))
        }
    }
}

impl Default for PlanarOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What [`flatten_planar_regions`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct PlanarReport {
    /// Regions grown (every triangle belongs to one).
    pub regions: usize,
    /// Regions found planar.
    pub planar_regions: usize,
    /// Triangles in planar regions.
    pub planar_triangles: usize,
    /// Vertices moved onto a plane.
    pub moved_vertices: usize,
}

/// Moves every vertex whose triangles all lie in one planar region onto that region's
/// least-squares plane (module docs). Boundary vertices and vertices that would move by
/// more than half the mean edge length stay. Fails with [`Error::InvalidInput`] when `mesh`
/// is not an oriented manifold with finite coordinates, [`Error::Parameter`] for options out
/// of range.
pub fn flatten_planar_regions(
    mesh: &mut Mesh,
    opts: &PlanarOptions,
) -> Result<PlanarReport, Error> {
    flatten_planar_regions_in(mesh, opts, None)
}

with_table_entry_point!(
    flatten_planar_regions,
    flatten_planar_regions_with_table,
    flatten_planar_regions_in,
    PlanarOptions,
    PlanarReport
);

fn flatten_planar_regions_in(
    mesh: &mut Mesh,
    opts: &PlanarOptions,
    given: Option<&CornerTable>,
) -> Result<PlanarReport, Error> {
    opts.validate()?;
    let table = table_for(mesh, given)?;
    let p = &mesh.positions;
    let nt = mesh.triangles.len();
    let (normals, area): (Vec<DVec3>, Vec<f64>) = (0..nt)
        .map(|t| {
            let n = mesh.face_cross(t);
            (n.normalize_or_zero(), 0.5 * n.length())
        })
        .unzip();
    let edge = table.mean_edge_length(p);
    let table = &table;
    let neighbours = |t: usize| {
        (0..3).filter_map(move |k| {
            table
                .opposite(CornerId((3 * t + k) as u32))
                .map(|o| o.index() / 3)
        })
    };
    // Seeds: the triangles whose neighbours agree best with them first (a seed on noise
    // would skew its region's mean normal). The agreement, a sum of up to three cosines, is
    // bucketed to 1/1000 (a counting sort: ties, and near-ties, in triangle order).
    const BUCKETS: usize = 6001;
    let bucket: Vec<u16> = (0..nt)
        .map(|t| {
            let s: f64 = neighbours(t).map(|u| normals[t].dot(normals[u])).sum();
            ((3.0 - s) * 1000.0)
                .round()
                .clamp(0.0, (BUCKETS - 1) as f64) as u16
        })
        .collect();
    let mut start = vec![0u32; BUCKETS + 1];
    for &b in &bucket {
        start[b as usize + 1] += 1;
    }
    for k in 0..BUCKETS {
        start[k + 1] += start[k];
    }
    let mut order = vec![0u32; nt];
    for (t, &b) in bucket.iter().enumerate() {
        order[start[b as usize] as usize] = t as u32;
        start[b as usize] += 1;
    }
    const NONE: u32 = u32::MAX;
    let cos_max = opts.max_normal_angle_degrees.to_radians().cos();
    let mut region = vec![NONE; nt];
    let mut planes: Vec<Option<(DVec3, f64)>> = Vec::new();
    let mut report = PlanarReport::default();
    let (mut stack, mut members, mut pts) = (Vec::new(), Vec::new(), Vec::new());
    // The last region each vertex was gathered for.
    let mut gathered = vec![NONE; p.len()];
    for seed in order.into_iter().map(|t| t as usize) {
        if region[seed] != NONE {
            continue;
        }
        let r = planes.len() as u32;
        region[seed] = r;
        let mut sum = normals[seed] * area[seed];
        // The running mean normal, renormalised once per triangle added.
        let mut mean = normals[seed];
        stack.clear();
        stack.push(seed);
        members.clear();
        members.push(seed);
        while let Some(t) = stack.pop() {
            for u in neighbours(t) {
                if region[u] == NONE && normals[u].dot(mean) >= cos_max {
                    region[u] = r;
                    sum += normals[u] * area[u];
                    mean = sum.normalize_or_zero();
                    stack.push(u);
                    members.push(u);
                }
            }
        }
        let normal = sum.normalize_or_zero();
        let mut plane = None;
        if members.len() >= opts.min_triangles && normal != DVec3::ZERO {
            pts.clear();
            for &t in &members {
                for v in mesh.triangles[t] {
                    if gathered[v as usize] != r {
                        gathered[v as usize] = r;
                        pts.push(p[v as usize]);
                    }
                }
            }
            if let Some(fit) = fit_plane(&pts, normal) {
                let tol = opts.tolerance * edge;
                if fit.rms <= tol
                    && fit.max <= 3.0 * tol
                    && fit.rms * fit.rms - fit.quadric_rms * fit.quadric_rms
                        <= opts.curvature_ratio * fit.quadric_rms * fit.quadric_rms
                {
                    plane = Some((fit.normal, fit.offset));
                    report.planar_regions += 1;
                    report.planar_triangles += members.len();
                }
            }
        }
        planes.push(plane);
    }
    report.regions = planes.len();
    let max_move = 0.5 * edge;
    let mut moved = Vec::new();
    'vertices: for v in 0..p.len() {
        let vid = VertexId(v as u32);
        if table.vertex_corner(vid).is_none() || table.is_boundary_vertex(vid) {
            continue;
        }
        let mut only = NONE;
        for c in table.vertex_corners(vid) {
            let r = region[c.index() / 3];
            if (only != NONE && r != only) || planes[r as usize].is_none() {
                continue 'vertices;
            }
            only = r;
        }
        if let Some((n, d)) = planes[only as usize] {
            let q = p[v] - n * (n.dot(p[v]) - d);
            if q.distance(p[v]) <= max_move {
                moved.push((v, q));
            }
        }
    }
    report.moved_vertices = moved.len();
    for (v, q) in moved {
        mesh.positions[v] = q;
    }
    Ok(report)
}

/// The corner table a projection runs on: `given` when it is `mesh`'s (the same
/// triangles; the coordinates are checked again, as a projection before may have moved
/// them), else [`checked_table`]'s.
pub(crate) fn table_for<'t>(
    mesh: &Mesh,
    given: Option<&'t CornerTable>,
) -> Result<std::borrow::Cow<'t, CornerTable>, Error> {
    match given {
        Some(table) if table.triangles() == mesh.triangles.as_slice() => {
            if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
                return Err(Error::InvalidInput(
                    whet_mesh::MeshError::NonFiniteCoordinate { vertex: v as u32 },
                ));
            }
            Ok(std::borrow::Cow::Borrowed(table))
        }
        _ => checked_table(mesh).map(std::borrow::Cow::Owned),
    }
}

/// The vertex ranges a projection's per-vertex pass runs side by side (rayon): a few per
/// thread, at least [`MIN_BLOCK`] vertices each, and no more than [`SCRATCH_BUDGET`]
/// bytes of scratch in all when each block holds `scratch_bytes` (its stamp arrays span
/// the mesh). Every such pass reads the input positions only and moves after it, so
/// splitting the range changes nothing in its result.
fn vertex_blocks(nv: usize, scratch_bytes: usize) -> Vec<std::ops::Range<usize>> {
    let by_memory = (SCRATCH_BUDGET / scratch_bytes.max(1)).max(1);
    let blocks = (4 * rayon::current_num_threads())
        .min(by_memory)
        .clamp(1, nv.div_ceil(MIN_BLOCK).max(1));
    let size = nv.div_ceil(blocks).max(1);
    (0..nv)
        .step_by(size)
        .map(|a| a..(a + size).min(nv))
        .collect()
}

/// A projection's per-vertex pass over [`vertex_blocks`] side by side: each block's report
/// and moves (vertex, new position), in block order. The caller applies the moves
/// ([`apply_moves`]) once the pass, which reads the positions, is done.
pub(crate) fn run_vertex_blocks<R: Send>(
    nv: usize,
    scratch_bytes: usize,
    block: impl Fn(std::ops::Range<usize>) -> (R, Vec<(usize, DVec3)>) + Sync + Send,
) -> Vec<(R, Vec<(usize, DVec3)>)> {
    vertex_blocks(nv, scratch_bytes)
        .into_par_iter()
        .map(block)
        .collect()
}

/// Moves the vertices of `moves` to their new positions; how many there were.
pub(crate) fn apply_moves(positions: &mut [DVec3], moves: Vec<(usize, DVec3)>) -> usize {
    let count = moves.len();
    for (v, q) in moves {
        positions[v] = q;
    }
    count
}

/// A fit's height `h` at its vertex as a step along the vertex's normal, clamped to
/// `max_move`: the step (0 for none) and whether it was clamped. The local quadric and
/// one-sided projections' move.
pub(crate) fn clamped_step(h: f64, max_move: f64) -> (f64, bool) {
    let step = h.clamp(-max_move, max_move);
    (step, step != h)
}

/// Fewest vertices a block of [`vertex_blocks`] holds (the blocks' scratch arrays span the
/// mesh).
const MIN_BLOCK: usize = 2048;

/// Most bytes the blocks of [`vertex_blocks`] hold in scratch together (64 MiB: a mesh of
/// two million triangles still splits five ways).
const SCRATCH_BUDGET: usize = 64 << 20;

/// The corner table of `mesh` for the post-sharpening passes, which need finite
/// coordinates and an oriented manifold: [`Error::InvalidInput`] otherwise.
pub(crate) fn checked_table(mesh: &Mesh) -> Result<CornerTable, Error> {
    if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::InvalidInput(
            whet_mesh::MeshError::NonFiniteCoordinate { vertex: v as u32 },
        ));
    }
    CornerTable::new(mesh).map_err(Error::InvalidInput)
}

/// A plane fit of a region's vertices.
struct PlaneFit {
    /// `normal . x = offset` on the least-squares plane.
    normal: DVec3,
    offset: f64,
    /// RMS and largest residual of the vertices' heights over that plane.
    rms: f64,
    max: f64,
    /// RMS residual of the least-squares quadratic height field.
    quadric_rms: f64,
}

/// Fits, as height fields over the plane through the centroid of `pts` with normal `normal`
/// (the region's mean normal), the least-squares plane `h = d u + e v + f` and the quadratic
/// `h = a u^2 + b uv + c v^2 + d u + e v + f`; `None` when either is undetermined (too few
/// or collinear points). The mean normal alone would not do: a sum of area-weighted normals
/// depends only on the region's border, whose noise would tilt the plane.
fn fit_plane(pts: &[DVec3], normal: DVec3) -> Option<PlaneFit> {
    if pts.len() < 6 {
        return None;
    }
    let centroid = pts.iter().copied().sum::<DVec3>() / pts.len() as f64;
    let (eu, ev) = normal.any_orthonormal_pair();
    let local: Vec<(f64, f64, f64)> = pts
        .iter()
        .map(|&x| {
            let d = x - centroid;
            (d.dot(eu), d.dot(ev), d.dot(normal))
        })
        .collect();
    // Coordinates scaled to about 1 so the normal equations stay well conditioned.
    let scale = local
        .iter()
        .map(|&(u, v, _)| u.abs().max(v.abs()))
        .fold(0.0f64, f64::max);
    if scale.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let basis = |u: f64, v: f64| {
        let (u, v) = (u / scale, v / scale);
        [u * u, u * v, v * v, u, v, 1.0]
    };
    let mut samples = HeightSamples::default();
    for &(u, v, h) in &local {
        samples.add(basis(u, v), h);
    }
    let m = samples.system();
    let coef = solve6(m)?;
    // The plane: the same system with the quadratic terms pinned to zero.
    let mut m_plane = m;
    pin_quadratic_terms(&mut m_plane);
    let lin = solve6(m_plane)?;
    let (mut sq, mut sq_plane, mut max) = (0.0f64, 0.0f64, 0.0f64);
    for &(u, v, h) in &local {
        let b = basis(u, v);
        let f: f64 = b.iter().zip(&coef).map(|(x, c)| x * c).sum();
        sq += (h - f) * (h - f);
        let r = h - (lin[3] * b[3] + lin[4] * b[4] + lin[5]);
        sq_plane += r * r;
        max = max.max(r.abs());
    }
    let n = pts.len() as f64;
    let (rms, quadric_rms) = ((sq_plane / n).sqrt(), (sq / n).sqrt());
    // h = d u + e v + f in unscaled coordinates: tangents eu + (d / scale) normal and
    // ev + (e / scale) normal, whose cross product is the plane's normal.
    let plane_normal = (normal - eu * (lin[3] / scale) - ev * (lin[4] / scale)).normalize_or_zero();
    let on_plane = centroid + normal * lin[5];
    (quadric_rms.is_finite() && rms.is_finite() && plane_normal != DVec3::ZERO).then_some(
        PlaneFit {
            normal: plane_normal,
            offset: plane_normal.dot(on_plane),
            rms,
            max,
            quadric_rms,
        },
    )
}

/// The area-weighted unit normal of each vertex of `mesh` (zero where its triangles' cross
/// products cancel or it has none), as the local quadric and one-sided projections take them.
pub(crate) fn vertex_normals(mesh: &Mesh) -> Vec<DVec3> {
    let mut normals = vec![DVec3::ZERO; mesh.positions.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let c = mesh.face_cross(t);
        for &v in tri {
            normals[v as usize] += c;
        }
    }
    for n in &mut normals {
        *n = n.normalize_or_zero();
    }
    normals
}

/// The least-squares normal equations of a quadratic height field over the basis `[u^2,
/// uv, v^2, u, v, 1]`, as the planar, quadric, one-sided and crease fits all build them,
/// sample by sample. The matrix is symmetric, so only its upper triangle and the right side
/// are summed (27 products a sample instead of 42: the sums were a tenth of `whet decode
/// --sharpen`); [`HeightSamples::system`] mirrors it. Each entry below the diagonal sums the
/// same products as its mirror (`b[j] b[i]` is `b[i] b[j]`), in the same order, so the
/// system is the full one's bit for bit.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct HeightSamples {
    m: [[f64; 7]; 6],
}

impl HeightSamples {
    /// Adds one sample of height `h` with basis values `b`.
    #[inline]
    pub fn add(&mut self, b: [f64; 6], h: f64) {
        for i in 0..6 {
            for j in i..6 {
                self.m[i][j] += b[i] * b[j];
            }
            self.m[i][6] += b[i] * h;
        }
    }

    /// The augmented system (the right side in column 6) for [`solve6`].
    pub fn system(&self) -> [[f64; 7]; 6] {
        let mut m = self.m;
        for i in 1..6 {
            for j in 0..i {
                m[i][j] = m[j][i];
            }
        }
        m
    }
}

/// Pins the quadratic terms of the normal equations `m` (as [`HeightSamples::system`] gives
/// them) to zero, so that [`solve6`] gives the least-squares plane `h = d u + e v + f`.
pub(crate) fn pin_quadratic_terms(m: &mut [[f64; 7]; 6]) {
    for i in 0..3 {
        for (j, x) in m[i].iter_mut().enumerate() {
            *x = if i == j { 1.0 } else { 0.0 };
        }
        for row in m.iter_mut().skip(3) {
            row[i] = 0.0;
        }
    }
}

/// Solves the 6x6 system of augmented matrix `m` by Gaussian elimination with partial
/// pivoting; `None` when it is singular.
pub(crate) fn solve6(mut m: [[f64; 7]; 6]) -> Option<[f64; 6]> {
    let norm = m
        .iter()
        .flat_map(|r| r[..6].iter())
        .fold(0.0f64, |a, x| a.max(x.abs()));
    for col in 0..6 {
        let pivot = (col..6).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        m.swap(col, pivot);
        let d = m[col][col];
        if d.abs().partial_cmp(&(1e-12 * norm)) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        for r in 0..6 {
            if r != col {
                let f = m[r][col] / d;
                for k in col..7 {
                    m[r][k] -= f * m[col][k];
                }
            }
        }
    }
    let mut x = [0.0; 6];
    for i in 0..6 {
        x[i] = m[i][6] / m[i][i];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn height_samples_give_the_full_sums_bit_for_bit() {
        // Every product summed into the full matrix, as the fits summed them before the
        // upper triangle alone was.
        let mut full = [[0.0f64; 7]; 6];
        let mut samples = HeightSamples::default();
        let mut next = crate::crease::tests::noise_source(0x9E37_79B9_7F4A_7C15);
        for _ in 0..500 {
            let (u, v, h) = (next() * 3.0, next() * 1e-3, next());
            let b = [u * u, u * v, v * v, u, v, 1.0];
            for i in 0..6 {
                for j in 0..6 {
                    full[i][j] += b[i] * b[j];
                }
                full[i][6] += b[i] * h;
            }
            samples.add(b, h);
        }
        let system = samples.system();
        for i in 0..6 {
            for j in 0..7 {
                assert_eq!(system[i][j].to_bits(), full[i][j].to_bits(), "{i} {j}");
            }
        }
    }

    /// A `n` x `n` grid of unit cells bent along x into `z = bend * x^2`, its vertices
    /// pushed along z by a deterministic pseudo-random `noise`.
    fn grid(n: usize, bend: f64, noise: f64) -> Mesh {
        let mut positions = Vec::new();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for j in 0..=n {
            for i in 0..=n {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let r = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                let x = i as f64;
                positions.push(DVec3::new(x, j as f64, bend * x * x + noise * r));
            }
        }
        let mut triangles = Vec::new();
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        for j in 0..n {
            for i in 0..n {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        Mesh::new(positions, triangles)
    }

    fn max_abs_z_interior(m: &Mesh, n: usize) -> f64 {
        let mut worst = 0.0f64;
        for j in 1..n {
            for i in 1..n {
                worst = worst.max(m.positions[j * (n + 1) + i].z.abs());
            }
        }
        worst
    }

    #[test]
    fn a_noisy_plane_is_flattened_inside_and_its_boundary_kept() {
        let n = 12;
        let mut m = grid(n, 0.0, 0.06);
        let before = m.clone();
        let opts = PlanarOptions::DEFAULT.with_tolerance(0.1);
        let report = flatten_planar_regions(&mut m, &opts).unwrap();
        assert_eq!(report.planar_regions, 1, "{report:?}");
        assert_eq!(report.moved_vertices, (n - 1) * (n - 1));
        // The noise was up to 0.03; the fitted plane is within its mean of z = 0.
        assert!(max_abs_z_interior(&before, n) > 0.02);
        assert!(
            max_abs_z_interior(&m, n) < 0.01,
            "{}",
            max_abs_z_interior(&m, n)
        );
        // Projection is along the normal only (nearly z): x and y stay within rounding.
        for (a, b) in m.positions.iter().zip(&before.positions) {
            assert!((a.x - b.x).abs() < 1e-3 && (a.y - b.y).abs() < 1e-3);
        }
        // Boundary vertices are untouched, bit for bit.
        for i in 0..=n {
            assert_eq!(m.positions[i], before.positions[i]);
        }
    }

    #[test]
    fn a_tilted_noisy_plane_goes_onto_its_least_squares_plane() {
        // z = 0.05 x + noise: the projection lands within the noise's mean of the true plane
        // (the border's noise would tilt a plane taken from the mean normal alone).
        let n = 14;
        let mut m = grid(n, 0.0, 0.06);
        for p in &mut m.positions {
            p.z += 0.05 * p.x;
        }
        let report = flatten_planar_regions(&mut m, &PlanarOptions::DEFAULT).unwrap();
        assert_eq!(report.moved_vertices, (n - 1) * (n - 1), "{report:?}");
        let unit = DVec3::new(-0.05, 0.0, 1.0).normalize();
        for j in 1..n {
            for i in 1..n {
                let p = m.positions[j * (n + 1) + i];
                assert!(p.dot(unit).abs() < 0.01, "{p}: {}", p.dot(unit));
            }
        }
    }

    #[test]
    fn a_gently_curved_region_is_not_flattened() {
        // z = 0.004 x^2 over 12 cells: the normals turn by 5.5 degrees (one region), the
        // sagitta (0.14 over 12 units, 0.05 RMS about the plane) stays within a tolerance
        // of 0.1, but a quadratic explains it: not planar.
        let n = 12;
        let mut m = grid(n, 0.004, 0.0);
        let before = m.clone();
        let report = flatten_planar_regions(&mut m, &PlanarOptions::DEFAULT).unwrap();
        assert_eq!(report.regions, 1, "{report:?}");
        assert_eq!(report.planar_regions, 0, "{report:?}");
        assert_eq!(m, before);
    }

    #[test]
    fn an_exact_plane_stays_on_itself() {
        let n = 8;
        let mut m = grid(n, 0.0, 0.0);
        let before = m.clone();
        let report = flatten_planar_regions(&mut m, &PlanarOptions::DEFAULT).unwrap();
        assert_eq!(report.planar_regions, 1);
        for (a, b) in m.positions.iter().zip(&before.positions) {
            assert!(a.distance(*b) < 1e-12);
        }
    }

    #[test]
    fn bad_options_and_inputs_are_errors() {
        let mut m = grid(4, 0.0, 0.0);
        for bad in [
            PlanarOptions::DEFAULT.with_tolerance(f64::NAN),
            PlanarOptions::DEFAULT.with_tolerance(-1.0),
            PlanarOptions::DEFAULT.with_curvature_ratio(-0.5),
            PlanarOptions {
                max_normal_angle_degrees: 95.0,
                ..PlanarOptions::DEFAULT
            },
        ] {
            assert!(matches!(
                flatten_planar_regions(&mut m, &bad),
                Err(Error::Parameter(_))
            ));
        }
        m.positions[3].x = f64::INFINITY;
        assert!(matches!(
            flatten_planar_regions(&mut m, &PlanarOptions::DEFAULT),
            Err(Error::InvalidInput(_))
        ));
        let mut nonmanifold = grid(2, 0.0, 0.0);
        let t = nonmanifold.triangles[0];
        nonmanifold.triangles.push(t);
        assert!(matches!(
            flatten_planar_regions(&mut nonmanifold, &PlanarOptions::DEFAULT),
            Err(Error::InvalidInput(_))
        ));
    }

    #[test]
    fn swing_tolerance_is_the_angle_step() {
        let t = PlanarOptions::swing_tolerance(6, 1.0);
        assert!((t - std::f64::consts::TAU / 64.0).abs() < 1e-15);
        assert!(PlanarOptions::swing_tolerance(99, 1.0) > 0.0);
    }
}
