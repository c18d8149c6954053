//! Feature detection (sharpening-extras.md A.1-A.2): the bounded, crease-stopping neighbourhood
//! `NFII(i)` and the normal-variation test `S(i) < eta`.

use glam::DVec3;

use super::{Geo, NONE};

/// The flood crosses an edge when `n_s . n_k > lambda + LAMBDA_SLACK`: with the paper's
/// `lambda = 0`, an exactly right-angled crease (dot product 0 up to rounding, either sign)
/// must stop it.
const LAMBDA_SLACK: f64 = 1e-9;

/// Breadth-first flood for `NFII`, with a generation-stamped visited mark so nothing is cleared
/// between faces.
pub(crate) struct Flood {
    mark: Vec<u32>,
    generation: u32,
    /// The faces of the last flood, in visiting order (the first is the seed face).
    pub faces: Vec<u32>,
}

impl Flood {
    pub fn new(face_count: usize) -> Flood {
        Flood {
            mark: vec![0; face_count],
            generation: 0,
            faces: Vec::with_capacity(256),
        }
    }

    /// `NFII(i)` into `self.faces` (A.1): from `f_i`, take an edge neighbour `f_k` of a taken
    /// face `f_s` when `d(c_i, f_k) < rho` (squared: `rho2`; `d` the smallest distance from
    /// `c_i` to the corners and centroid of `f_k`) and `n_s . n_k > lambda`.
    pub fn nfii(&mut self, i: u32, geo: &Geo, normals: &[DVec3], rho2: f64, lambda: f64) {
        if self.generation == u32::MAX {
            self.mark.iter_mut().for_each(|m| *m = 0);
            self.generation = 0;
        }
        self.generation += 1;
        let g = self.generation;
        let center = geo.centroids[i as usize];
        self.faces.clear();
        self.faces.push(i);
        self.mark[i as usize] = g;
        let mut head = 0;
        while head < self.faces.len() {
            let s = self.faces[head] as usize;
            head += 1;
            let ns = normals[s];
            for &k in &geo.nfi[s] {
                if k == NONE || self.mark[k as usize] == g {
                    continue;
                }
                if ns.dot(normals[k as usize]) > lambda + LAMBDA_SLACK
                    && geo.dist2(center, k) < rho2
                {
                    self.mark[k as usize] = g;
                    self.faces.push(k);
                }
            }
        }
    }
}

/// `S(i) < eta` on the faces of `flood.faces` (A.2), `S` the smallest dot product of two of
/// their normals. When every normal is within angle `t` of the seed's, every pair is within
/// `2t`: `2 c^2 - 1 >= eta` (`c >= 0` the smallest dot with the seed's normal) proves the
/// answer false without the quadratic scan; otherwise the scan stops at the first pair under
/// `eta`.
pub(crate) fn is_feature(faces: &[u32], normals: &[DVec3], eta: f64) -> bool {
    let Some(&first) = faces.first() else {
        return false;
    };
    let ni = normals[first as usize];
    let mut c = 1.0f64;
    for &k in faces {
        c = c.min(ni.dot(normals[k as usize]));
    }
    if c < eta {
        return true;
    }
    if c >= 0.0 && 2.0 * c * c - 1.0 >= eta {
        return false;
    }
    for (a, &j) in faces.iter().enumerate() {
        let nj = normals[j as usize];
        for &k in &faces[a + 1..] {
            if nj.dot(normals[k as usize]) < eta {
                return true;
            }
        }
    }
    false
}

/// The exact `S(i)` (for tests and diagnostics): the smallest pairwise dot product.
#[cfg(test)]
pub(crate) fn variation(faces: &[u32], normals: &[DVec3]) -> f64 {
    let mut s = 1.0f64;
    for (a, &j) in faces.iter().enumerate() {
        for &k in &faces[a..] {
            s = s.min(normals[j as usize].dot(normals[k as usize]));
        }
    }
    s
}

/// Feature faces among the `eligible` ones.
pub(crate) fn detect(
    geo: &Geo,
    normals: &[DVec3],
    eligible: &[bool],
    rho2: f64,
    eta: f64,
    lambda: f64,
) -> Vec<bool> {
    let nt = geo.tris.len();
    let mut flood = Flood::new(nt);
    let mut feature = vec![false; nt];
    for i in 0..nt {
        if !eligible[i] {
            continue;
        }
        flood.nfii(i as u32, geo, normals, rho2, lambda);
        feature[i] = is_feature(&flood.faces, normals, eta);
    }
    feature
}

#[cfg(test)]
mod tests {
    use super::*;
    use whet_synth::SplitMix64;

    #[test]
    fn shortcut_agrees_with_the_pairwise_scan() {
        let mut rng = SplitMix64::new(5);
        for trial in 0..2000 {
            let spread = [0.05, 0.3, 0.8, 1.6][trial % 4];
            let n: Vec<DVec3> = (0..12)
                .map(|_| {
                    DVec3::new(rng.next_signed() * spread, rng.next_signed() * spread, 1.0)
                        .normalize()
                })
                .collect();
            let faces: Vec<u32> = (0..12).collect();
            for eta in [-0.5, 0.0, 0.1, 0.5, 0.9] {
                assert_eq!(
                    is_feature(&faces, &n, eta),
                    variation(&faces, &n) < eta,
                    "trial {trial} eta {eta}"
                );
            }
        }
    }
}
