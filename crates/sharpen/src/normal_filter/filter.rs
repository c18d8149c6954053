//! Pre-smoothing, greedy normal filtering and normal rectifying (sharpening-extras.md
//! A.3-A.5).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use glam::DVec3;

use super::detect::Flood;
use super::{Geo, NONE};

/// Two edge neighbours "agree" for rectifying when their normals are within 15 degrees (A.5,
/// a reconstruction: the paper says "almost the same").
const RECTIFY_AGREE: f64 = 0.965_925_826_289_068_3; // cos 15 degrees

/// A face is rectified at most this many times (the pass then ends whatever the input).
const RECTIFY_MAX_PER_FACE: u8 = 2;

/// Vertex rings in CSR form: the neighbours of `v` are `list[start[v]..start[v + 1]]`.
pub(crate) struct Rings {
    pub start: Vec<u32>,
    pub list: Vec<u32>,
}

impl Rings {
    pub fn new(tris: &[[u32; 3]], vertex_count: usize) -> Rings {
        let mut start = vec![0u32; vertex_count + 1];
        for t in tris {
            for &v in t {
                start[v as usize + 1] += 2;
            }
        }
        for v in 0..vertex_count {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut list = vec![0u32; start[vertex_count] as usize];
        for t in tris {
            for k in 0..3 {
                let v = t[k] as usize;
                for w in [t[(k + 1) % 3], t[(k + 2) % 3]] {
                    list[fill[v] as usize] = w;
                    fill[v] += 1;
                }
            }
        }
        // Sort and deduplicate each ring in place, then compact.
        let mut out = Vec::with_capacity(list.len() / 2 + 1);
        let mut new_start = vec![0u32; vertex_count + 1];
        for v in 0..vertex_count {
            let seg = &mut list[start[v] as usize..start[v + 1] as usize];
            seg.sort_unstable();
            let mut last = NONE;
            for &w in seg.iter() {
                if w != last {
                    out.push(w);
                    last = w;
                }
            }
            new_start[v + 1] = out.len() as u32;
        }
        Rings {
            start: new_start,
            list: out,
        }
    }

    #[inline]
    pub fn of(&self, v: usize) -> &[u32] {
        &self.list[self.start[v] as usize..self.start[v + 1] as usize]
    }

    /// The triangles around each vertex (for the vertex updates), sized by the rings.
    pub fn vertex_faces(&self, nv: usize, tris: &[[u32; 3]]) -> Vec<Vec<u32>> {
        let mut vf: Vec<Vec<u32>> = (0..nv)
            .map(|v| Vec::with_capacity(self.of(v).len()))
            .collect();
        for (t, tri) in tris.iter().enumerate() {
            for &v in tri {
                vf[v as usize].push(t as u32);
            }
        }
        vf
    }
}

/// `ceil(4 L / rho)` Jacobi steps of Kobbelt's umbrella bilaplacian on the `movable` vertices
/// (A.3): `p -= U2(p) / nu(p)`. A step that would turn a face by 90 degrees or more (from its
/// previous or its input normal), or take its area to (almost) zero, is undone for that face's
/// vertices. Returns the vertices moved.
pub(crate) fn presmooth(
    positions: &mut [DVec3],
    tris: &[[u32; 3]],
    rings: &Rings,
    movable: &[bool],
    iterations: usize,
    min_area2: f64,
    input_normals: &[DVec3],
) -> usize {
    let nv = positions.len();
    let active: Vec<u32> = (0..nv as u32)
        .filter(|&v| movable[v as usize] && !rings.of(v as usize).is_empty())
        .collect();
    if active.is_empty() || iterations == 0 {
        return 0;
    }
    // U is needed at the movable vertices and at their neighbours.
    let mut need = vec![false; nv];
    for &v in &active {
        need[v as usize] = true;
        for &w in rings.of(v as usize) {
            need[w as usize] = true;
        }
    }
    let touched_faces: Vec<usize> = (0..tris.len())
        .filter(|&t| tris[t].iter().any(|&v| movable[v as usize]))
        .collect();
    let mut u = vec![DVec3::ZERO; nv];
    let mut moved = vec![false; nv];
    for _ in 0..iterations {
        for v in 0..nv {
            if need[v] {
                let r = rings.of(v);
                if !r.is_empty() {
                    let mean =
                        r.iter().map(|&w| positions[w as usize]).sum::<DVec3>() / r.len() as f64;
                    u[v] = mean - positions[v];
                }
            }
        }
        let old: Vec<DVec3> = active.iter().map(|&v| positions[v as usize]).collect();
        for &v in &active {
            let r = rings.of(v as usize);
            let n = r.len() as f64;
            let u2 = r.iter().map(|&w| u[w as usize]).sum::<DVec3>() / n - u[v as usize];
            let nu = 1.0
                + r.iter()
                    .map(|&w| 1.0 / rings.of(w as usize).len() as f64)
                    .sum::<f64>()
                    / n;
            let p = positions[v as usize] - u2 / nu;
            if p.is_finite() {
                positions[v as usize] = p;
            }
        }
        // Undo the step around faces it would fold or flatten (a few rounds, then all of it).
        let before = |v: u32, positions: &[DVec3]| -> DVec3 {
            match active.binary_search(&v) {
                Ok(k) => old[k],
                Err(_) => positions[v as usize],
            }
        };
        let mut clean = false;
        for _ in 0..8 {
            let mut undo = Vec::new();
            for &t in &touched_faces {
                let [a, b, c] = tris[t];
                let now = cross(
                    positions[a as usize],
                    positions[b as usize],
                    positions[c as usize],
                );
                let was = cross(
                    before(a, positions),
                    before(b, positions),
                    before(c, positions),
                );
                if now.dot(was) <= 0.0
                    || now.dot(input_normals[t]) <= 0.0
                    || now.length_squared() <= min_area2
                {
                    undo.extend([a, b, c]);
                }
            }
            if undo.is_empty() {
                clean = true;
                break;
            }
            for v in undo {
                if let Ok(k) = active.binary_search(&v) {
                    positions[v as usize] = old[k];
                }
            }
        }
        if !clean {
            for (k, &v) in active.iter().enumerate() {
                positions[v as usize] = old[k];
            }
        }
        for (k, &v) in active.iter().enumerate() {
            if positions[v as usize] != old[k] {
                moved[v as usize] = true;
            }
        }
    }
    moved.iter().filter(|&&m| m).count()
}

#[inline]
pub(crate) fn cross(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    (b - a).cross(c - a)
}

/// The cost key of a non-negative cost: its bits order like the value.
#[inline]
fn key(cost: f64) -> u64 {
    (cost.max(0.0) + 0.0).to_bits()
}

/// `C(i)` and `m` (A.4): the smallest `1 - n_i . n_j` over the edge neighbours `j` of `i` that
/// are not in `FFt`, and the neighbour attaining it; `None` for `+inf`.
fn cost(i: usize, geo: &Geo, normals: &[DVec3], in_fft: &[bool], eta: f64) -> Option<(f64, u32)> {
    let ni = normals[i];
    let mut best: Option<(f64, u32)> = None;
    for &j in &geo.nfi[i] {
        if j == NONE || in_fft[j as usize] {
            continue;
        }
        let d = ni.dot(normals[j as usize]);
        if d <= eta {
            continue;
        }
        let c = (1.0 - d).max(0.0) + 0.0;
        if best.is_none_or(|(b, bj)| c < b || (c == b && j < bj)) {
            best = Some((c, j));
        }
    }
    best
}

/// What the greedy pass did.
pub(crate) struct Filtered {
    /// Faces that received a filtered normal.
    pub adjusted: Vec<bool>,
    pub count: usize,
}

/// The greedy normal filter (A.4): every feature face, cheapest first, takes
/// `normalize(sum h_k n_k)` over `k` in `NFII(m) \ FFt` (flooded with the current normals),
/// `h_k = (n_m . n_k - eta)^2` when `n_m . n_k > eta`, and leaves `FFt`; its edge neighbours
/// still in `FFt` are re-keyed. Faces never reached keep their normals and stay flagged in
/// `in_fft`.
pub(crate) fn filter(
    geo: &Geo,
    normals: &mut [DVec3],
    in_fft: &mut [bool],
    rho2: f64,
    eta: f64,
    lambda: f64,
) -> Filtered {
    let nt = normals.len();
    let mut keys = vec![u64::MAX; nt];
    let mut heap: BinaryHeap<Reverse<(u64, u32)>> = BinaryHeap::new();
    for i in 0..nt {
        if in_fft[i] {
            if let Some((c, _)) = cost(i, geo, normals, in_fft, eta) {
                keys[i] = key(c);
                heap.push(Reverse((keys[i], i as u32)));
            }
        }
    }
    let mut flood = Flood::new(nt);
    let mut adjusted = vec![false; nt];
    let mut count = 0;
    while let Some(Reverse((k, i))) = heap.pop() {
        let i = i as usize;
        if !in_fft[i] || keys[i] != k {
            continue;
        }
        let Some((_, m)) = cost(i, geo, normals, in_fft, eta) else {
            continue;
        };
        let nm = normals[m as usize];
        flood.nfii(m, geo, normals, rho2, lambda);
        let mut sum = DVec3::ZERO;
        for &f in &flood.faces {
            if in_fft[f as usize] {
                continue;
            }
            let nk = normals[f as usize];
            let d = nm.dot(nk) - eta;
            if d > 0.0 {
                sum += nk * (d * d);
            }
        }
        let n = sum.normalize_or_zero();
        normals[i] = if n == DVec3::ZERO { nm } else { n };
        in_fft[i] = false;
        adjusted[i] = true;
        count += 1;
        for &j in &geo.nfi[i] {
            if j == NONE || !in_fft[j as usize] {
                continue;
            }
            if let Some((c, _)) = cost(j as usize, geo, normals, in_fft, eta) {
                let kj = key(c);
                if kj != keys[j as usize] {
                    keys[j as usize] = kj;
                    heap.push(Reverse((kj, j)));
                }
            }
        }
    }
    Filtered { adjusted, count }
}

/// The rectifying candidate of face `i` (A.5): an adjusted face whose normal is under `eta`
/// against two edge neighbours that agree with each other; returns the cost `1 - n_i . n_j`
/// and `j`, the closer of the two (the cheapest pair).
fn rectify_candidate(i: usize, geo: &Geo, normals: &[DVec3], eta: f64) -> Option<(f64, u32)> {
    let ni = normals[i];
    let nb = geo.nfi[i];
    let mut best: Option<(f64, u32)> = None;
    for a in 0..3 {
        for b in a + 1..3 {
            let (j, k) = (nb[a], nb[b]);
            if j == NONE || k == NONE {
                continue;
            }
            let (nj, nk) = (normals[j as usize], normals[k as usize]);
            let (dj, dk) = (ni.dot(nj), ni.dot(nk));
            if nj.dot(nk) >= RECTIFY_AGREE && dj < eta && dk < eta {
                let (d, f) = if dj >= dk { (dj, j) } else { (dk, k) };
                let c = (1.0 - d).max(0.0) + 0.0;
                if best.is_none_or(|(bc, _)| c < bc) {
                    best = Some((c, f));
                }
            }
        }
    }
    best
}

/// Normal rectifying (A.5), cheapest first; returns the number of normals replaced.
pub(crate) fn rectify(geo: &Geo, normals: &mut [DVec3], adjusted: &[bool], eta: f64) -> usize {
    let nt = normals.len();
    let mut heap: BinaryHeap<Reverse<(u64, u32)>> = BinaryHeap::new();
    let mut times = vec![0u8; nt];
    for i in 0..nt {
        if adjusted[i] {
            if let Some((c, _)) = rectify_candidate(i, geo, normals, eta) {
                heap.push(Reverse((key(c), i as u32)));
            }
        }
    }
    let mut count = 0;
    while let Some(Reverse((k, i))) = heap.pop() {
        let i = i as usize;
        if times[i] >= RECTIFY_MAX_PER_FACE {
            continue;
        }
        let Some((c, j)) = rectify_candidate(i, geo, normals, eta) else {
            continue;
        };
        if key(c) != k {
            heap.push(Reverse((key(c), i as u32)));
            continue;
        }
        normals[i] = normals[j as usize];
        times[i] += 1;
        count += 1;
        for &f in &geo.nfi[i] {
            if f != NONE && adjusted[f as usize] && times[f as usize] < RECTIFY_MAX_PER_FACE {
                if let Some((c, _)) = rectify_candidate(f as usize, geo, normals, eta) {
                    heap.push(Reverse((key(c), f)));
                }
            }
        }
    }
    count
}
