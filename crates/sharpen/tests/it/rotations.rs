//! The output guarantees under rotations the figure tables do not use: random generic
//! rotations of every synth shape, and (a known defect, ignored) rotations within two degrees
//! of the grid axes, where the pyramid's planes pass through grid points in regular patterns.

use glam::{DQuat, DVec3};
use whet_sharpen::{sharpen, SharpenOptions};
use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};

use crate::support::check;

use whet_testkit::Lcg;

/// The shapes the sweeps cycle through.
const KINDS: [ShapeKind; 4] = [
    ShapeKind::Cube,
    ShapeKind::Fandisk,
    ShapeKind::Pyramid,
    ShapeKind::TorusBox,
];

/// The next random case of a sweep: case `i`'s shape, a resolution from 24 to
/// `24 + res_span - 1`, a random axis and an angle up to `angle_scale` half-turns.
fn next_case(
    rng: &mut Lcg,
    i: usize,
    res_span: f64,
    angle_scale: f64,
) -> (Shape, usize, DVec3, f64) {
    let kind = KINDS[i % KINDS.len()];
    let res = 24 + (rng.unit() * res_span) as usize;
    let axis = DVec3::new(
        rng.unit() * 2.0 - 1.0,
        rng.unit() * 2.0 - 1.0,
        rng.unit() * 2.0 - 1.0 + 1e-3,
    )
    .normalize();
    let angle = rng.unit() * std::f64::consts::PI * angle_scale;
    let params = ShapeParams::default().with_rotation(DQuat::from_axis_angle(axis, angle));
    (Shape::new(kind, &params).unwrap(), res, axis, angle)
}

/// Sharpens `cases` marching-cubes samplings (resolutions 24-63) rotated by random angles
/// scaled by `angle_scale` about random axes, and returns the failures of the output
/// guarantees: manifold, same boundary, no new angle under 1 degree, under 1 % of the new
/// triangles reversed against the truth (`support::reversed`). Also prints the count of
/// *folds*: new triangles lying on the truth face nearest their centroid (corners within a
/// fifth of the longest edge of its plane) and facing within 26 degrees of its opposite.
fn failures(seed: u64, cases: usize, angle_scale: f64) -> Vec<String> {
    let mut rng = Lcg(seed);
    let mut failed = Vec::new();
    let (mut folds, mut new) = (0usize, 0usize);
    for i in 0..cases {
        let (shape, res, axis, angle) = next_case(&mut rng, i, 40.0, angle_scale);
        let kind = shape.kind();
        let input = marching_cubes(&shape, res).unwrap();
        let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
        let truth = shape.truth_mesh();
        let c = check(&truth, &input, &out);
        folds += fold_count(&truth, &input, &out);
        new += c.new_triangles;
        if !c.manifold
            || c.new_boundary_edges != 0
            || c.min_new_angle < 1.0 - 1e-9
            || c.reversed * 100 > c.new_triangles.max(100)
        {
            failed.push(format!(
                "{} res {res} axis {axis:.3} angle {angle:.4}: {c:?}",
                kind.name()
            ));
        }
    }
    eprintln!("{cases} cases: {folds} folds in {new} new triangles");
    failed
}

/// New triangles of `out` folded onto the truth face nearest their centroid.
fn fold_count(
    truth: &whet_mesh::Mesh,
    input: &whet_mesh::Mesh,
    out: &whet_sharpen::Sharpened,
) -> usize {
    let bvh = whet_metro::Bvh::new(truth);
    let normals = truth.face_normals();
    let keys = input.sorted_vertex_sets();
    let nv = input.positions.len();
    let mut folds = 0;
    for (t, tri) in out.mesh.triangles.iter().enumerate() {
        let mut k = *tri;
        k.sort_unstable();
        let unchanged = tri.iter().all(|&v| {
            (v as usize) < nv && out.mesh.positions[v as usize] == input.positions[v as usize]
        });
        if unchanged && keys.binary_search(&k).is_ok() {
            continue;
        }
        let p = out.mesh.triangle_positions(t);
        let hit = bvh.closest_point((p[0] + p[1] + p[2]) / 3.0).triangle as usize;
        let (n, a) = (
            normals[hit],
            truth.positions[truth.triangles[hit][0] as usize],
        );
        let longest = (0..3)
            .map(|k| p[k].distance(p[(k + 1) % 3]))
            .fold(0.0f64, f64::max);
        let d = p
            .iter()
            .map(|x| (*x - a).dot(n).abs())
            .fold(0.0f64, f64::max);
        let facing = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero().dot(n);
        if facing < -0.9 && d < 0.2 * longest {
            folds += 1;
        }
    }
    folds
}

#[test]
fn generic_rotations_keep_the_output_guarantees() {
    // Measured 2026-12-02 over 300 such cases at resolutions 32-95: one failure, a pyramid
    // turned by 0.4 degrees (a near-axis-aligned case, below).
    let failed = failures(7, 24, 1.0);
    assert!(failed.is_empty(), "{failed:#?}");
}

#[test]
#[ignore = "known gap: pyramids turned by under 2 degrees exceed 1 % reversed by the truth check"]
fn near_axis_aligned_rotations_keep_the_output_guarantees() {
    // Measured 2026-12-03: 57 of these 300 cases fail, all pyramids (1-10 % of the new
    // triangles). Most of it is the check: chamfer pieces parallel to a side face and 0.2
    // edges inside it lie within its tolerance of the base plane across the 58-degree crease
    // and are judged against the base. Real folds (pieces lying on the nearest truth face and
    // within 26 degrees of facing against it) were 87 of 767k new triangles over the 300
    // cases, never 1 % of a case, and are 8 since the sharpener's own test also looks for
    // pieces folded onto any plane of their vertices (both counts printed by this test,
    // `--nocapture`; 87 with 1ebcc01 reverted); 9 with settling's move of the vertex a snap
    // folds over (docs/sharpen.md, step 12), which also took one case from under 1 % to
    // 1.04 % (56 failures before it); 45 failures and 8 folds after the strip arms, 43 and
    // 10 (in 811,700 new triangles) with the clusters welded up front; 24 and 3 (in 779,651)
    // after settling's half moves and the sliver pass's coincident merge (2026-12-05). Run with
    // `cargo test -p whet-sharpen --test it -- --ignored near_axis --nocapture`.
    let failed = failures(12345, 300, 0.01);
    assert!(failed.is_empty(), "{} failures: {failed:#?}", failed.len());
}

/// Metro errors (100k samples a direction) of `kind` sampled at `res` cells, turned by
/// `angle` radians about `axis`, before and after sharpening with the defaults.
fn near_axis_case(
    kind: ShapeKind,
    res: usize,
    axis: DVec3,
    angle: f64,
) -> (crate::support::Error, crate::support::Error) {
    let params = ShapeParams::default().with_rotation(DQuat::from_axis_angle(axis, angle));
    let shape = Shape::new(kind, &params).unwrap();
    let input = marching_cubes(&shape, res).unwrap();
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    let truth = shape.truth_mesh();
    (
        crate::support::error(&truth, &input, Some(100_000)),
        crate::support::error(&truth, &out.mesh, Some(100_000)),
    )
}

/// Asserts that sharpening kept the max error and cut the RMS error by more than `rms_gain`.
fn assert_no_worse(before: &crate::support::Error, after: &crate::support::Error, rms_gain: f64) {
    assert!(
        after.max_pct <= before.max_pct && after.rms_pct * rms_gain < before.rms_pct,
        "max {:.3} -> {:.3} %, RMS {:.4} -> {:.4} %",
        before.max_pct,
        after.max_pct,
        before.rms_pct,
        after.rms_pct
    );
}

#[test]
fn a_coarse_near_axis_fandisk_keeps_its_max() {
    // A case of the near-axis sweep below: fandisk at 24 cells turned by 1.1 degrees. The
    // unlabelled-corner rule moved a crease vertex on the true surface 1.07 edges onto the
    // point of three regions of 8-9 triangles: max 2.851 % -> 4.093 % of the diagonal
    // (Metro, 100k samples a direction), 1.951 % since the rule needs larger regions
    // (`MIN_CORNER_REGION`; RMS 0.292 % -> 0.190 %).
    let axis = DVec3::new(0.16273488381328596, 0.8614438138841246, 0.4810737086050847);
    let (before, after) = near_axis_case(ShapeKind::Fandisk, 24, axis, 0.019456290220210046);
    assert_no_worse(&before, &after, 1.0);
}

#[test]
fn a_near_axis_hole_is_not_cut_into_a_polygon() {
    // A case of the near-axis sweep below: torus-box at 25 cells turned by 0.6 degrees. Its
    // hole, about three cells in radius, comes out of marching cubes as a band of 8 flat
    // grid-aligned strips, each a thin region; the crease lines of neighbouring strips lie
    // outside the round wall, and sharpening them moved a row of vertices into the part:
    // max 1.335 % -> 1.764 %, RMS 0.1510 % -> 0.1624 % of the diagonal (Metro, 100k samples a
    // direction). Since tubes of thin facets are left alone (`TUBE_FACETS`): max 1.311 %,
    // RMS 0.0930 %.
    let axis = DVec3::new(
        0.008343512590354957,
        0.23646319450722295,
        0.9716046230031503,
    );
    let (before, after) = near_axis_case(ShapeKind::TorusBox, 25, axis, 0.010425430626566435);
    // The RMS bound is loose (measured 1.62x), so that it holds whatever the next change
    // does to the hole's rim; the point is that the wall is not cut.
    assert_no_worse(&before, &after, 1.3);
}

#[test]
fn a_near_axis_concave_face_is_not_dug_into() {
    // Two cases of the near-axis sweep below. Fandisk at 33 cells turned by 0.28 degrees: a
    // concave face curved at the sampling's scale came out of marching cubes as two flat
    // regions meeting along a grid line, with the strip between them over both regions'
    // planes; snapping it onto their line dug a row of vertices 0.5 edges into the part:
    // max 1.128 % -> 1.481 %, RMS 0.1581 % -> 0.1168 % (Metro, 100k samples a direction).
    // Since concave blends are left alone (an edge with both ends outside its planes counts
    // like one with both inside): max 1.257 % (the rest is a corner), RMS 0.0976 %. Fandisk at
    // 36 cells turned by 1.5 degrees, the same kind of place: max 1.468 % -> 1.299 %, RMS
    // 0.1627 % -> 0.1062 % before, max 0.935 %, RMS 0.0959 % since.
    let axis = DVec3::new(
        -0.9327683263747987,
        0.28017306084211363,
        0.22681777992546842,
    );
    let (before, after) = near_axis_case(ShapeKind::Fandisk, 33, axis, 0.004890059476248357);
    assert!(
        after.max_pct < 1.35 && after.rms_pct * 1.5 < before.rms_pct,
        "fandisk 33: max {:.3} -> {:.3} %, RMS {:.4} -> {:.4} %",
        before.max_pct,
        after.max_pct,
        before.rms_pct,
        after.rms_pct
    );
    let axis = DVec3::new(-0.38495212459430195, 0.1145685948465951, 0.9157979574366879);
    let (before, after) = near_axis_case(ShapeKind::Fandisk, 36, axis, 0.026977849365721843);
    assert!(
        after.max_pct * 1.4 < before.max_pct,
        "fandisk 36: {after:?}"
    );
    assert_no_worse(&before, &after, 1.5);
}

#[test]
#[ignore = "known gap: 2 of 120 near-axis samplings at 33 and 37 cells come out with a larger max error"]
fn near_axis_aligned_rotations_never_make_the_error_worse() {
    // Measured 2026-12-05 (Metro, 100k samples a direction): 4 of these 120 cases had a
    // larger max than their input (fandisk at 24, 33 and 37 cells: 0.70x, 0.76x, 0.86x;
    // torus-box at 25: 0.76x, RMS 0.93x), none a larger RMS otherwise; 3 since the
    // unlabelled-corner rule needs regions of `MIN_CORNER_REGION` triangles (fandisk 24:
    // 1.46x, test `a_coarse_near_axis_fandisk_keeps_its_max`); 2 since tubes of thin facets are
    // left alone (torus-box 25: 1.02x, RMS 1.62x, test
    // `a_near_axis_hole_is_not_cut_into_a_polygon`); still 2 since concave blends are left
    // alone (fandisk 33: 0.76x -> 0.90x, test `a_near_axis_concave_face_is_not_dug_into`;
    // fandisk 36 and 38 max 1.13x and 1.29x -> 1.57x and 1.68x). Traced on fandisk 48
    // turned by 0.16 degrees (max 0.79x, `sharpen_diag` with `DIAG_ROT`): a cone split into
    // two smooth regions by a staircase along a grid line, whose two tangent planes and the
    // top face's meet 1.15 edges from the crease vertex that the unlabelled-corner rule moved
    // there (docs/results.md, "Near-axis samplings"). Run with `cargo test --release -p
    // whet-sharpen --test it -- --ignored never_make --nocapture`.
    let mut rng = Lcg(4242);
    let mut worse = Vec::new();
    for i in 0..120 {
        let (shape, res, axis, angle) = next_case(&mut rng, i, 60.0, 0.01);
        let kind = shape.kind();
        let input = marching_cubes(&shape, res).unwrap();
        let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
        let truth = shape.truth_mesh();
        let before = crate::support::error(&truth, &input, Some(100_000));
        let after = crate::support::error(&truth, &out.mesh, Some(100_000));
        let line = format!(
            "{} res {res} DIAG_ROT={},{},{},{}: RMS {:.4} -> {:.4} %, max {:.3} -> {:.3} %",
            kind.name(),
            axis.x,
            axis.y,
            axis.z,
            angle,
            before.rms_pct,
            after.rms_pct,
            before.max_pct,
            after.max_pct
        );
        eprintln!("{line}");
        if after.rms_pct > before.rms_pct || after.max_pct > before.max_pct {
            worse.push(line);
        }
    }
    assert!(worse.is_empty(), "{} worse: {worse:#?}", worse.len());
}
