//! Truth-mesh accuracy both ways: the mesh is on the surface, and the surface is on the mesh.

use whet_synth::{marching_cubes, ShapeKind, TESSELLATION_TOLERANCE};

use crate::common::{
    distance_to_mesh, generic_rotation, project_to_surface, rotated, surface_samples,
};

#[test]
fn truth_mesh_points_lie_on_the_surface() {
    for kind in ShapeKind::ALL {
        let s = rotated(kind, generic_rotation());
        let m = s.truth_mesh();
        let tol = s.tessellation_error() + 1e-9;
        for p in surface_samples(&m, 4000, 11) {
            let d = s.sdf(p).abs();
            assert!(d < tol, "{kind}: |sdf| = {d} at {p} (tolerance {tol})");
        }
        for p in &m.positions {
            assert!(
                s.sdf(*p).abs() < 1e-12,
                "{kind}: vertex {p} off the surface"
            );
        }
    }
}

#[test]
fn surface_points_lie_on_the_truth_mesh() {
    for kind in ShapeKind::ALL {
        let s = rotated(kind, generic_rotation());
        let m = s.truth_mesh();
        let limit = TESSELLATION_TOLERANCE * s.diagonal();
        let sampled = marching_cubes(&s, 24).unwrap();
        let step = (sampled.positions.len() / 150).max(1);
        let mut checked = 0;
        for p in sampled.positions.iter().step_by(step) {
            let Some(q) = project_to_surface(&s, *p) else {
                continue;
            };
            let d = distance_to_mesh(&m, q);
            assert!(
                d < limit,
                "{kind}: surface point {q} is {d} from the truth mesh"
            );
            assert!(d <= s.tessellation_error() + 1e-9, "{kind}: {d}");
            checked += 1;
        }
        assert!(checked >= 100, "{kind}: only {checked} points projected");
    }
}
