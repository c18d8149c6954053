//! The blend: a box with every edge rounded by a fillet of radius `r` (the Minkowski sum of the
//! box shrunk by `r` and a ball), with the same outer size as its sharp counterpart. Truth mesh:
//! eight spherical corner patches, twelve cylindrical strips between them, six planar
//! rectangles.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

use super::build::{
    chords_for, octant_dir, octant_grid_index, octant_triangles, sagitta, sphere_patch_error,
    Builder,
};
use super::revolved::octant_signs;
use super::{Built, Geometry};

pub(crate) fn rounded_box(half: DVec3, r: f64, tol: f64) -> Built {
    let mut m = chords_for(r, FRAC_PI_2, tol, 1).max(2);
    loop {
        let (b, err) = rounded_box_mesh(half, r, m);
        if err <= tol || m > 4096 {
            let inner = (half - DVec3::splat(r)) * 2.0;
            let volume = inner.x * inner.y * inner.z
                + 2.0 * r * (inner.x * inner.y + inner.y * inner.z + inner.z * inner.x)
                + PI * r * r * (inner.x + inner.y + inner.z)
                + 4.0 / 3.0 * PI * r * r * r;
            return Built {
                geometry: Geometry::RoundBox { half, r },
                mesh: b.finish(),
                tessellation_error: err,
                volume,
            };
        }
        m += m.div_ceil(8);
    }
}

fn rounded_box_mesh(half: DVec3, r: f64, m: usize) -> (Builder, f64) {
    let inner = half - DVec3::splat(r);
    let mut b = Builder::new();
    let tris = octant_triangles(m);
    // grids[oct][octant_grid_index(a, b, m)] = vertex id.
    let mut grids: Vec<Vec<u32>> = Vec::with_capacity(8);
    let mut err: f64 = 0.0;
    for oct in 0..8 {
        let s = octant_signs(oct);
        let corner = inner * s;
        let mut grid = Vec::with_capacity((m + 1) * (m + 2) / 2);
        for a in 0..=m {
            for bb in 0..=(m - a) {
                grid.push(b.vertex(corner + octant_dir(a, bb, m - a - bb, m, s) * r));
            }
        }
        let first = b.triangles.len();
        for t in &tris {
            let (p, q, w) = (grid[t[0]], grid[t[1]], grid[t[2]]);
            let c = (b.pos(p) + b.pos(q) + b.pos(w)) / 3.0;
            b.tri_facing(p, q, w, c - corner);
        }
        let patch: Vec<[u32; 3]> = b.triangles[first..].to_vec();
        err = err.max(sphere_patch_error(&b, &patch, corner, r));
        grids.push(grid);
    }
    let oct_of = |s: DVec3| {
        (usize::from(s.x < 0.0)) | (usize::from(s.y < 0.0) << 1) | (usize::from(s.z < 0.0) << 2)
    };
    // Strips along each axis between the two octants that differ in that axis' sign.
    for axis in 0..3 {
        for s1 in [1.0, -1.0] {
            for s2 in [1.0, -1.0] {
                let mut sp = DVec3::ONE;
                sp[(axis + 1) % 3] = s1;
                sp[(axis + 2) % 3] = s2;
                let mut sm = sp;
                sm[axis] = -1.0;
                let (gp, gm) = (&grids[oct_of(sp)], &grids[oct_of(sm)]);
                // Boundary points of the octant with zero `axis` component, in order.
                let boundary = |g: &Vec<u32>| -> Vec<u32> {
                    (0..=m)
                        .map(|k| {
                            let idx = match axis {
                                0 => octant_grid_index(0, k, m),
                                1 => octant_grid_index(k, 0, m),
                                _ => octant_grid_index(k, m - k, m),
                            };
                            g[idx]
                        })
                        .collect()
                };
                let (bp, bm) = (boundary(gp), boundary(gm));
                let axis_point = inner * sp;
                b.strip(&bp, &bm, false, |c| {
                    let mut d = c - axis_point;
                    d[axis] = 0.0;
                    d
                });
            }
        }
    }
    // Planar faces between the four poles on each side.
    for axis in 0..3 {
        for side in [1.0, -1.0] {
            let mut ring = Vec::new();
            for (s1, s2) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
                let mut s = DVec3::ZERO;
                s[axis] = side;
                s[(axis + 1) % 3] = s1;
                s[(axis + 2) % 3] = s2;
                let pole = match axis {
                    0 => octant_grid_index(m, 0, m),
                    1 => octant_grid_index(0, m, m),
                    _ => octant_grid_index(0, 0, m),
                };
                ring.push(grids[oct_of(s)][pole]);
            }
            let mut n = DVec3::ZERO;
            n[axis] = side;
            b.convex_polygon(&ring, n);
        }
    }
    (b, err.max(sagitta(r, FRAC_PI_2 / m as f64)))
}
