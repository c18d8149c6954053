//! Smooth and revolved shapes: cylinder with flat caps, cone, sphere. Their caps are planar
//! disks (fans, exact); the curved faces are strips between rings of points on the true
//! surface, fine enough that the chordal error stays under the tolerance.

use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::{DVec2, DVec3};

use super::build::{
    chords_for, circle, octant_dir, octant_grid_index, octant_triangles, sagitta,
    sphere_patch_error, Builder,
};
use super::sdf::Revolved;
use super::Built;
use super::Geometry;

/// Cylinder of radius `r` about the y axis, `|y| <= hh`, with flat caps.
pub(crate) fn cylinder(r: f64, hh: f64, tol: f64) -> Built {
    let n = chords_for(r, TAU, tol, 8);
    let mut b = Builder::new();
    let top = b.vertices(circle(DVec3::new(0.0, hh, 0.0), DVec3::X, DVec3::Z, r, n));
    let bottom = b.vertices(circle(DVec3::new(0.0, -hh, 0.0), DVec3::X, DVec3::Z, r, n));
    let tc = b.vertex(DVec3::new(0.0, hh, 0.0));
    let bc = b.vertex(DVec3::new(0.0, -hh, 0.0));
    b.disk(tc, &top, DVec3::Y);
    b.disk(bc, &bottom, -DVec3::Y);
    b.strip(&bottom, &top, true, |c| DVec3::new(c.x, 0.0, c.z));
    Built {
        geometry: Geometry::Cylinder { r, hh },
        mesh: b.finish(),
        tessellation_error: sagitta(r, TAU / n as f64),
        volume: PI * r * r * 2.0 * hh,
    }
}

/// Cone with base disk of radius `r` at `y = -h / 2` and apex at `(0, h / 2, 0)`.
pub(crate) fn cone(r: f64, h: f64, tol: f64) -> Built {
    let n = chords_for(r, TAU, tol, 8);
    let y0 = -0.5 * h;
    let mut b = Builder::new();
    let ring = b.vertices(circle(DVec3::new(0.0, y0, 0.0), DVec3::X, DVec3::Z, r, n));
    let bc = b.vertex(DVec3::new(0.0, y0, 0.0));
    let apex = b.vertex(DVec3::new(0.0, 0.5 * h, 0.0));
    b.disk(bc, &ring, -DVec3::Y);
    for i in 0..n {
        let (p, q) = (ring[i], ring[(i + 1) % n]);
        let c = (b.pos(p) + b.pos(q)) * 0.5;
        b.tri_facing(p, q, apex, DVec3::new(c.x, 0.0, c.z));
    }
    let profile = Revolved::new(vec![
        DVec2::new(0.0, y0),
        DVec2::new(r, y0),
        DVec2::new(0.0, 0.5 * h),
    ]);
    Built {
        geometry: Geometry::Revolved(profile),
        mesh: b.finish(),
        tessellation_error: sagitta(r, TAU / n as f64),
        volume: PI * r * r * h / 3.0,
    }
}

/// Sphere of radius `r` about the origin: eight octant patches sharing their boundary points.
pub(crate) fn sphere(r: f64, tol: f64) -> Built {
    let mut m = chords_for(r, FRAC_PI_2, tol, 1);
    loop {
        let (b, err) = sphere_mesh(r, m);
        if err <= tol || m > 4096 {
            return Built {
                geometry: Geometry::Sphere(r),
                mesh: b.finish(),
                tessellation_error: err,
                volume: 4.0 / 3.0 * PI * r * r * r,
            };
        }
        m += m.div_ceil(8);
    }
}

fn sphere_mesh(r: f64, m: usize) -> (Builder, f64) {
    let mut b = Builder::new();
    let mut ids: HashMap<(i64, i64, i64), u32> = HashMap::new();
    let tris = octant_triangles(m);
    let mut all = Vec::new();
    for oct in 0..8 {
        let s = octant_signs(oct);
        let mut grid = Vec::with_capacity((m + 1) * (m + 2) / 2);
        for a in 0..=m {
            for bb in 0..=(m - a) {
                let c = m - a - bb;
                let key = (
                    s.x as i64 * a as i64,
                    s.y as i64 * bb as i64,
                    s.z as i64 * c as i64,
                );
                let p = octant_dir(a, bb, c, m, s) * r;
                let id = *ids.entry(key).or_insert_with(|| b.vertex(p));
                debug_assert_eq!(grid.len(), octant_grid_index(a, bb, m));
                grid.push(id);
            }
        }
        for t in &tris {
            let (p, q, w) = (grid[t[0]], grid[t[1]], grid[t[2]]);
            let c = b.pos(p) + b.pos(q) + b.pos(w);
            b.tri_facing(p, q, w, c);
            all.push([p, q, w]);
        }
    }
    let err = sphere_patch_error(&b, &all, DVec3::ZERO, r);
    (b, err)
}

/// Coordinate signs of octant `oct` (bit 0: x, bit 1: y, bit 2: z; set means negative).
pub(crate) fn octant_signs(oct: usize) -> DVec3 {
    let s = |bit: usize| if oct >> bit & 1 == 1 { -1.0 } else { 1.0 };
    DVec3::new(s(0), s(1), s(2))
}
