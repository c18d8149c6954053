//! Sharp edges of the truth meshes lie on the true creases.

use glam::DQuat;
use whet_mesh::angle_between;
use whet_synth::ShapeKind;

use crate::common::{edge_pairs, gradient, rotated};

#[test]
fn sharp_truth_edges_lie_on_true_creases() {
    for kind in [
        ShapeKind::Cube,
        ShapeKind::Box,
        ShapeKind::Pyramid,
        ShapeKind::Octahedron,
        ShapeKind::Fandisk,
        ShapeKind::ThinFace,
        ShapeKind::TorusBox,
        ShapeKind::Cylinder,
        ShapeKind::Cone,
    ] {
        for q in [DQuat::IDENTITY, crate::common::generic_rotation()] {
            let s = rotated(kind, q);
            let m = s.truth_mesh();
            let mut sharp = 0;
            for (a, b, t0, t1) in edge_pairs(&m) {
                let (n0, n1) = (m.face_normal(t0), m.face_normal(t1));
                let angle = angle_between(n0, n1);
                if angle <= 30f64.to_radians() {
                    continue;
                }
                sharp += 1;
                let (pa, pb) = (m.positions[a as usize], m.positions[b as usize]);
                for p in [pa, pb] {
                    assert!(
                        s.sdf(p).abs() < 1e-12,
                        "{kind}: crease vertex {p} off the surface"
                    );
                }
                let mid = (pa + pb) * 0.5;
                assert!(s.sdf(mid).abs() <= s.tessellation_error() + 1e-12, "{kind}");
                // Step a little into each face and just outside it: the SDF gradients there
                // are the two sides' normals, which differ across a true crease.
                // Step in by more than the chordal error: near a concave curved crease the
                // chord lies off the true face by up to that much.
                let eps = 1e-5 * s.diagonal();
                let inward = 4.0 * eps + 3.0 * s.tessellation_error();
                let side = |t: usize, n: glam::DVec3| {
                    let [x, y, z] = m.triangle_positions(t);
                    // Perpendicular to the edge, in the face, towards the face.
                    let mut into = n.cross(pb - pa).normalize();
                    if into.dot((x + y + z) / 3.0 - mid) < 0.0 {
                        into = -into;
                    }
                    gradient(&s, mid + into * inward + n * eps, eps * 0.01)
                };
                let (g0, g1) = (side(t0, n0), side(t1, n1));
                let crease = angle_between(g0, g1);
                assert!(
                    crease > 0.5 * angle,
                    "{kind}: edge {a}-{b} (dihedral {:.1} deg) is not on a crease ({:.1} deg)",
                    angle.to_degrees(),
                    crease.to_degrees()
                );
                // The faces' normals are those of the sides (up to the chord angle of a curved
                // side, a few degrees at most).
                assert!(
                    angle_between(g0, n0) < 5f64.to_radians(),
                    "{kind}: {g0} vs {n0}"
                );
                assert!(
                    angle_between(g1, n1) < 5f64.to_radians(),
                    "{kind}: {g1} vs {n1}"
                );
            }
            let expected_min = match kind {
                ShapeKind::Cube | ShapeKind::Box => 12,
                ShapeKind::Pyramid => 8,
                ShapeKind::Octahedron => 12,
                _ => 12,
            };
            assert!(sharp >= expected_min, "{kind}: only {sharp} sharp edges");
        }
    }
}

#[test]
fn smooth_shapes_have_no_sharp_truth_edges() {
    for kind in [ShapeKind::Sphere, ShapeKind::Blend] {
        let m = rotated(kind, DQuat::IDENTITY).truth_mesh();
        for (_, _, t0, t1) in edge_pairs(&m) {
            let angle = angle_between(m.face_normal(t0), m.face_normal(t1));
            assert!(angle < 10f64.to_radians(), "{kind}: {}", angle.to_degrees());
        }
    }
}
