//! Property test: whatever the noise, holes and options, sharpening never panics and the
//! output keeps its guarantees (oriented manifold, same boundary, no thin new triangle, input
//! vertices first).

use proptest::prelude::*;
use whet_sharpen::{sharpen, Method, SharpenOptions};
use whet_synth::{add_noise, marching_cubes, Shape, ShapeKind, ShapeParams};
use whet_testkit::meshes;

use crate::support::rotations;

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn guarantees_hold_on_random_damage(
        kind in prop::sample::select(vec![ShapeKind::Cube, ShapeKind::Fandisk, ShapeKind::Pyramid, ShapeKind::TorusBox]),
        res in 8usize..20,
        rot in 0usize..2,
        noise in 0.0f64..1.5,
        seed in any::<u64>(),
        holes in 0usize..40,
        factor in 0.5f64..4.0,
        papers in any::<bool>(),
    ) {
        let shape = Shape::new(kind, &ShapeParams::default().with_rotation(rotations()[rot])).unwrap();
        let mut mesh = add_noise(&marching_cubes(&shape, res).unwrap(), noise, seed);
        if holes > 0 {
            mesh = meshes::punch(&mesh, |t| (t as u64).wrapping_mul(seed | 1) % (holes as u64 + 7) == 0);
        }
        let method = if papers { Method::Papers } else { Method::Extended };
        let opts = SharpenOptions::DEFAULT.with_method(method).with_smooth_factor(factor);
        let out = sharpen(&mesh, &opts).unwrap();
        let before = mesh.topology_report();
        let after = out.mesh.topology_report();
        prop_assert!(after.manifold && after.oriented);
        prop_assert_eq!(after.boundary_edges, before.boundary_edges);
        prop_assert_eq!(out.parents.len(), out.mesh.triangles.len());
        prop_assert!(out.mesh.positions.len() >= mesh.positions.len());
        if method == Method::Papers {
            prop_assert_eq!(&out.mesh.positions[..mesh.positions.len()], &mesh.positions[..]);
        }
        // Smallest angle of the triangles that are not input triangles.
        let keys = mesh.sorted_vertex_sets();
        for (t, tri) in out.mesh.triangles.iter().enumerate() {
            let mut k = *tri;
            k.sort_unstable();
            let old = keys.binary_search(&k).is_ok()
                && tri.iter().all(|&v| out.mesh.positions[v as usize] == mesh.positions[v as usize]);
            if old {
                continue;
            }
            let p = out.mesh.triangle_positions(t);
            for i in 0..3 {
                let a = whet_mesh::angle_between(p[(i + 1) % 3] - p[i], p[(i + 2) % 3] - p[i]);
                prop_assert!(a.to_degrees() >= 1.0 - 1e-6, "triangle {} angle {}", t, a.to_degrees());
            }
        }
    }
}
