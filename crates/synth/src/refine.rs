//! Dense, irregular tessellations of a polyhedral truth mesh that stay exactly on its surface:
//! midpoint subdivision, then a jitter of every vertex within its own facet (or along its own
//! crease), so the tessellation looks like a real mesher's output (no parallelogram-perfect
//! grid) while the surface, its creases and corners are untouched.

use crate::noise::SplitMix64;
use glam::DVec3;
use std::collections::HashMap;
use whet_mesh::Mesh;

/// Splits every triangle into four at its edge midpoints (shared midpoints), `levels` times.
/// The surface is unchanged, so creases stay exact.
pub fn midpoint_subdivide(mesh: &Mesh, levels: u32) -> Mesh {
    let mut m = mesh.clone();
    for _ in 0..levels {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut tris = Vec::with_capacity(m.triangles.len() * 4);
        let mut pos = m.positions.clone();
        let mut midpoint = |a: u32, b: u32, pos: &mut Vec<DVec3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pos.push((pos[a as usize] + pos[b as usize]) * 0.5);
                (pos.len() - 1) as u32
            })
        };
        for &[a, b, c] in &m.triangles {
            let ab = midpoint(a, b, &mut pos);
            let bc = midpoint(b, c, &mut pos);
            let ca = midpoint(c, a, &mut pos);
            tris.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        m = Mesh::new(pos, tris);
    }
    m
}

/// Two unit normals closer than this (1 - cos) are the same plane.
const SAME_PLANE: f64 = 1e-9;

/// Moves every vertex by up to `amount` (a fraction, at most 0.3) of the smallest altitude of
/// its incident triangles, in a direction that keeps it on the surface: anywhere in the plane
/// when all incident triangles are coplanar, along the crease when they lie in exactly two
/// planes; vertices where three or more planes meet (corners) and boundary vertices stay put.
/// Each vertex moves by less than a third of every incident altitude, which cannot flip a
/// triangle (the altitude of any vertex over the opposite edge keeps at least 10 % of its
/// length). Deterministic from `seed`; connectivity is never changed.
pub fn jitter_within_surface(mesh: &Mesh, amount: f64, seed: u64) -> Mesh {
    let amount = if amount.is_finite() {
        amount.abs().min(0.3)
    } else {
        0.0
    };
    let n = mesh.positions.len();
    let mut normals: Vec<Vec<DVec3>> = vec![Vec::new(); n];
    let mut min_altitude = vec![f64::INFINITY; n];
    let mut edge_count: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &mesh.triangles {
        let p = t.map(|v| mesh.positions[v as usize]);
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        let area2 = cross.length();
        if area2 == 0.0 || !area2.is_finite() {
            // A degenerate triangle pins its vertices.
            for &v in t {
                min_altitude[v as usize] = 0.0;
            }
            continue;
        }
        let normal = cross / area2;
        for k in 0..3 {
            let v = t[k] as usize;
            let opposite = (p[(k + 2) % 3] - p[(k + 1) % 3]).length();
            min_altitude[v] = min_altitude[v].min(area2 / opposite);
            let list = &mut normals[v];
            if !list.iter().any(|m| 1.0 - m.dot(normal) < SAME_PLANE) {
                list.push(normal);
            }
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edge_count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut on_boundary = vec![false; n];
    for (&(a, b), &c) in &edge_count {
        if c != 2 {
            on_boundary[a as usize] = true;
            on_boundary[b as usize] = true;
        }
    }
    let mut rng = SplitMix64::new(seed);
    let mut out = mesh.clone();
    for v in 0..n {
        // Draw for every vertex so one vertex's class does not shift the others' noise.
        let (u, w) = (rng.next_signed(), rng.next_signed());
        let reach = amount * min_altitude[v];
        if on_boundary[v] || !(reach.is_finite() && reach > 0.0) {
            continue;
        }
        let step = match normals[v].as_slice() {
            [nrm] => {
                let a = nrm.any_orthonormal_vector();
                let b = nrm.cross(a);
                // Uniform in the unit disc would need rejection; a square clipped to the
                // disc keeps the bound and the determinism.
                let d = a * u + b * w;
                if d.length() > 1.0 {
                    d.normalize()
                } else {
                    d
                }
            }
            [n0, n1] => {
                let dir = n0.cross(*n1);
                if dir.length() == 0.0 {
                    continue;
                }
                dir.normalize() * u
            }
            _ => continue,
        };
        out.positions[v] += step * reach;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> Mesh {
        let p = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        let t = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        Mesh::new(p, t)
    }

    #[test]
    fn midpoint_subdivision_quadruples_and_keeps_the_surface() {
        let m = midpoint_subdivide(&cube(), 2);
        assert_eq!(m.triangles.len(), 12 * 16);
        // Euler characteristic of a sphere.
        let edges = m.triangles.len() * 3 / 2;
        assert_eq!(
            m.positions.len() as i64 - edges as i64 + m.triangles.len() as i64,
            2
        );
        for p in &m.positions {
            let on_face = [p.x, p.y, p.z]
                .iter()
                .any(|&c| c.abs() < 1e-15 || (c - 1.0).abs() < 1e-15);
            assert!(on_face, "{p} left the cube's surface");
        }
    }

    #[test]
    fn jitter_stays_on_the_cube_keeps_corners_and_orientation() {
        let m = midpoint_subdivide(&cube(), 3);
        let j = jitter_within_surface(&m, 0.3, 7);
        assert_eq!(j.triangles, m.triangles);
        let mut moved = 0;
        for (a, b) in m.positions.iter().zip(&j.positions) {
            // Every vertex stays on the cube's surface (on a face plane, inside [0, 1]^3).
            for c in [b.x, b.y, b.z] {
                assert!((-1e-12..=1.0 + 1e-12).contains(&c), "{b} left the cube");
            }
            let corner = [a.x, a.y, a.z].iter().all(|&c| c == 0.0 || c == 1.0);
            if corner {
                assert_eq!(a, b, "a corner moved");
            }
            // Along a crease (two coordinates at 0 or 1): the crease is kept.
            let pinned = |p: &DVec3| {
                [p.x, p.y, p.z]
                    .iter()
                    .filter(|&&c| c == 0.0 || c == 1.0)
                    .count()
            };
            assert!(pinned(b) >= pinned(a).min(2), "{a} -> {b} left its crease");
            if a != b {
                moved += 1;
            }
        }
        assert!(moved > m.positions.len() / 2, "only {moved} vertices moved");
        // No triangle flips: each normal keeps its direction.
        for t in &m.triangles {
            let n = |m: &Mesh| {
                let p = t.map(|v| m.positions[v as usize]);
                (p[1] - p[0]).cross(p[2] - p[0])
            };
            assert!(n(&m).dot(n(&j)) > 0.0);
        }
        // Deterministic.
        assert_eq!(j, jitter_within_surface(&m, 0.3, 7));
        assert_ne!(j, jitter_within_surface(&m, 0.3, 8));
    }
}
