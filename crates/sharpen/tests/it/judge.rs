//! Snap vetoes (`SnapJudge`, docs/sharpen.md "Snap vetoes"): what a judge is asked, what a
//! veto does, and the replay of stated vetoes.

use whet_mesh::Mesh;
use whet_sharpen::{
    sharpen, sharpen_judged, Method, SharpenOptions, Snap, SnapJudge, UnmovedReason, VetoReplay,
};
use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};

fn chamfered_cube() -> Mesh {
    let cube = Shape::new(ShapeKind::Cube, &ShapeParams::default()).unwrap();
    marching_cubes(&cube, 16).unwrap()
}

/// Records every pass's snaps and vetoes those `veto` picks.
struct Recorder<F: FnMut(usize, &Snap) -> bool> {
    asked: Vec<Vec<Snap>>,
    veto: F,
}

impl<F: FnMut(usize, &Snap) -> bool> SnapJudge for Recorder<F> {
    fn vetoes(&mut self, snaps: &[Snap]) -> Vec<bool> {
        self.asked.push(snaps.to_vec());
        snaps
            .iter()
            .enumerate()
            .map(|(i, s)| (self.veto)(i, s))
            .collect()
    }
}

#[test]
fn a_judge_that_vetoes_nothing_changes_nothing() {
    let input = chamfered_cube();
    for method in crate::EDGE_SHARPENER {
        let opts = SharpenOptions::DEFAULT.with_method(method);
        let plain = sharpen(&input, &opts).unwrap();
        let mut judge = Recorder {
            asked: Vec::new(),
            veto: |_, _| false,
        };
        let judged = sharpen_judged(&input, &opts, &mut judge).unwrap();
        assert_eq!(judged.mesh, plain.mesh, "{method:?}");
        assert_eq!(judged.report.unmoved(UnmovedReason::Vetoed), 0);
        // One call for the one pass; every snap moved its vertex, and a new vertex names the
        // two or three vertices it was inserted between.
        assert_eq!(judge.asked.len(), 1, "{method:?}");
        let snaps = &judge.asked[0];
        assert!(snaps.len() >= plain.report.snapped_vertices, "{method:?}");
        assert!(snaps.iter().all(|s| s.rest != s.snapped));
        assert!(snaps
            .iter()
            .all(|s| s.origins.is_empty() || (2..=4).contains(&s.origins.len())));
    }
}

#[test]
fn vetoed_snaps_stay_at_rest_and_are_counted() {
    let input = chamfered_cube();
    let opts = SharpenOptions::DEFAULT.with_method(Method::Papers);
    let plain = sharpen(&input, &opts).unwrap();
    let mut judge = Recorder {
        asked: Vec::new(),
        veto: |i, _| i % 2 == 0,
    };
    let judged = sharpen_judged(&input, &opts, &mut judge).unwrap();
    let r = &judged.report;
    assert!(r.unmoved(UnmovedReason::Vetoed) > 0);
    assert!(r.snapped_vertices < plain.report.snapped_vertices);
    // The output stays what the sharpener promises: an oriented manifold without new
    // borders, input vertices outside the chamfers untouched.
    let t = judged.mesh.topology_report();
    assert!(t.manifold && t.oriented && t.boundary_edges == 0);
    // Every vetoed new vertex still in the output sits at its rest position.
    let rests: Vec<_> = judge.asked[0]
        .iter()
        .enumerate()
        .filter(|(i, _)| i % 2 == 0)
        .map(|(_, s)| s.rest)
        .collect();
    let at_rest = judged.mesh.positions[input.positions.len()..]
        .iter()
        .filter(|p| rests.contains(p))
        .count();
    assert!(at_rest >= r.unmoved(UnmovedReason::Vetoed), "{at_rest}");
    assert!(r.to_json().contains("\"vetoed\":"));
}

#[test]
fn a_replay_applies_stated_vetoes_only_to_the_run_they_fit() {
    let input = chamfered_cube();
    let opts = SharpenOptions::DEFAULT;
    let mut judge = Recorder {
        asked: Vec::new(),
        veto: |i, _| i % 3 == 0,
    };
    let judged = sharpen_judged(&input, &opts, &mut judge).unwrap();
    let flags: Vec<Vec<bool>> = judge
        .asked
        .iter()
        .map(|p| (0..p.len()).map(|i| i % 3 == 0).collect())
        .collect();
    // The same flags replayed give the same mesh: what a decoder does with field 33.
    let mut replay = VetoReplay::new(flags.clone());
    let replayed = sharpen_judged(&input, &opts, &mut replay).unwrap();
    assert_eq!(replayed.mesh, judged.mesh);
    assert_eq!(replay.mismatched_passes(), 0);
    assert_eq!(replay.applied(), flags[0].iter().filter(|&&v| v).count());
    // Flags of another run (one snap short) are not applied: the plain run's mesh.
    let mut short = flags.clone();
    short[0].pop();
    let mut replay = VetoReplay::new(short);
    let out = sharpen_judged(&input, &opts, &mut replay).unwrap();
    assert_eq!(out.mesh, sharpen(&input, &opts).unwrap().mesh);
    assert_eq!((replay.mismatched_passes(), replay.applied()), (1, 0));
    // A stated pass the run never asks about is a mismatch too.
    let mut extra = flags;
    extra.push(vec![true]);
    let mut replay = VetoReplay::new(extra);
    sharpen_judged(&input, &opts, &mut replay).unwrap();
    assert_eq!(replay.mismatched_passes(), 1);
}

#[test]
fn a_mesh_without_chamfers_asks_no_judge() {
    let sphere = Shape::new(ShapeKind::Sphere, &ShapeParams::default()).unwrap();
    let input = marching_cubes(&sphere, 16).unwrap();
    let mut judge = Recorder {
        asked: Vec::new(),
        veto: |_, _| true,
    };
    let out = sharpen_judged(&input, &SharpenOptions::DEFAULT, &mut judge).unwrap();
    assert!(judge.asked.is_empty());
    assert_eq!(out.mesh, input);
}
