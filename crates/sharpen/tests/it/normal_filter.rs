//! The normal filter (issue 10) at test-suite scale: the figures on the blend and the
//! chamfered box as regression bounds, the output guarantees (manifold, same boundary, no
//! triangle facing against its input triangle), the selection and random damage.
//!
//! Golden numbers come from `cargo run --release -p whet-sharpen --example
//! normal_filter_figures` (docs/results.md, "Normal-filter sharpener"), with the Metro sample
//! count lowered to 100k here; bounds sit about 25 % under the measured gains.

use proptest::prelude::*;
use whet_mesh::Mesh;
use whet_sharpen::{sharpen, sharpen_region, Method, SharpenOptions, Sharpened, VertexSelection};
use whet_synth::{add_noise, marching_cubes, Shape, ShapeKind, ShapeParams};
use whet_testkit::meshes;

use crate::support::{check, error, rotations};

fn nf() -> SharpenOptions {
    SharpenOptions::DEFAULT.with_method(Method::NormalFilter)
}

fn shape(kind: ShapeKind, rot: usize) -> Shape {
    Shape::new(
        kind,
        &ShapeParams::default().with_rotation(rotations()[rot]),
    )
    .unwrap()
}

/// Output triangles facing against the input triangle they come from.
fn flipped(input: &Mesh, out: &Sharpened) -> usize {
    let n = input.face_normals();
    (0..out.mesh.triangles.len())
        .filter(|&t| out.mesh.face_cross(t).dot(n[out.parents[t].index()]) <= 0.0)
        .count()
}

/// The guarantees every output keeps.
fn assert_valid(input: &Mesh, out: &Sharpened) {
    let before = input.topology_report();
    let after = out.mesh.topology_report();
    assert!(after.manifold && after.oriented, "{:?}", after.problems);
    assert_eq!(after.boundary_edges, before.boundary_edges);
    assert_eq!(out.parents.len(), out.mesh.triangles.len());
    assert_eq!(flipped(input, out), 0);
    assert_eq!(
        out.mesh.positions.len() + out.report.collapses,
        input.positions.len()
    );
}

#[test]
fn blend_sampling_is_sharpened_to_the_box() {
    // Fillet radius 0.04 sampled at 64 (2.6 steps): measured 6.85x (r0) and 6.77x (r1) RMS.
    for rot in 0..2 {
        let truth = shape(ShapeKind::Box, rot).truth_mesh();
        let input = marching_cubes(&shape(ShapeKind::Blend, rot), 64).unwrap();
        let out = sharpen(&input, &nf()).unwrap();
        assert_valid(&input, &out);
        let (e0, e1) = (
            error(&truth, &input, Some(100_000)),
            error(&truth, &out.mesh, Some(100_000)),
        );
        assert!(e0.rms_pct / e1.rms_pct > 5.0, "r{rot}: {e0:?} -> {e1:?}");
        assert!(e1.max_pct < e0.max_pct / 2.0, "r{rot}: {e0:?} -> {e1:?}");
        let c = check(&truth, &input, &out);
        assert!(c.reversed <= 2, "r{rot}: {} reversed", c.reversed);
        let r = &out.report;
        assert!(r.feature_faces > 0 && r.filtered_normals > r.feature_faces * 9 / 10);
        assert!(
            r.absolute_feature_vertices > 0 && r.feature_vertices > r.absolute_feature_vertices
        );
        assert!(!out.tags.edges.is_empty());
    }
}

#[test]
fn chamfered_box_sampling_gains_at_least_twice() {
    // Marching cubes of the box at 32: measured 2.66x (r0) and 2.41x (r1) RMS.
    for rot in 0..2 {
        let truth = shape(ShapeKind::Box, rot).truth_mesh();
        let input = marching_cubes(&shape(ShapeKind::Box, rot), 32).unwrap();
        let out = sharpen(&input, &nf()).unwrap();
        assert_valid(&input, &out);
        let (e0, e1) = (
            error(&truth, &input, Some(100_000)),
            error(&truth, &out.mesh, Some(100_000)),
        );
        assert!(e0.rms_pct / e1.rms_pct > 2.0, "r{rot}: {e0:?} -> {e1:?}");
    }
}

#[test]
fn noisy_box_sampling_is_denoised_then_sharpened() {
    // Marching cubes of the box at 32 with `--noise 0.3` (seed 7): measured 2.27x (r0) and
    // 2.15x (r1) RMS with 100k Metro samples (0.38x and 0.36x before the denoising pass). The
    // bound sits under the measurement by the spread of the sampling, not 25 %: the target
    // itself is 2x.
    for rot in 0..2 {
        let truth = shape(ShapeKind::Box, rot).truth_mesh();
        let input = add_noise(
            &marching_cubes(&shape(ShapeKind::Box, rot), 32).unwrap(),
            0.3,
            7,
        );
        let out = sharpen(&input, &nf()).unwrap();
        assert_valid(&input, &out);
        let (e0, e1) = (
            error(&truth, &input, Some(100_000)),
            error(&truth, &out.mesh, Some(100_000)),
        );
        assert!(e0.rms_pct / e1.rms_pct > 2.0, "r{rot}: {e0:?} -> {e1:?}");
        let c = check(&truth, &input, &out);
        assert!(c.reversed <= 12, "r{rot}: {} reversed", c.reversed);
    }
}

#[test]
fn non_uniform_samplings_are_refused() {
    // The exact blend mesh: two triangles per flat side, strips of needles on the fillets
    // (faces with an edge over 8 L cover 98-99 % of it). The method made it 3-4x worse before
    // it refused it.
    for rot in 0..2 {
        let input = shape(ShapeKind::Blend, rot).truth_mesh();
        match sharpen(&input, &nf()) {
            Err(whet_sharpen::Error::Parameter(m)) => {
                assert!(m.contains("roughly uniform sampling"), "{m}")
            }
            other => panic!("r{rot}: {:?}", other.map(|s| s.report)),
        }
    }
    // A clean sampling of the same shape is accepted.
    let mc = marching_cubes(&shape(ShapeKind::Blend, 0), 24).unwrap();
    assert!(sharpen(&mc, &nf()).is_ok());
}

#[test]
fn already_sharp_meshes_are_left_alone() {
    // The box truth mesh: every edge is a true crease, which lambda keeps out of every
    // neighbourhood, so nothing is a feature.
    let truth = shape(ShapeKind::Box, 0).truth_mesh();
    let out = sharpen(&truth, &nf()).unwrap();
    assert_eq!(out.report.feature_faces, 0);
    assert_eq!(out.mesh, truth);
}

#[test]
fn the_selection_limits_the_work() {
    let input = marching_cubes(&shape(ShapeKind::Blend, 0), 32).unwrap();
    // The vertices in the upper half (in the rotated frame's y).
    let sel: Vec<u32> = (0..input.positions.len() as u32)
        .filter(|&v| input.positions[v as usize].y > 0.1)
        .collect();
    let selection = VertexSelection::parse(
        &format!(
            "# upper half\n{}\n",
            sel.iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(" ")
        ),
        input.positions.len(),
    )
    .unwrap();
    let out = sharpen_region(&input, &nf(), &selection).unwrap();
    assert_valid(&input, &out);
    let all = sharpen(&input, &nf()).unwrap();
    assert!(out.report.feature_faces > 0);
    assert!(out.report.feature_faces < all.report.feature_faces);
    let mut selected = vec![false; input.positions.len()];
    for &v in &sel {
        selected[v as usize] = true;
    }
    // Unselected vertices neither move nor disappear: each input position is still there.
    let mut outs: Vec<[u64; 3]> = out
        .mesh
        .positions
        .iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect();
    outs.sort_unstable();
    for (i, p) in input.positions.iter().enumerate() {
        if !selected[i] {
            let k = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
            assert!(
                outs.binary_search(&k).is_ok(),
                "unselected vertex {i} moved"
            );
        }
    }
}

#[test]
fn holes_keep_their_boundary() {
    let mc = marching_cubes(&shape(ShapeKind::Blend, 1), 40).unwrap();
    let punched = meshes::punch(&mc, |t| t % 97 == 0);
    let out = sharpen(&punched, &nf()).unwrap();
    assert_valid(&punched, &out);
    assert!(out.report.feature_faces > 0);
}

#[test]
fn json_has_the_method_counts() {
    let input = marching_cubes(&shape(ShapeKind::Box, 0), 16).unwrap();
    let j = sharpen(&input, &nf()).unwrap().report.to_json();
    for key in [
        "\"method\":\"normal-filter\"",
        "\"feature_faces\":",
        "\"feature_vertices\":",
        "\"absolute_feature_vertices\":",
        "\"filtered_normals\":",
        "\"flips_avoided\":",
        "\"swaps\":",
        "\"collapses\":",
        "\"detection_ms\":",
        "\"filtering_ms\":",
        "\"updating_ms\":",
        "\"chamfer_edges\":0",
    ] {
        assert!(j.contains(key), "{key} in {j}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    #[test]
    fn guarantees_hold_on_random_damage(
        kind in prop::sample::select(vec![ShapeKind::Box, ShapeKind::Blend, ShapeKind::Fandisk, ShapeKind::Pyramid]),
        res in 8usize..24,
        rot in 0usize..2,
        noise in 0.0f64..0.5,
        seed in any::<u64>(),
        holes in 0usize..30,
        rho in 1.0f64..6.0,
        eta in -0.2f64..0.9,
    ) {
        let mut mesh = add_noise(&marching_cubes(&shape(kind, rot), res).unwrap(), noise, seed);
        if holes > 0 {
            mesh = meshes::punch(&mesh, |t| (t as u64).wrapping_mul(seed | 1) % (holes as u64 + 7) == 0);
        }
        let out = sharpen(&mesh, &nf().with_rho(rho).with_eta(eta)).unwrap();
        let before = mesh.topology_report();
        let after = out.mesh.topology_report();
        prop_assert!(after.manifold && after.oriented);
        prop_assert_eq!(after.boundary_edges, before.boundary_edges, "boundary");
        prop_assert_eq!(flipped(&mesh, &out), 0, "flipped");
        prop_assert!(out.mesh.positions.iter().all(|p| p.is_finite()));
    }
}
