//! Vertex updating (sharpening-extras.md A.6): Gauss-Seidel least-squares sweeps that move the
//! feature vertices until their faces agree with the filtered normals, with a backtracking
//! step against flips, and cap/needle removal after every sweep.

use glam::DVec3;

use super::remesh::DynMesh;

/// Sweeps stop when no vertex moved by more than this many mean edge lengths (A.6 suggests
/// 1e-4 L)...
const TOLERANCE: f64 = 1e-4;
/// ...or after this many sweeps (Sun et al. use 50; A.6 suggests 50-100).
const MAX_SWEEPS: usize = 100;
/// The step is halved at most this many times (A.6: four tries).
const HALVINGS: usize = 3;

/// What updating did.
pub(crate) struct Updated {
    pub sweeps: usize,
    pub flips_avoided: usize,
}

/// Runs the sweeps on `m` over the vertices `moving` (feature vertices that may move). No
/// vertex ends farther than `reach` from where updating found it: the crease a feature vertex
/// belongs on is inside the feature, which `rho` bounds; normals that disagree with each other
/// (noise) would otherwise let Gauss-Seidel sweeps drift without bound.
pub(crate) fn update(m: &mut DynMesh, moving: &[u32], mean_edge: f64, reach: f64) -> Updated {
    let tol = TOLERANCE * mean_edge;
    let home: Vec<DVec3> = m.pos.clone();
    let mut flips_avoided = 0;
    let mut sweeps = 0;
    let mut stamp = vec![0u32; m.tris.len()];
    let mut faces: Vec<u32> = Vec::new();
    while sweeps < MAX_SWEEPS {
        sweeps += 1;
        let mut max_step = 0.0f64;
        for &v in moving {
            if m.removed[v as usize] || !m.movable[v as usize] {
                continue;
            }
            let around = &m.vf[v as usize];
            if around.is_empty() {
                continue;
            }
            let x = m.pos[v as usize];
            let mut delta = DVec3::ZERO;
            for &f in around {
                let [a, b, c] = m.tris[f as usize];
                let centroid = (m.pos[a as usize] + m.pos[b as usize] + m.pos[c as usize]) / 3.0;
                let n = m.target[f as usize];
                delta += n * n.dot(centroid - x);
            }
            delta /= around.len() as f64;
            let len = delta.length();
            if len.is_nan() || len <= 1e-3 * tol {
                continue;
            }
            let mut gamma = 1.0;
            let mut accepted = false;
            for _ in 0..=HALVINGS {
                let y = x + delta * gamma;
                if y.distance_squared(home[v as usize]) <= reach * reach && m.move_ok(v, y) {
                    accepted = true;
                    break;
                }
                gamma *= 0.5;
            }
            if gamma < 1.0 {
                flips_avoided += 1;
            }
            if accepted {
                m.pos[v as usize] = x + delta * gamma;
                max_step = max_step.max(len * gamma);
            }
        }
        // Caps and needles among the faces around the feature vertices.
        faces.clear();
        for &v in moving {
            if m.removed[v as usize] {
                continue;
            }
            for &f in &m.vf[v as usize] {
                if stamp[f as usize] != sweeps as u32 {
                    stamp[f as usize] = sweeps as u32;
                    faces.push(f);
                }
            }
        }
        let mut changed = false;
        for &f in &faces {
            changed |= m.fix_degenerate(f);
        }
        if max_step <= tol && !changed {
            break;
        }
    }
    Updated {
        sweeps,
        flips_avoided,
    }
}
