//! Property tests: random smooth closed meshes and meshes with holes retile into valid
//! manifolds that round-trip bit for bit.

use crate::round_trip_with;
use proptest::prelude::*;
use whet_mesh::{DVec3, Mesh};
use whet_swing::{Rate, SwingOptions};
use whet_testkit::meshes::{icosphere, punch, torus};

/// A bumpy, stretched version of `base`: radial displacement by a few random waves.
fn bumpy(base: &Mesh, waves: &[(f64, f64, f64, f64)], stretch: (f64, f64, f64)) -> Mesh {
    let mut m = base.clone();
    for p in &mut m.positions {
        let mut r = 1.0;
        for &(fx, fy, fz, a) in waves {
            r += a * (fx * p.x + fy * p.y + fz * p.z).sin();
        }
        *p = DVec3::new(p.x * stretch.0, p.y * stretch.1, p.z * stretch.2) * r;
    }
    m
}

fn waves() -> impl Strategy<Value = Vec<(f64, f64, f64, f64)>> {
    prop::collection::vec(
        (-4.0..4.0f64, -4.0..4.0f64, -4.0..4.0f64, 0.0..0.08f64),
        0..4,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, .. ProptestConfig::default() })]

    #[test]
    fn closed_bumpy_spheres_round_trip(
        w in waves(),
        sx in 0.6..1.6f64,
        sz in 0.6..1.6f64,
        fraction in 0.03..0.09f64,
        bits in 5u32..10,
    ) {
        let m = bumpy(&icosphere(3), &w, (sx, 1.0, sz));
        let out = round_trip_with(
            &m,
            &SwingOptions::DEFAULT
                .with_rate(Rate::EdgeLength(fraction))
                .with_angle_bits(bits),
        );
        prop_assert_eq!(&out.geometry, &whet_codec::SwingGeometry::Swing);
        let report = out.retiled.topology_report();
        prop_assert_eq!(report.boundary_edges, 0);
        prop_assert_eq!(report.genus, Some(0));
    }

    #[test]
    fn closed_bumpy_tori_round_trip(w in waves(), fraction in 0.03..0.07f64) {
        let m = bumpy(&torus(48, 24), &w, (1.0, 1.0, 1.0));
        let out = round_trip_with(&m, &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(fraction)));
        prop_assert_eq!(&out.geometry, &whet_codec::SwingGeometry::Swing);
    }

    #[test]
    fn spheres_with_holes_round_trip(
        w in waves(),
        centers in prop::collection::vec((-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64, 0.1..0.6f64), 1..5),
        fraction in 0.03..0.09f64,
    ) {
        // Round holes of random sizes (cut before the bumps, so they stay round).
        let sphere = icosphere(3);
        let holes: Vec<(DVec3, f64)> = centers
            .iter()
            .map(|&(x, y, z, r)| (DVec3::new(x, y, z).normalize_or(DVec3::X), r))
            .collect();
        let punched = punch(&sphere, |t| {
            let c = sphere.triangle_positions(t).iter().fold(DVec3::ZERO, |a, p| a + *p) / 3.0;
            holes.iter().any(|&(h, r)| (c - h).length() < r)
        });
        prop_assume!(!punched.triangles.is_empty());
        let m = bumpy(&punched, &w, (1.0, 1.0, 1.0));
        let out = round_trip_with(&m, &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(fraction)));
        prop_assert_eq!(&out.geometry, &whet_codec::SwingGeometry::Swing);
    }
}
