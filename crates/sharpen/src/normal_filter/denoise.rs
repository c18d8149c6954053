//! Two guards in front of seed 002, which assumes a clean, roughly uniform sampling (not in the
//! paper; docs/sharpen.md, "Noise and non-uniform samplings"):
//!
//! - `noisy_share` and `denoise`: when the flat regions are noisy, a feature-preserving
//!   denoising of the whole mesh first, bilateral normal filtering in the style of Sun et al.
//!   2007 ("Fast and effective feature-preserving mesh denoising"): face normals averaged over
//!   the faces sharing a vertex, weighted by `(n_i . n_j - T)^2` where `n_i . n_j > T`, then
//!   least-squares vertex updates towards the filtered normals;
//! - `coarse_share`: the edge-length spread that tells a roughly uniform sampling (where `rho` in
//!   mean edge lengths means something) from a mesh of a few large faces and strips of needles.

use glam::DVec3;

use super::filter::{cross, Rings};

/// A face is "noisy" when even its most similar edge neighbour is this far away (1 - cos; 3
/// degrees). Clean samplings of flat regions have coplanar neighbours almost everywhere.
const NOISY_FACE: f64 = 1.370_465_245_426_58e-3;
/// A face is coarse when its longest edge is longer than this many mean edge lengths.
pub(crate) const COARSE_EDGE: f64 = 8.0;
/// The method refuses meshes whose coarse faces cover more than this share of the surface.
pub(crate) const COARSE_SHARE: f64 = 0.25;
/// The mesh is denoised when more than this share of its faces is noisy.
pub(crate) const NOISY_SHARE: f64 = 0.5;
/// Sun et al.'s normal-difference threshold `T` (dot product): neighbours turned by more than
/// 73 degrees do not take part, so right-angled creases survive. (Measured on the `--noise 0.3`
/// box samplings: 0.2-0.5 all work at 64 cells; at 32, 0.3 is the only value that gains 2x on
/// both rotations.)
const THRESHOLD: f64 = 0.3;
/// Normal-filtering iterations (Sun et al.: `n1`). More rounds round the creases beyond `rho`:
/// on the `--noise 0.3` box at 32 cells, 15 rounds gave 1.7-1.8x, 8-12 rounds 2.0-2.3x.
const NORMAL_ITERATIONS: usize = 10;
/// Vertex-updating iterations (Sun et al.: `n2`).
const VERTEX_ITERATIONS: usize = 30;

/// The share of faces whose most similar edge neighbour is more than 3 degrees away.
pub(crate) fn noisy_share(normals: &[DVec3], nfi: &[[u32; 3]]) -> f64 {
    if normals.is_empty() {
        return 0.0;
    }
    let noisy = normals
        .iter()
        .zip(nfi)
        .filter(|(n, nb)| {
            let best = nb
                .iter()
                .filter(|&&k| k != super::NONE)
                .map(|&k| n.dot(normals[k as usize]))
                .fold(f64::NEG_INFINITY, f64::max);
            best.is_finite() && 1.0 - best > NOISY_FACE
        })
        .count();
    noisy as f64 / normals.len() as f64
}

/// The share of the surface (by area) in faces whose longest edge is longer than
/// `COARSE_EDGE` mean edge lengths `mean_edge`: about 0 on a roughly uniform sampling, most of
/// the surface on a mesh of a few large faces and strips of needles.
pub(crate) fn coarse_share(positions: &[DVec3], tris: &[[u32; 3]], mean_edge: f64) -> f64 {
    let limit2 = (COARSE_EDGE * mean_edge).powi(2);
    let (mut coarse, mut total) = (0.0, 0.0);
    for t in tris {
        let p = t.map(|v| positions[v as usize]);
        let area = cross(p[0], p[1], p[2]).length();
        let longest2 = p[0]
            .distance_squared(p[1])
            .max(p[1].distance_squared(p[2]))
            .max(p[2].distance_squared(p[0]));
        total += area;
        if longest2 > limit2 {
            coarse += area;
        }
    }
    if total > 0.0 {
        coarse / total
    } else {
        0.0
    }
}

/// What denoising did.
pub(crate) struct Denoised {
    /// The filtered face normals (unit), which detection and filtering use in place of the
    /// normals of the moved faces: a marching-cubes sliver's own normal stays arbitrary.
    pub normals: Vec<DVec3>,
}

/// Sun et al.'s denoising: `NORMAL_ITERATIONS` Jacobi rounds of the bilateral normal filter over
/// the faces sharing a vertex with each face (area-weighted, so marching-cubes slivers weigh
/// nothing), then `VERTEX_ITERATIONS` Gauss-Seidel rounds moving each `movable` vertex by the
/// mean of `n_j (n_j . (c_j - x))` over its faces. A step that would leave a face around the
/// vertex facing against its input normal `input_normals`, with `|cross|^2` at most
/// `min_area2`, or newly facing against its filtered normal (a fold the noise did not make),
/// is halved up to three times, else refused.
pub(crate) fn denoise(
    positions: &mut [DVec3],
    tris: &[[u32; 3]],
    rings: &Rings,
    movable: &[bool],
    input_normals: &[DVec3],
    min_area2: f64,
) -> Denoised {
    let nv = positions.len();
    let nt = tris.len();
    let vf = rings.vertex_faces(nv, tris);
    // Faces sharing a vertex with each face (itself included).
    let mut around: Vec<Vec<u32>> = Vec::with_capacity(nt);
    for tri in tris {
        let mut a: Vec<u32> = tri.iter().flat_map(|&v| vf[v as usize].clone()).collect();
        a.sort_unstable();
        a.dedup();
        around.push(a);
    }
    let crosses: Vec<DVec3> = tris
        .iter()
        .map(|t| {
            cross(
                positions[t[0] as usize],
                positions[t[1] as usize],
                positions[t[2] as usize],
            )
        })
        .collect();
    let area: Vec<f64> = crosses.iter().map(|c| c.length()).collect();
    let mut n: Vec<DVec3> = crosses.iter().map(|c| c.normalize_or_zero()).collect();
    let mut next = n.clone();
    for _ in 0..NORMAL_ITERATIONS {
        for i in 0..nt {
            let mut g = DVec3::ZERO;
            for &j in &around[i] {
                g += n[j as usize] * area[j as usize];
            }
            let g = g.normalize_or_zero();
            // An outlier (its own normal more than `T` from the area-weighted mean around it)
            // would only ever average with itself: it is weighed against the mean instead.
            let ni = if g != DVec3::ZERO && n[i].dot(g) < THRESHOLD {
                g
            } else {
                n[i]
            };
            let mut s = DVec3::ZERO;
            for &j in &around[i] {
                let d = ni.dot(n[j as usize]) - THRESHOLD;
                if d > 0.0 {
                    s += n[j as usize] * (area[j as usize] * d * d);
                }
            }
            let s = s.normalize_or_zero();
            next[i] = if s == DVec3::ZERO { ni } else { s };
        }
        std::mem::swap(&mut n, &mut next);
    }
    for _ in 0..VERTEX_ITERATIONS {
        for v in 0..nv {
            if !movable[v] || vf[v].is_empty() {
                continue;
            }
            let x = positions[v];
            let mut delta = DVec3::ZERO;
            for &f in &vf[v] {
                let [a, b, c] = tris[f as usize];
                let centroid =
                    (positions[a as usize] + positions[b as usize] + positions[c as usize]) / 3.0;
                let nf = n[f as usize];
                delta += nf * nf.dot(centroid - x);
            }
            delta /= vf[v].len() as f64;
            if !delta.is_finite() {
                continue;
            }
            let mut gamma = 1.0;
            for _ in 0..4 {
                let y = x + delta * gamma;
                let ok = vf[v].iter().all(|&f| {
                    let t = tris[f as usize];
                    let p = t.map(|w| {
                        if w as usize == v {
                            y
                        } else {
                            positions[w as usize]
                        }
                    });
                    let c = cross(p[0], p[1], p[2]);
                    let nf = n[f as usize];
                    let was = cross(
                        positions[t[0] as usize],
                        positions[t[1] as usize],
                        positions[t[2] as usize],
                    );
                    c.length_squared() > min_area2
                        && c.dot(input_normals[f as usize]) > 0.0
                        && (c.dot(nf) > 0.0 || c.dot(nf) >= was.dot(nf))
                });
                if ok {
                    positions[v] = y;
                    break;
                }
                gamma *= 0.5;
            }
        }
    }
    Denoised { normals: n }
}
