//! Truth meshes: closed, manifold, right genus, outward, with the analytic volume; the API.

use std::str::FromStr;

use glam::{DQuat, DVec3};
use whet_synth::{Error, Shape, ShapeKind, ShapeParams, TESSELLATION_TOLERANCE};

use crate::common::{generic_rotation, gradient, rotated, shape, volume};

#[test]
fn names_round_trip() {
    for kind in ShapeKind::ALL {
        assert_eq!(ShapeKind::from_str(kind.name()).unwrap(), kind);
        assert_eq!(kind.to_string(), kind.name());
        assert!(!kind.description().is_empty());
    }
    let names: Vec<&str> = ShapeKind::ALL.iter().map(|k| k.name()).collect();
    assert_eq!(
        names,
        [
            "cube",
            "box",
            "pyramid",
            "octahedron",
            "cylinder",
            "cone",
            "fandisk",
            "blend",
            "thin-face",
            "torus-box",
            "sphere"
        ]
    );
    match ShapeKind::from_str("teapot") {
        Err(Error::UnknownShape { name, known }) => {
            assert_eq!(name, "teapot");
            assert!(known.contains("torus-box"));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn truth_meshes_are_closed_manifolds_of_the_right_genus() {
    for kind in ShapeKind::ALL {
        for q in [DQuat::IDENTITY, generic_rotation()] {
            let s = rotated(kind, q);
            let m = s.truth_mesh();
            let r = m.topology_report();
            assert!(r.manifold && r.oriented, "{kind}: {r:?}");
            assert!(r.problems.is_empty(), "{kind}: {:?}", r.problems);
            assert_eq!(r.boundary_loops, 0, "{kind}");
            assert_eq!(r.components, 1, "{kind}");
            assert_eq!(r.genus, Some(s.genus()), "{kind}");
        }
    }
}

#[test]
fn truth_volumes_match_the_analytic_volumes() {
    for kind in ShapeKind::ALL {
        let s = shape(kind);
        let m = s.truth_mesh();
        let v = volume(&m);
        assert!(
            v > 0.0,
            "{kind}: outward orientation gives a positive volume"
        );
        // The mesh lies within the tessellation error of the surface.
        let tol = m.area() * s.tessellation_error() + 1e-12;
        assert!(
            (v - s.volume()).abs() <= tol,
            "{kind}: mesh volume {v} vs analytic {} (tolerance {tol})",
            s.volume()
        );
        // Rotation keeps the volume.
        let vr = volume(&rotated(kind, generic_rotation()).truth_mesh());
        assert!((vr - v).abs() < 1e-12, "{kind}");
    }
}

#[test]
fn tessellation_errors_are_under_the_tolerance() {
    for kind in ShapeKind::ALL {
        let s = shape(kind);
        let err = s.tessellation_error();
        assert!(err >= 0.0);
        assert!(
            err < TESSELLATION_TOLERANCE * s.diagonal(),
            "{kind}: {err} vs {}",
            TESSELLATION_TOLERANCE * s.diagonal()
        );
        if matches!(
            kind,
            ShapeKind::Cube
                | ShapeKind::Box
                | ShapeKind::Pyramid
                | ShapeKind::Octahedron
                | ShapeKind::ThinFace
        ) {
            assert_eq!(err, 0.0, "{kind}");
        }
        let d = s.diagonal();
        assert!((1.0..=3.0).contains(&d), "{kind}: diagonal {d}");
    }
}

#[test]
fn every_triangle_faces_outward() {
    // The SDF gradient just outside each triangle's centroid points along its normal.
    for kind in ShapeKind::ALL {
        let s = rotated(kind, generic_rotation());
        let m = s.truth_mesh();
        for t in 0..m.triangles.len() {
            let [a, b, c] = m.triangle_positions(t);
            let n = m.face_normal(t);
            let centroid = (a + b + c) / 3.0;
            let g = gradient(&s, centroid + n * 1e-6, 1e-8);
            assert!(
                n.dot(g) > 0.5,
                "{kind}: triangle {t} normal {n} gradient {g}"
            );
        }
    }
}

#[test]
fn bounds_contain_the_surface_and_the_inside_is_negative() {
    for kind in ShapeKind::ALL {
        for q in [DQuat::IDENTITY, generic_rotation()] {
            let s = rotated(kind, q);
            let b = s.bounds();
            assert_eq!(b, {
                let mut tb = s.truth_mesh().bounding_box();
                tb.min -= DVec3::splat(s.tessellation_error());
                tb.max += DVec3::splat(s.tessellation_error());
                tb
            });
            // Just outside the bounds the SDF is positive; on each face of the bounds it is
            // non-negative somewhere near zero (the bounds are tight).
            let (lo, hi) = (b.min - DVec3::splat(1e-9), b.max + DVec3::splat(1e-9));
            for corner in 0..8 {
                let pick = |bit: usize, a: f64, b: f64| if corner >> bit & 1 == 1 { b } else { a };
                let p = DVec3::new(
                    pick(0, lo.x, hi.x),
                    pick(1, lo.y, hi.y),
                    pick(2, lo.z, hi.z),
                );
                assert!(s.sdf(p) > 0.0, "{kind}");
            }
            let m = s.truth_mesh();
            for a in 0..3 {
                let top = m.positions.iter().map(|p| p[a]).fold(f64::MIN, f64::max);
                assert!(top <= b.max[a] && top >= b.max[a] - 2.0 * s.tessellation_error());
            }
        }
    }
    assert!(
        shape(ShapeKind::TorusBox).sdf(DVec3::ZERO) > 0.0,
        "the hole is outside"
    );
    assert!(shape(ShapeKind::Sphere).sdf(DVec3::ZERO) < 0.0);
}

#[test]
fn exact_sdfs_measure_euclidean_distance() {
    // Box: distance to a corner region, an edge region, inside.
    let b = shape(ShapeKind::Box);
    assert!((b.sdf(DVec3::new(1.5, 0.0, 0.0)) - 1.0).abs() < 1e-15);
    assert!((b.sdf(DVec3::new(0.0, 0.0, 0.0)) + 0.25).abs() < 1e-15);
    let s = shape(ShapeKind::Sphere);
    assert!((s.sdf(DVec3::new(0.0, 2.0, 0.0)) - 1.5).abs() < 1e-15);
    let c = shape(ShapeKind::Cylinder);
    assert!((c.sdf(DVec3::new(1.5, 1.5, 0.0)) - 2f64.sqrt()).abs() < 1e-15);
    let blend = shape(ShapeKind::Blend);
    // Beyond the rounded corner: distance to the inner box corner minus the radius.
    let inner = DVec3::new(0.46, 0.31, 0.21);
    let p = inner + DVec3::ONE.normalize() * 1.0;
    assert!((blend.sdf(p) - 0.96).abs() < 1e-12);
    let pyr = shape(ShapeKind::Pyramid);
    assert!((pyr.sdf(DVec3::new(0.0, 1.4, 0.0)) - 1.0).abs() < 1e-15);
    let cone = shape(ShapeKind::Cone);
    assert!((cone.sdf(DVec3::new(0.0, -1.5, 0.0)) - 1.0).abs() < 1e-15);
}

#[test]
fn rotation_rotates_everything() {
    let q = generic_rotation();
    for kind in ShapeKind::ALL {
        let a = shape(kind);
        let b = rotated(kind, q);
        let ma = a.truth_mesh();
        let mb = b.truth_mesh();
        assert_eq!(ma.triangles, mb.triangles);
        for (pa, pb) in ma.positions.iter().zip(&mb.positions) {
            assert!((q * *pa - *pb).length() < 1e-15);
        }
        for p in [DVec3::new(0.3, -0.2, 0.1), DVec3::new(1.0, 0.5, -0.7)] {
            assert!((a.sdf(p) - b.sdf(q * p)).abs() < 1e-12, "{kind}");
        }
    }
    // Non-normalised quaternions are normalised; degenerate ones refused.
    let s = Shape::new(
        ShapeKind::Cube,
        &ShapeParams::default().with_rotation(DQuat::from_xyzw(0.0, 0.0, 0.0, 2.0)),
    )
    .unwrap();
    assert_eq!(s.params().rotation, DQuat::IDENTITY);
    for bad in [
        DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0),
        DQuat::from_xyzw(f64::NAN, 0.0, 0.0, 1.0),
    ] {
        assert!(matches!(
            Shape::new(ShapeKind::Cube, &ShapeParams::default().with_rotation(bad)),
            Err(Error::BadRotation(_))
        ));
    }
}

#[test]
fn blend_radius_is_checked_and_used() {
    for bad in [0.0, -0.1, 0.25, 0.3, f64::NAN, f64::INFINITY] {
        let r = Shape::new(ShapeKind::Blend, &ShapeParams::default().with_radius(bad));
        assert!(matches!(r, Err(Error::BadRadius { .. })), "{bad}: {r:?}");
    }
    for radius in [0.001, 0.04, 0.1, 0.249] {
        let s = Shape::new(
            ShapeKind::Blend,
            &ShapeParams::default().with_radius(radius),
        )
        .unwrap();
        let r = s.truth_mesh().topology_report();
        assert!(
            r.manifold && r.problems.is_empty() && r.genus == Some(0),
            "{radius}"
        );
        // Same outer size as the box.
        let b = s.truth_mesh().bounding_box();
        assert!((b.size() - DVec3::new(1.0, 0.7, 0.5)).abs().max_element() < 1e-12);
        assert!(s.tessellation_error() < TESSELLATION_TOLERANCE * s.diagonal());
        assert!((volume(&s.truth_mesh()) - s.volume()).abs() < 1e-4);
    }
    // The default is 0.04, and the box is its sharp counterpart.
    let blend = shape(ShapeKind::Blend);
    assert_eq!(blend.params().radius, None);
    let edge_point = DVec3::new(0.0, 0.35, 0.25);
    assert!((shape(ShapeKind::Box).sdf(edge_point)).abs() < 1e-15);
    let expected = 0.04 * (2f64.sqrt() - 1.0);
    assert!((blend.sdf(edge_point) - expected).abs() < 1e-12);
}

#[test]
fn thin_face_is_narrower_than_three_steps_at_64() {
    let s = shape(ShapeKind::ThinFace);
    let m = s.truth_mesh();
    // The chamfer face: normal (0, 1, 1) / sqrt 2.
    let n = DVec3::new(0.0, 1.0, 1.0).normalize();
    let tris: Vec<usize> = (0..m.triangles.len())
        .filter(|&t| (m.face_normal(t) - n).length() < 1e-12)
        .collect();
    assert_eq!(tris.len(), 2);
    let area: f64 = tris.iter().map(|&t| m.face_area(t)).sum();
    let width = area / 1.0;
    assert!((width - 0.02).abs() < 1e-12);
    let step = s.bounds().size().max_element() / 64.0;
    assert!(width < 3.0 * step);
}
