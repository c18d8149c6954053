//! Issue 6 (EdgeSharpener) at test-suite scale: the figure targets as regression bounds on
//! coarse marching-cubes samplings, and the noise requirement.
//!
//! Where the bounds come from: the table of docs/results.md ("## EdgeSharpener", produced by
//! `cargo run --release -p whet-sharpen --example sharpen_figures -- synth`), rows "cube 32",
//! "pyramid 32" and "fandisk 32", whose gains are (papers / extended, RMS):
//! cube 2.07x, 1.67x / 3.69x, 5.66x; pyramid 1.76x, 1.80x / 3.29x, 2.61x;
//! fandisk 1.85x, 1.36x / 1.91x, 2.22x. The bounds below sit about 15 % under the smaller of
//! the two rotations (this suite measures with 50k Metro samples instead of the table's
//! default, which moves the figures by a few percent).

use whet_mesh::Mesh;
use whet_sharpen::{sharpen, SharpenOptions};
use whet_synth::{add_noise, marching_cubes, Shape, ShapeKind, ShapeParams};

use crate::support::{check, error, rotations};

const SAMPLES: Option<usize> = Some(50_000);

fn sampled(kind: ShapeKind, res: usize, rot: usize) -> (Mesh, Mesh) {
    let shape = Shape::new(
        kind,
        &ShapeParams::default().with_rotation(rotations()[rot]),
    )
    .unwrap();
    (shape.truth_mesh(), marching_cubes(&shape, res).unwrap())
}

/// RMS gains (papers, extended) on `kind` at resolution 32, for both rotations.
fn gains(kind: ShapeKind) -> [[f64; 2]; 2] {
    let mut g = [[0.0; 2]; 2];
    for rot in 0..2 {
        let (truth, input) = sampled(kind, 32, rot);
        let before = error(&truth, &input, SAMPLES);
        for (m, method) in crate::EDGE_SHARPENER.into_iter().enumerate() {
            let out = sharpen(&input, &SharpenOptions::DEFAULT.with_method(method)).unwrap();
            g[m][rot] = before.rms_pct / error(&truth, &out.mesh, SAMPLES).rms_pct;
        }
    }
    g
}

#[test]
fn issue6_rms_gains_on_marching_cubes() {
    // (shape, papers bound, extended bound)
    for (kind, papers, extended) in [
        (ShapeKind::Cube, 1.4, 3.1),
        (ShapeKind::Pyramid, 1.5, 2.2),
        (ShapeKind::Fandisk, 1.15, 1.6),
    ] {
        let [p, e] = gains(kind);
        assert!(
            p.iter().all(|&g| g >= papers),
            "{} papers {p:?}",
            kind.name()
        );
        assert!(
            e.iter().all(|&g| g >= extended),
            "{} extended {e:?}",
            kind.name()
        );
    }
}

#[test]
fn issue6_extended_reaches_the_corners() {
    // The papers barely move the max (their corners stay cut); the extended method's corner
    // vertices do. Cube at 32, rotation 1: max 1.71 % -> 0.66 % in the table (2.59x).
    let (truth, input) = sampled(ShapeKind::Cube, 32, 1);
    let before = error(&truth, &input, SAMPLES);
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    let after = error(&truth, &out.mesh, SAMPLES);
    assert!(
        before.max_pct / after.max_pct >= 2.0,
        "{before:?} -> {after:?}"
    );
    assert!(out.report.moved_input_vertices > 0);
}

#[test]
fn issue6_acute_corners_reach_their_point() {
    // The synth pyramid's base corners have interior angles of 58 degrees: marching cubes cuts
    // them 1.6-1.8 mean edges deep, past the support test's right-angle reach, which now
    // widens with the corner's acuteness. Pyramid 32, rotation 0 (docs/results.md): max
    // 2.62 % -> 1.63 % (1.61x) before, -> 1.21 % (2.16x) with it; RMS 3.11x -> 3.29x.
    let (truth, input) = sampled(ShapeKind::Pyramid, 32, 0);
    let before = error(&truth, &input, SAMPLES);
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    let after = error(&truth, &out.mesh, SAMPLES);
    assert!(
        before.max_pct / after.max_pct >= 1.9,
        "{before:?} -> {after:?}"
    );
}

#[test]
fn issue6_corner_vertices_survive_an_idle_neighbour_split() {
    // A corner vertex two edges from the cut corner's rim used to be given up when a rim
    // edge's split could not snap and its piece folded against the moved corner; the sliver
    // pass now undoes that split instead. Pyramid 64, rotation 1 (docs/results.md): RMS
    // 0.0700 % -> 0.0245 % (2.86x) before, -> 0.0225 % (3.11x); max 1.17 % -> 1.05 %.
    let (truth, input) = sampled(ShapeKind::Pyramid, 64, 1);
    let before = error(&truth, &input, SAMPLES);
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    let after = error(&truth, &out.mesh, SAMPLES);
    assert!(
        before.rms_pct / after.rms_pct >= 2.95,
        "{before:?} -> {after:?}"
    );
    let c = check(&truth, &input, &out);
    assert!(c.manifold && c.new_boundary_edges == 0);
    assert!(c.min_new_angle >= 1.0 - 1e-9, "{}", c.min_new_angle);
}

#[test]
fn issue6_corners_without_a_corner_triangle_are_reached() {
    // The synth fandisk at 128, rotation 0, has a corner whose cut left an unlabelled vertex
    // in its middle, so no corner triangle: it now moves onto the three-plane point itself.
    // docs/results.md: max 0.482 % -> 0.385 % (1.25x) before, -> 0.242 % (1.99x).
    let (truth, input) = sampled(ShapeKind::Fandisk, 128, 0);
    let before = error(&truth, &input, SAMPLES);
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    let after = error(&truth, &out.mesh, SAMPLES);
    assert!(
        before.max_pct / after.max_pct >= 1.7,
        "{before:?} -> {after:?}"
    );
}

#[test]
fn issue6_noise_never_makes_it_worse() {
    // Normal noise up to 100 % of the longest edge (seed 000 Figure 12): never worse than the
    // input (Metro against the truth), no new triangle reversed or under 1 degree.
    let (truth, clean) = sampled(ShapeKind::Cube, 24, 0);
    for amount in [0.1, 0.25, 0.5, 1.0] {
        let input = add_noise(&clean, amount, 7);
        let before = error(&truth, &input, SAMPLES);
        let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
        let after = error(&truth, &out.mesh, SAMPLES);
        let label = format!("noise {amount}");
        assert!(
            after.rms_pct <= before.rms_pct * 1.001,
            "{label}: {before:?} -> {after:?}"
        );
        assert!(
            after.max_pct <= before.max_pct * 1.001,
            "{label}: {before:?} -> {after:?}"
        );
        let c = check(&truth, &input, &out);
        assert!(c.manifold && c.new_boundary_edges == 0, "{label}");
        assert!(
            c.min_new_angle >= 1.0 - 1e-9,
            "{label}: {}",
            c.min_new_angle
        );
        assert_eq!(
            c.reversed, 0,
            "{label}: {} of {} new triangles reversed",
            c.reversed, c.new_triangles
        );
    }
}

#[test]
fn issue6_welding_clears_the_cluster_gaps() {
    // Marching cubes' clusters of near-coincident vertices block chamfer splits on the cube's
    // creases, which keep a gap there (docs/results.md, "Not reached"). Cube 64, rotation 0:
    // max 0.80 % -> 0.44 % without welding, 0.39 % with it (`sharpen_diag cube 64 0
    // extended`, with and without DIAG_NO_WELD; 2.06x, the 2x target).
    let (truth, input) = sampled(ShapeKind::Cube, 64, 0);
    let before = error(&truth, &input, SAMPLES);
    let plain = sharpen(&input, &SharpenOptions::DEFAULT.with_weld_clusters(false)).unwrap();
    let welded = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    assert_eq!(plain.report.welded_vertices, 0);
    assert!(welded.report.welded_vertices > 0);
    // The smooth threshold is the input's (summed in another order: equal to rounding).
    let (a, b) = (
        welded.report.smooth_threshold_degrees,
        plain.report.smooth_threshold_degrees,
    );
    assert!((a - b).abs() <= 1e-9 * b, "{a} {b}");
    let (p, w) = (
        error(&truth, &plain.mesh, SAMPLES),
        error(&truth, &welded.mesh, SAMPLES),
    );
    // Sampling moves the max by a few percent: bounds with that margin.
    assert!(w.max_pct < 0.95 * p.max_pct, "{p:?} -> {w:?}");
    assert!(before.max_pct / w.max_pct >= 1.9, "{before:?} -> {w:?}");
    assert!(w.rms_pct <= 1.02 * p.rms_pct, "{p:?} -> {w:?}");
    // The promise: input vertex i is output vertex i. Welded vertices keep their place and
    // are used by no triangle; every output triangle's parent is an input triangle.
    let mut used = vec![false; welded.mesh.positions.len()];
    for t in &welded.mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let unused = (0..input.positions.len()).filter(|&v| !used[v]).count();
    assert_eq!(unused, welded.report.welded_vertices);
    for v in (0..input.positions.len()).filter(|&v| !used[v]) {
        assert_eq!(welded.mesh.positions[v], input.positions[v]);
    }
    assert!(welded
        .parents
        .iter()
        .all(|p| p.index() < input.triangles.len()));
    let c = check(&truth, &input, &welded);
    assert!(c.manifold && c.new_boundary_edges == 0 && c.min_new_angle >= 1.0 - 1e-9);
    // The papers' method never welds.
    let papers = sharpen(&input, &SharpenOptions::PAPERS).unwrap();
    assert_eq!(papers.report.welded_vertices, 0);
    // A run that sharpens nothing comes back unwelded: a smooth marching-cubes sphere has
    // clusters too, and the welds join triangles across its slivers at angles above the
    // smooth threshold (a sphere at resolution 100 kept 306 tagged vertices that way); it
    // comes out exactly as without welding.
    let sphere = marching_cubes(
        &Shape::new(ShapeKind::Sphere, &ShapeParams::default()).unwrap(),
        48,
    )
    .unwrap();
    let (a, b) = (
        sharpen(&sphere, &SharpenOptions::DEFAULT).unwrap(),
        sharpen(&sphere, &SharpenOptions::DEFAULT.with_weld_clusters(false)).unwrap(),
    );
    assert_eq!(a.report.welded_vertices, 0);
    assert_eq!((a.mesh, a.tags), (b.mesh, b.tags));
}

#[test]
fn issue6_clusters_away_from_the_creases_keep_their_triangles() {
    // Every cluster is welded before the run and put back where the run left it untouched
    // (docs/sharpen.md step 10): deep inside the cube's faces, farther than 3.5 mean edges
    // from the truth's creases, every input triangle comes out as it went in, those of the
    // clusters there included. (3 edges until refused clusters got a second try: one welded
    // on its second try shares an input triangle with a touched cluster nearer the crease, so
    // both stay welded, and one triangle with a vertex 3.01 edges from the crease changed.)
    let (truth, input) = sampled(ShapeKind::Cube, 48, 1);
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    assert!(out.report.new_vertices > 0 && out.report.welded_vertices > 0);
    let table = whet_mesh::CornerTable::new(&input).unwrap();
    let edge = table.mean_edge_length(&input.positions);
    // The truth's creases: its edges whose triangles turn by more than 30 degrees.
    let truth_table = whet_mesh::CornerTable::new(&truth).unwrap();
    let normals = truth.face_normals();
    let mut creases = Vec::new();
    for (c, &o) in truth_table.opposites().iter().enumerate() {
        if (o as usize) > c && normals[c / 3].angle_between(normals[o as usize / 3]) > 0.5 {
            let t = truth.triangles[c / 3];
            let (a, b) = (t[(c + 1) % 3], t[(c + 2) % 3]);
            creases.push((truth.positions[a as usize], truth.positions[b as usize]));
        }
    }
    let deep = |p: glam::DVec3| {
        creases.iter().all(|&(a, b)| {
            let d = b - a;
            let s = ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
            p.distance(a + d * s) > 3.5 * edge
        })
    };
    let mut output: Vec<[u32; 3]> = out.mesh.triangles.clone();
    output.sort_unstable();
    let (mut kept, mut clustered) = (0, 0);
    for (t, tri) in input.triangles.iter().enumerate() {
        if !tri.iter().all(|&v| deep(input.positions[v as usize])) {
            continue;
        }
        let p = input.triangle_positions(t);
        let shortest = (0..3)
            .map(|k| p[k].distance(p[(k + 1) % 3]))
            .fold(f64::INFINITY, f64::min);
        if shortest < 0.05 * edge {
            clustered += 1;
        }
        assert!(
            output.binary_search(tri).is_ok(),
            "input triangle {t} changed"
        );
        assert!(tri
            .iter()
            .all(|&v| out.mesh.positions[v as usize] == input.positions[v as usize]));
        kept += 1;
    }
    // Deep triangles of clusters exist there (else the test shows nothing).
    assert!(kept > 1000 && clustered > 10, "{kept} {clustered}");
}

/// Max- and RMS-error gains of the default sharpener on `kind` at `res`, rotation `rot`, and
/// the output checks, after asserting that the output stays a manifold with no new boundary
/// edge.
fn gains_and_checks(kind: ShapeKind, res: usize, rot: usize) -> (f64, f64, crate::support::Checks) {
    let (truth, input) = sampled(kind, res, rot);
    let before = error(&truth, &input, SAMPLES);
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    let after = error(&truth, &out.mesh, SAMPLES);
    let c = check(&truth, &input, &out);
    assert!(c.manifold && c.new_boundary_edges == 0, "{}", kind.name());
    (
        before.max_pct / after.max_pct,
        before.rms_pct / after.rms_pct,
        c,
    )
}

/// [`gains_and_checks`] without the RMS gain.
fn max_gain_and_checks(kind: ShapeKind, res: usize, rot: usize) -> (f64, crate::support::Checks) {
    let (gain, _, c) = gains_and_checks(kind, res, rot);
    (gain, c)
}

#[test]
fn issue6_settling_moves_the_vertex_a_snap_folds_over() {
    // A snap that folds a piece over an input vertex left inside the cut used to be given up;
    // settling now moves that vertex onto the snapped vertices' planes or crease line instead
    // (docs/sharpen.md, "What we extend", step 12). Cube 64, rotation 1: max gain 2.09x ->
    // 2.62x in docs/results.md ("Moving the vertex a snap folds over", 1M samples), 2.09x ->
    // 2.62x here (50k samples; measured with the move turned off and on); the bound sits
    // between.
    let (gain, c) = max_gain_and_checks(ShapeKind::Cube, 64, 1);
    assert!(c.min_new_angle >= 1.0 - 1e-9, "{}", c.min_new_angle);
    assert!(gain >= 2.35, "{gain:.2}x");
}

#[test]
fn issue6_a_folding_corner_moves_the_triangle_leaning_across_the_crease() {
    // Pyramid 128, rotation 1: the worst base corner's snap folded an input triangle that
    // leans across the crease; judged against its own normal it refused the move that closes
    // the corner, judged like a piece (its vertices' planes) it takes it (docs/results.md,
    // "Moving the vertex a snap folds over": max gain 1.30x -> 1.84x at 1M samples; here, at
    // 50k samples, 1.31x before and 1.85x after).
    let (gain, _) = max_gain_and_checks(ShapeKind::Pyramid, 128, 1);
    assert!(gain >= 1.6, "{gain:.2}x");
}

#[test]
fn issue6_a_deep_corner_moves_the_vertex_inside_its_cut() {
    // Pyramid 64, rotation 1: the apex is cut 1.6 mean edges deep. Its corner vertex may now
    // move that far (CORNER_MOVE_LIMIT 1.75), and settling moves the input vertex it folds
    // over as deep as the corner vertex went (docs/sharpen.md, "What we extend", step 12).
    // docs/results.md ("A deep corner's inside vertex", 1M samples): max gain 1.26x -> 2.53x;
    // here, at 50k samples, 1.26x before and 2.54x after; the bound sits between.
    let (gain, c) = max_gain_and_checks(ShapeKind::Pyramid, 64, 1);
    assert!(c.min_new_angle >= 1.0 - 1e-9, "{}", c.min_new_angle);
    assert!(gain >= 2.0, "{gain:.2}x");
}

#[test]
fn issue6_one_noisy_neighbour_plane_does_not_refuse_a_crease_snap() {
    // Pyramid 48, rotation 1: a base-crease edge's snap onto the true crease was refused by
    // the consistency test because one neighbour's plane, borrowed by a vertex deep in the
    // acute cut, leans 7.7 degrees into the chamfer; one such miss is now allowed
    // (CONSISTENCY_MISSES). docs/results.md ("One noisy plane", 1M samples): max gain 1.63x
    // -> 2.16x; here, at 50k samples, 1.64x before and 2.16x after; the bound sits between.
    let (gain, c) = max_gain_and_checks(ShapeKind::Pyramid, 48, 1);
    assert!(c.min_new_angle >= 1.0 - 1e-9, "{}", c.min_new_angle);
    assert!(gain >= 1.9, "{gain:.2}x");
}

/// The max and RMS gains of the default sharpening of a synth sampling whose output keeps the
/// guarantees (manifold, no new boundary edge, no new angle under 1 degree).
fn sound_gains(kind: ShapeKind, res: usize, rot: usize) -> (f64, f64) {
    let (max_gain, rms_gain, c) = gains_and_checks(kind, res, rot);
    assert!(c.min_new_angle >= 1.0 - 1e-9, "{}", c.min_new_angle);
    (max_gain, rms_gain)
}

#[test]
fn issue6_a_vertex_inside_an_acute_cut_moves_onto_its_crease() {
    // Pyramid 128, rotation 1: a vertex 0.38 edges under both planes of a 58-degree base edge
    // took only one label (crease tolerance 0.3) and the crease had a gap of 2.4 edges there.
    // The tolerance and the move limit now widen with the wedge's acute reach, and the move,
    // which turned a chamfer triangle against its input normal once its neighbour moved onto
    // the crease too, gets a second chance with the other moves in place (docs/sharpen.md,
    // "What we extend", step 4). docs/results.md ("A vertex inside an acute cut", 1M samples):
    // max gain 1.84x -> 2.03x, RMS gain 5.34x -> 6.04x; here, at 50k samples, measured before
    // and after: max 1.85x -> 2.04x, RMS 5.14x -> 5.96x; the bounds sit between.
    let (max_gain, rms_gain) = sound_gains(ShapeKind::Pyramid, 128, 1);
    assert!(max_gain >= 1.95, "{max_gain:.2}x");
    assert!(rms_gain >= 5.6, "{rms_gain:.2}x");
}

#[test]
fn issue6_a_chamfer_strip_joined_to_a_face_is_demoted() {
    // Fandisk 64, rotation 1: a crease that fades out has its chamfer strip joined, through
    // smooth edges around the crease's end, to one face; it was one thick region with that
    // face, and the whole crease kept its chamfer. The strip's edges with the face turn by
    // the chamfer's angle inside the region, and the strip side of them is now demoted
    // (docs/sharpen.md, "What we extend", step 2). docs/results.md ("Strip arms", 1M
    // samples): RMS gain 2.52x -> 4.16x, max gain 1.49x -> 2.13x; here, at 50k samples,
    // measured before and after: RMS 2.56x -> 4.22x, max 1.49x -> 2.19x; the bounds sit between.
    let (max_gain, rms_gain) = sound_gains(ShapeKind::Fandisk, 64, 1);
    assert!(rms_gain >= 3.3, "{rms_gain:.2}x");
    assert!(max_gain >= 1.85, "{max_gain:.2}x");
}

#[test]
fn issue6_a_split_past_a_corner_moves_onto_the_corner() {
    // Fandisk 96, rotation 0: at a corner where three surfaces meet, an edge from a vertex on
    // one crease to a vertex of the third face had its split snapped onto the line of a
    // crease past the corner (half an edge under the third plane), folding a piece; settling
    // put it back at rest, 0.34 % off the surface. The split now moves onto the three planes'
    // point instead (docs/sharpen.md, "What we extend", step 12). docs/results.md ("A split
    // past a corner", 1M samples): max gain 1.70x -> 2.10x; here, at 50k samples, measured
    // before and after: 1.88x -> 2.22x; the bound sits between. Since a lone triangle's
    // label takes the ring's plane (2026-12-07), two splits beside the third face's corner
    // snap onto the crease and leave a sliver; unsnapped by the sliver pass they sat at their
    // edges' midpoints (1.89x here), and they now move half way back first (docs/sharpen.md,
    // "The sliver pass", step 4).
    let (max_gain, _) = sound_gains(ShapeKind::Fandisk, 96, 0);
    assert!(max_gain >= 2.05, "{max_gain:.2}x");
}

#[test]
fn issue6_twin_corner_triangles_share_one_centre() {
    // Cube 48, rotation 1: two corner triangles across a chamfer edge snapped their centres
    // to nearly one corner point (0.06 edges apart); the pieces between the two centres
    // folded and settling unsnapped one, leaving the corner half cut. They now share one
    // centre, a fan over both triangles (docs/sharpen.md, "What we extend", step 13).
    // docs/results.md ("Twin corner triangles", 1M samples): max gain 2.35x -> 3.16x; here,
    // at 50k samples, measured before and after: 2.42x -> 3.16x; the bound sits between.
    let (max_gain, _) = sound_gains(ShapeKind::Cube, 48, 1);
    assert!(max_gain >= 2.8, "{max_gain:.2}x");
    // The report counts the pairs (two on this sampling, one at each of two opposite
    // corners: measured), and the papers' method has none.
    let (_, input) = sampled(ShapeKind::Cube, 48, 1);
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    assert_eq!(out.report.twin_corners, 2);
    assert!(out.report.to_json().contains("\"twin_corners\":2"));
    let papers = SharpenOptions::DEFAULT.with_method(whet_sharpen::Method::Papers);
    assert_eq!(sharpen(&input, &papers).unwrap().report.twin_corners, 0);
}

#[test]
fn issue6_a_split_folding_a_corner_centre_joins_it() {
    // A corner triangle's centre snapped onto its corner, and a split of one of its edges
    // onto a crease line from that corner; the fan folded over the split and settling gave
    // up the centre, leaving the corner cut. The split now joins the centre on the corner
    // and the sliver pass collapses the zero-length edge (docs/sharpen.md, "What we extend",
    // step 14; docs/results.md, "A split joining its corner's centre", 1M samples: cube 64
    // r0 max gain 2.06x -> 2.86x, fandisk 48 r0 1.96x -> 2.18x). Measured here before and
    // after: cube 64 r0 at 50k samples 2.07x -> 2.86x; the bound sits between.
    let (max_gain, _) = sound_gains(ShapeKind::Cube, 64, 0);
    assert!(max_gain >= 2.5, "{max_gain:.2}x");
    // On fandisk 48 r0 the joined split's pieces are zero-area triangles whose two angles at
    // the coincident vertices are undefined; the sliver pass used to rank them by angle and
    // collapsed the corner into an input vertex an edge away. It now ranks a triangle's
    // corners by their opposite sides (exact, and defined there). 300k samples (50k miss
    // the corner), measured: 2.01x before, 1.89x with the join alone, 2.19x with both.
    let (truth, input) = sampled(ShapeKind::Fandisk, 48, 0);
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    let samples = Some(300_000);
    let gain = error(&truth, &input, samples).max_pct / error(&truth, &out.mesh, samples).max_pct;
    assert!(gain >= 2.1, "{gain:.2}x");
}

#[test]
fn issue6_a_corner_keeps_its_vertex_over_a_triangle_marching_cubes_folded() {
    // Pyramid 96, rotation 0: a base corner's corner vertex moved onto the true corner, and
    // settling unsnapped it because a whole input triangle around it faced against its
    // vertices' plane; it did so at rest already (marching cubes folded it). Settling now
    // leaves such a triangle to the sliver pass, which repairs it (docs/sharpen.md, "What
    // we extend", step 15; docs/results.md, "Input triangles folded at rest", 1M samples:
    // max gain 1.71x -> 2.54x). Measured here at 50k samples: 1.71x before, 2.55x after;
    // the bound sits between.
    let (max_gain, _) = sound_gains(ShapeKind::Pyramid, 96, 0);
    assert!(max_gain >= 2.2, "{max_gain:.2}x");
}

#[test]
fn issue6_a_cluster_refused_for_its_neighbours_sliver_is_welded_after_it() {
    // Cube 32, rotation 0: two marching-cubes clusters sit across one triangle, one on each
    // face of a crease. Welded first, the one refused because the triangle between them
    // would become a sliver (its other short edge is the second cluster's); the second then
    // welded, the first stayed, and its needle blocked the move of the vertex inside the cut
    // onto the crease. Refused clusters now get one more try after the others (docs/
    // sharpen.md, "What we extend", step 10; docs/results.md, "A second try for refused
    // clusters", 1M samples: max gain 1.62x -> 2.22x). Measured here at 50k samples before
    // and after: 1.62x -> 2.22x, 39 -> 42 welded vertices; the bound sits between. The
    // count is of vertices still welded after the run (the clusters it left untouched are
    // put back): with strip arms found from a turn of 2 smooth thresholds instead of 3
    // (2026-12-05) the run sharpens more around clusters and 48 stay welded.
    let (max_gain, _) = sound_gains(ShapeKind::Cube, 32, 0);
    assert!(max_gain >= 2.0, "{max_gain:.2}x");
    let (_, input) = sampled(ShapeKind::Cube, 32, 0);
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    assert_eq!(out.report.welded_vertices, 48);
}

#[test]
fn issue6_chamfer_vertices_a_third_of_an_edge_from_their_second_plane_join_the_crease() {
    // Cube 64, rotation 0: chamfer vertices between 0.3 and 0.35 mean edges from their second
    // plane kept one label and stayed inside the cut. The crease tolerance is now 0.35
    // (docs/sharpen.md, "What we extend", step 4; docs/results.md, "Crease tolerance", 1M
    // samples: RMS gain 6.27x -> 7.28x, max gain 2.86x both). Measured here at 50k samples
    // before and after: RMS 6.11x -> 7.02x, max 2.86x both; the RMS bound sits between, and
    // the max may not drop.
    let (max_gain, rms_gain) = sound_gains(ShapeKind::Cube, 64, 0);
    assert!(rms_gain >= 6.6, "{rms_gain:.2}x");
    assert!(max_gain >= 2.8, "{max_gain:.2}x");
}

#[test]
fn issue6_a_gray_vertex_inside_an_acute_cut_takes_its_plane() {
    // Pyramid 64, rotation 0: vertices inside the cuts of the 58-degree base edges lie up to
    // 1.46 times deeper under the plane they belong to than in a right-angled cut, beyond the
    // gray tolerance (0.4 edges), and stayed unlabelled. The tolerance now widens with the
    // wedge's acute reach, as step 4's does (docs/sharpen.md, "What we extend", step 3;
    // docs/results.md, "Gray vertices in acute cuts", 1M samples: max gain 2.85x -> 3.64x).
    // Measured here at 50k samples before and after: max 2.86x -> 3.64x, RMS 6.61x -> 7.11x;
    // the bounds sit between.
    let (max_gain, rms_gain) = sound_gains(ShapeKind::Pyramid, 64, 0);
    assert!(max_gain >= 3.2, "{max_gain:.2}x");
    assert!(rms_gain >= 6.85, "{rms_gain:.2}x");
}

#[test]
fn issue6_a_rounded_blend_is_not_sharpened_into_a_crease() {
    // Synth blend (the box with every edge filleted, radius 0.04: about two cells at 64): the
    // extended method labelled both sides of each fillet, split its edges and snapped them
    // onto the faces' line, 0.41 radii above the arc. Creases whose chamfer edges mostly join
    // vertices inside both of their planes are now taken for blends and left alone
    // (docs/sharpen.md, "What we extend", step 5; docs/results.md, "Rounded blends").
    // Measured here (sharpen_diag, 50k samples) before and after, the input at 0.0251 % and
    // 0.0234 % RMS: r0 RMS 0.0781 % -> 0.0251 %, max 1.128 % -> 0.188 % (the input's); r1
    // RMS 0.0715 % -> 0.0238 %, max 0.928 % -> 0.298 % (input 0.196 %: still worse, see
    // "Not reached"). The bounds allow 5 % over the input's RMS and, at r0, its max.
    for rot in 0..2 {
        let (truth, input) = sampled(ShapeKind::Blend, 64, rot);
        let before = error(&truth, &input, SAMPLES);
        let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
        let after = error(&truth, &out.mesh, SAMPLES);
        assert!(
            after.rms_pct <= 1.05 * before.rms_pct,
            "r{rot} RMS {:.4} % -> {:.4} %",
            before.rms_pct,
            after.rms_pct
        );
        if rot == 0 {
            assert!(
                after.max_pct <= 1.05 * before.max_pct,
                "max {:.3} % -> {:.3} %",
                before.max_pct,
                after.max_pct
            );
        }
    }
}

#[test]
fn issue6_a_piece_its_split_turned_towards_its_plane_keeps_the_split() {
    // Next to a corner, a chamfer triangle leaning towards the third surface faced against
    // the plane its piece lies on best already at rest; the split's move turned the piece
    // towards that plane, and settling unsnapped the split for it. Settling now leaves such
    // pieces to the sliver pass, as it did whole triangles marching cubes folded, and first
    // moves a split that reverses a piece back half way (docs/sharpen.md, "What we extend",
    // steps 15 and 16; docs/results.md, "Pieces folded at rest, and half a move", 1M
    // samples: pyramid 96 r1 max gain 2.67x -> 3.20x). Measured here at 50k samples: 2.67x
    // before, 3.22x after; the bound sits between.
    let (max_gain, _) = sound_gains(ShapeKind::Pyramid, 96, 1);
    assert!(max_gain >= 2.95, "{max_gain:.2}x");
}

#[test]
fn issue6_coincident_corner_vertices_merge_in_place() {
    // Fandisk 64, rotation 0: a moved corner vertex, a split joined to the corner and a
    // corner triangle's centre sat on one point. No two of them in one triangle could
    // collapse first (the third is a common neighbour too), and the sliver pass's best other
    // operation collapsed the split into the far end of its edge, bringing back an input
    // edge that crossed the corner half an edge off the part. A new vertex now merges into a
    // coincident neighbour first, in or out of the triangle (docs/sharpen.md, "The sliver
    // pass"; docs/results.md, "Coincident vertices merge in place", 1M samples: max gain
    // 1.70x -> 2.11x). Measured here at 50k samples: 1.75x before, 2.24x after; the bound
    // sits between.
    let (max_gain, _) = sound_gains(ShapeKind::Fandisk, 64, 0);
    assert!(max_gain >= 2.0, "{max_gain:.2}x");
}

#[test]
fn issue6_a_narrow_faces_end_is_not_taken_for_a_cut_corner() {
    // Synth thin-face (the box with one edge cut by a 45-degree face 0.02 wide, about 1.8
    // mean edges at 99 cells) at a generic rotation of `generic_sweep 303 180`. At the face's
    // end, a vertex on it lies under the planes of the two faces it separates and of the end
    // face, as a vertex inside a marching-cubes cut corner does, and the unlabelled-corner
    // rule moved it 1.2 edges out onto their point, the corner the face cut off: max 0.591 ->
    // 0.680 % (the input's max is elsewhere). The three surfaces must now meet pairwise in
    // creases near the vertex, and the narrow face keeps two of them apart (docs/sharpen.md,
    // step 4; docs/results.md, "A narrow face's end is no cut corner"). Measured here at 50k
    // samples: max 0.591 % -> 0.680 % before, 0.326 % after (RMS 0.0330 % -> 0.0073 % and
    // 0.0069 %). The input's max lies elsewhere, so the bound sits between the two outputs'.
    let axis = glam::DVec3::new(
        -0.9296184940381779,
        -0.3617881832067612,
        0.07013391500651672,
    );
    let rotation = glam::DQuat::from_axis_angle(axis.normalize(), 0.18750234813545358);
    let shape = Shape::new(
        ShapeKind::ThinFace,
        &ShapeParams::default().with_rotation(rotation),
    )
    .unwrap();
    let (truth, input) = (shape.truth_mesh(), marching_cubes(&shape, 99).unwrap());
    let before = error(&truth, &input, SAMPLES);
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    let after = error(&truth, &out.mesh, SAMPLES);
    assert!(
        after.max_pct < 0.45,
        "max {:.3} % -> {:.3} %",
        before.max_pct,
        after.max_pct
    );
}

/// A shared fixture turned about `axis` by `angle` radians and sampled by marching cubes at
/// `res` cells, with its Metro figures (50k samples) before and after sharpening.
fn turned_fixture(
    name: &str,
    axis: [f64; 3],
    angle: f64,
    res: usize,
) -> (crate::support::Error, crate::support::Error) {
    let original = whet_io::read_path(&whet_testkit::shared_fixture(name), None).unwrap();
    let rotation = glam::DQuat::from_axis_angle(glam::DVec3::from(axis).normalize(), angle);
    let (truth, input) = crate::support::turned_sampling(&original, rotation, res).unwrap();
    let out = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    (
        error(&truth, &input, SAMPLES),
        error(&truth, &out.mesh, SAMPLES),
    )
}

#[test]
fn issue6_a_corner_lies_on_the_surface_its_vertices_share() {
    // cad_bracket turned as case 12 of `fixture_sweep 4 100` (41 cells). A corner triangle
    // there has one vertex on face B, one on faces A and C, one on A and D: four faces meeting
    // two by two. The three-plane point of B, C and D stood 0.8 mean edges above A, which both
    // of the other vertices lie on, and became the max: 0.943 % -> 1.367 %. The corner must
    // now lie on a surface two of its vertices share (docs/sharpen.md, step 21; docs/results.md,
    // "Fixtures at any angle"). Measured here: max 0.943 % -> 0.707 %, RMS 2.58x better.
    let (before, after) = turned_fixture(
        "cad_bracket.off",
        [-0.6936184766204092, 0.6825215556518187, 0.23034264685768463],
        1.7092014399078883,
        41,
    );
    assert!(
        after.max_pct < 0.85 && after.max_pct < before.max_pct,
        "max {:.3} % -> {:.3} %",
        before.max_pct,
        after.max_pct
    );
    assert!(after.rms_pct * 2.0 < before.rms_pct);
}

#[test]
fn issue6_an_acute_wedge_ends_at_the_face_that_cuts_it_off() {
    // fandisk turned as case 60 of `fixture_sweep 7 100` (38 cells). Two faces meeting at
    // 29 degrees, whose edge a third face truncates at a width the sampling does not resolve:
    // the wedge's chamfer edges were snapped onto the two faces' line 1.1 mean edges past the
    // third face's plane, into the air: max 1.236 % -> 1.963 %. A snap of an acute pair now
    // stops at the plane of a convex neighbouring face (docs/sharpen.md, step 21). Measured
    // here: max 1.236 % -> 1.119 %, RMS 1.74x better.
    let (before, after) = turned_fixture(
        "fandisk.off",
        [0.559133811781437, 0.8274268429690071, -0.05228957885757527],
        1.3542597377255352,
        38,
    );
    assert!(
        after.max_pct < before.max_pct,
        "max {:.3} % -> {:.3} %",
        before.max_pct,
        after.max_pct
    );
    assert!(after.rms_pct * 1.5 < before.rms_pct);
}

#[test]
fn issue6_a_corner_triangle_on_an_acute_wedge_ends_at_the_face_that_cuts_it_off() {
    // fandisk turned as case 60 of `fixture_sweep 3 100` (34 cells). A corner triangle at the
    // end of the 29-degree fin has its vertices on the fin's two faces and the face truncating
    // it, whose three planes give no corner point the checks accept. The fallback, the line of
    // two of its planes, took the fin's two faces and put the triangle's new vertex 2.7 mean
    // edges past the truncating face, into the air: max 1.890 % -> 2.741 %. That fallback now
    // stops at a cutting face as edge snaps do (docs/sharpen.md, step 21). Measured here: max
    // 1.890 % -> 1.800 %, RMS 1.35x better.
    let (before, after) = turned_fixture(
        "fandisk.off",
        [
            -0.3143505803593981,
            0.8791498424839822,
            -0.35816095137256226,
        ],
        2.1188755213494255,
        34,
    );
    assert!(
        after.max_pct < before.max_pct,
        "max {:.3} % -> {:.3} %",
        before.max_pct,
        after.max_pct
    );
    assert!(after.rms_pct * 1.25 < before.rms_pct);
}
