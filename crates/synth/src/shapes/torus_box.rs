//! The torus-box: a box with a cylindrical through-hole along z (genus 1). Its two pierced
//! faces are triangulated by matching the rectangle's corners to the hole's ring.

use std::f64::consts::{PI, TAU};

use glam::DVec3;

use super::build::{chords_for, circle, sagitta, Builder};
use super::polyhedra::cuboid;
use super::{Built, Geometry};

pub(crate) fn torus_box(half: DVec3, r: f64, tol: f64) -> Built {
    let n = chords_for(r, TAU, tol, 8);
    let cube = cuboid(half);
    let mut b = Builder::new();
    let corners = b.vertices(cube.vertices.iter().copied());
    let top_c = DVec3::new(0.0, 0.0, half.z);
    let bot_c = DVec3::new(0.0, 0.0, -half.z);
    let top = b.vertices(circle(top_c, DVec3::X, DVec3::Y, r, n));
    let bottom = b.vertices(circle(bot_c, DVec3::X, DVec3::Y, r, n));
    for (face, normal) in cube.faces.iter().zip([
        -DVec3::X,
        DVec3::X,
        -DVec3::Y,
        DVec3::Y,
        -DVec3::Z,
        DVec3::Z,
    ]) {
        let ring: Vec<u32> = face.iter().map(|&i| corners[i]).collect();
        if normal == DVec3::Z {
            b.annulus(&ring, &top, top_c, normal);
        } else if normal == -DVec3::Z {
            b.annulus(&ring, &bottom, bot_c, normal);
        } else {
            b.convex_polygon(&ring, normal);
        }
    }
    // The hole's wall faces the axis.
    b.strip(&bottom, &top, true, |c| DVec3::new(-c.x, -c.y, 0.0));
    Built {
        geometry: Geometry::TorusBox { half, r },
        mesh: b.finish(),
        tessellation_error: sagitta(r, TAU / n as f64),
        volume: 8.0 * half.x * half.y * half.z - PI * r * r * 2.0 * half.z,
    }
}
