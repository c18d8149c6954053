//! Rate control: size targets land within the tolerance, error targets are met.

use whet_swing::{encode, ErrorOf, Rate, SwingOptions};
use whet_testkit::shared_fixture;

fn spot() -> whet_mesh::Mesh {
    whet_io::read_path(&shared_fixture("spot.off"), None).unwrap()
}

#[test]
fn target_bytes_lands_within_five_percent() {
    let mesh = spot();
    for target in [1200usize, 3000] {
        let out = encode(
            &mesh,
            &SwingOptions::DEFAULT.with_rate(Rate::TargetBytes(target)),
        )
        .unwrap();
        let err = (out.bytes.len() as f64 / target as f64 - 1.0).abs();
        assert!(
            err <= 0.05,
            "{target}: {} bytes, search {:?}",
            out.bytes.len(),
            out.search
        );
        assert!(out.search.len() <= 8, "{:?}", out.search);
    }
}

#[test]
fn bits_per_original_vertex_lands_within_five_percent() {
    let mesh = spot();
    let out = encode(
        &mesh,
        &SwingOptions::DEFAULT.with_rate(Rate::BitsPerVertex(4.0)),
    )
    .unwrap();
    let bpv = out.bits_per_original_vertex();
    assert!((bpv / 4.0 - 1.0).abs() <= 0.05, "{bpv}");
}

#[test]
fn max_error_is_met_by_the_stream_returned() {
    let mesh = spot();
    let target = 0.08;
    let out = encode(
        &mesh,
        &SwingOptions::DEFAULT
            .with_rate(Rate::MaxError(target))
            .with_metro_samples(100_000),
    )
    .unwrap();
    let rms = out.rms_pct.unwrap();
    assert!(rms <= target, "{rms}");
    // Re-measured independently with another sample layout.
    let r = whet_metro::metro(
        &mesh,
        &out.retiled,
        &whet_metro::MetroOptions::DEFAULT
            .with_samples(200_000)
            .with_seed(7),
    )
    .unwrap();
    assert!(
        r.symmetric.rms_pct <= target * 1.05,
        "{}",
        r.symmetric.rms_pct
    );
    // And it is not needlessly fine: within 40 % of the target.
    assert!(rms >= 0.6 * target, "{rms}");
}

/// A target every length meets stops at the longest length allowed (0.7 of the diagonal):
/// the search once re-encoded and re-measured that length until its iterations ran out.
#[test]
fn a_loose_error_target_stops_at_the_longest_length() {
    let out = encode(
        &spot(),
        &SwingOptions::DEFAULT
            .with_rate(Rate::MaxError(50.0))
            .with_metro_samples(100_000),
    )
    .unwrap();
    assert!(out.rms_pct.unwrap() <= 50.0);
    let at_longest = out.search.iter().filter(|s| s.0 == 0.7).count();
    assert_eq!(at_longest, 1, "{:?}", out.search);
    assert!(out.search.len() <= 4, "{:?}", out.search);
}

#[test]
fn bad_rates_are_parameter_errors() {
    let mesh = spot();
    for rate in [
        Rate::EdgeLength(0.0),
        Rate::EdgeLength(f64::NAN),
        Rate::BitsPerVertex(-1.0),
        Rate::TargetBytes(0),
        Rate::MaxError(0.0),
    ] {
        let e = encode(&mesh, &SwingOptions::DEFAULT.with_rate(rate)).unwrap_err();
        assert!(!e.is_input_error(), "{rate:?}: {e}");
    }
    let e = encode(&mesh, &SwingOptions::DEFAULT.with_angle_bits(2)).unwrap_err();
    assert!(matches!(e, whet_swing::Error::Parameter(_)), "{e}");
}

#[test]
fn edge_lengths_too_short_for_the_mesh_are_refused_before_any_work() {
    // A tetrahedron of four faces each spanning the whole box. At 1e-5 of the diagonal it
    // would need about 1.9e10 triangles: refused at once, by the area law. (Before the
    // check, and before the grid followed large faces, 1e-3 alone took minutes and 14 GB
    // in the original's grid.)
    let tet = whet_mesh::Mesh::new(
        vec![
            whet_mesh::DVec3::ZERO,
            whet_mesh::DVec3::X,
            whet_mesh::DVec3::Y,
            whet_mesh::DVec3::Z,
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    );
    for rate in [Rate::EdgeLength(1e-5), Rate::TargetBytes(1 << 40)] {
        let start = std::time::Instant::now();
        let e = encode(&tet, &SwingOptions::DEFAULT.with_rate(rate)).unwrap_err();
        assert!(
            matches!(e, whet_swing::Error::Parameter(_)),
            "{rate:?}: {e}"
        );
        assert!(e.to_string().contains("more than the limit"), "{e}");
        // Generous: a refusal is instant, a started retiling takes minutes.
        assert!(start.elapsed().as_secs() < 30, "{rate:?}");
    }
    // An error target the area law puts past the limit: unreachable, and it says why,
    // after one retiling at 1 % (no probe at a length the limit refuses).
    let e = encode(&tet, &SwingOptions::DEFAULT.with_rate(Rate::MaxError(1e-7))).unwrap_err();
    assert!(matches!(e, whet_swing::Error::Unreachable(_)), "{e}");
    assert!(e.to_string().contains("limit"), "{e}");
    // A mesh of almost no area passes the size limit at any length; the grid's range
    // refuses lengths under 2^-19 of the diagonal.
    let sliver = whet_mesh::Mesh::new(
        vec![
            whet_mesh::DVec3::ZERO,
            whet_mesh::DVec3::X,
            whet_mesh::DVec3::new(0.5, 1e-9, 0.0),
            whet_mesh::DVec3::new(0.5, 0.0, 1e-9),
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    );
    let e = encode(
        &sliver,
        &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(1e-7)),
    )
    .unwrap_err();
    assert!(matches!(e, whet_swing::Error::Parameter(_)), "{e}");
    assert!(e.to_string().contains("2^-19"), "{e}");
    // The limit is a tuning knob: a lower one refuses a length the default accepts.
    let tight = whet_swing::RetileTuning::DEFAULT.with_max_triangles(1000);
    let e = encode(
        &tet,
        &SwingOptions::DEFAULT
            .with_rate(Rate::EdgeLength(0.02))
            .with_tuning(tight),
    )
    .unwrap_err();
    assert!(matches!(e, whet_swing::Error::Parameter(_)), "{e}");
    encode(
        &tet,
        &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(0.02)),
    )
    .unwrap();
}

#[test]
fn meshes_whose_size_overflows_or_underflows_are_input_errors() {
    let tet = |s: f64| {
        whet_mesh::Mesh::new(
            vec![
                whet_mesh::DVec3::ZERO,
                whet_mesh::DVec3::X * s,
                whet_mesh::DVec3::Y * s,
                whet_mesh::DVec3::Z * s,
            ],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
    };
    for (scale, says) in [
        (1e300, "too large"),
        (1e200, "too large"),
        (1e-300, "no extent"),
    ] {
        let e = encode(&tet(scale), &SwingOptions::DEFAULT).unwrap_err();
        assert!(e.is_input_error(), "{scale}: {e}");
        assert!(e.to_string().contains(says), "{scale}: {e}");
    }
    encode(&tet(1e30), &SwingOptions::DEFAULT).unwrap();
    encode(&tet(1e-30), &SwingOptions::DEFAULT).unwrap();
}

#[test]
fn automatic_angle_bits_climb_on_flat_parts_and_stay_low_on_smooth_ones() {
    // cad_box_hole: flat faces predict their swing angles almost exactly, so extra angle
    // bits are nearly free there and remove the quantization noise the sharpener leaves
    // (measured at 3 bpv, seed 0: 6 bits 0.022 %, 9-12 bits 0.0077 %).
    let cad = whet_io::read_path(&shared_fixture("cad_box_hole.off"), None).unwrap();
    let opts = SwingOptions::DEFAULT
        .with_rate(Rate::BitsPerVertex(3.0))
        .with_auto_angle_bits(true)
        .with_error_of(ErrorOf::Sharpened)
        .with_metro_samples(100_000);
    let out = encode(&cad, &opts).unwrap();
    assert!(out.angle_bits >= 8, "{:?}", out.angle_trials);
    // The climb upwards succeeded, and the walk still looked one bit under the default:
    // a noisy gain above must not hide a real one below (sharp_sphere at 0.5 bpv measured
    // 0.71 % at 7 bits, 0.48 % at 4).
    let tried = |bits: u32| out.angle_trials.iter().any(|t| t.angle_bits == bits);
    assert!(
        tried(SwingOptions::DEFAULT_ANGLE_BITS - 1),
        "{:?}",
        out.angle_trials
    );
    // Each quantization is scored with EdgeSharpener's default as the sharpening is chosen,
    // the max error counting too. The best one's sharpening is chosen, and a finalist's
    // (within 5 % of that score) too; the one that ends better by the margin is written.
    let weighted = |(rms, max): (f64, f64)| rms * max.powf(whet_swing::MAX_ERROR_WEIGHT);
    let score = |t: &whet_swing::AngleTrial| weighted((t.rms_pct.unwrap(), t.max_pct.unwrap()));
    let measured: Vec<_> = out
        .angle_trials
        .iter()
        .filter(|t| t.rms_pct.is_some())
        .collect();
    let best = measured
        .iter()
        .min_by(|a, b| score(a).total_cmp(&score(b)))
        .unwrap();
    let ended: Vec<_> = measured.iter().filter(|t| t.sharpened.is_some()).collect();
    assert!(
        ended.iter().any(|t| t.angle_bits == best.angle_bits),
        "{:?}",
        out.angle_trials
    );
    let written = ended
        .iter()
        .find(|t| t.angle_bits == out.angle_bits)
        .unwrap_or_else(|| panic!("{:?}", out.angle_trials));
    // Here a finalist is measured (2026-12-07, at these options: 8 bits scored 0.00391 with
    // the default sharpening, 9 bits 0.00396; they ended at RMS 0.00201 and 0.00204 %), so
    // this test runs that path; elsewhere one quantization alone can end.
    assert_eq!(ended.len(), 2, "{:?}", out.angle_trials);
    let other = ended
        .iter()
        .find(|t| t.angle_bits != out.angle_bits)
        .unwrap();
    let finalist = if other.angle_bits == best.angle_bits {
        written
    } else {
        other
    };
    assert!(
        score(finalist) <= 1.05 * score(best),
        "{:?}",
        out.angle_trials
    );
    // The proxy's best stays unless the finalist ends better by the 0.5 % margin.
    assert!(
        weighted(written.sharpened.unwrap()) <= weighted(other.sharpened.unwrap()) / 0.995,
        "{:?}",
        out.angle_trials
    );
    let at_default = out
        .angle_trials
        .iter()
        .find(|t| t.angle_bits == SwingOptions::DEFAULT_ANGLE_BITS)
        .unwrap();
    let chosen = out.rms_pct.unwrap();
    assert!(
        chosen < 0.6 * at_default.rms_pct.unwrap(),
        "{:?}",
        out.angle_trials
    );
    // The chosen stream is the one returned, and it still meets the size target.
    assert!((out.bits_per_original_vertex() / 3.0 - 1.0).abs() <= 0.05);
    let decoded = whet_codec::decode(&out.bytes, &whet_codec::DecodeOptions::DEFAULT).unwrap();
    assert_eq!(decoded, out.retiled);
    // The sharpening choice retiled its candidates at the chosen bits (twelve methods,
    // factors and curved walls, in one pass and in two, each the same retiling, the
    // extended method's best with gray labels when there is one, the best of them refined:
    // 2 neighbours without curved walls, 8 with, and itself in one more pass; and none),
    // then tried the
    // chosen one with the planar-region projection, the local quadric one, the one-sided
    // one beside creases, the crease one and the apex restoration, and without its filter
    // for after sharpening.
    let unprojected = out
        .sharpen_trials
        .iter()
        .filter(|t| {
            !t.runner_up
                && !t.planar
                && !t.quadric
                && !t.beside
                && !t.crease
                && !t.apex
                && t.sharpened_filter
        })
        .count();
    assert!(
        [25, 28, 29, 34, 35].contains(&unprojected),
        "{:?}",
        out.sharpen_trials
    );
    // (Plus five projections, and the chosen sharpening without its filter for after
    // sharpening with its five; then up to two runners-up's paths: each its judged trial,
    // five projections, and without its filter with its five.)
    assert!(
        out.sharpen_trials.len() <= unprojected + 11 + 2 * 12,
        "{:?}",
        out.sharpen_trials
    );

    // spot, smooth: every bit is paid for on curved patches (measured: 5-6 bits best).
    let out = encode(
        &spot(),
        &SwingOptions::DEFAULT
            .with_rate(Rate::BitsPerVertex(3.0))
            .with_auto_angle_bits(true)
            .with_metro_samples(100_000),
    )
    .unwrap();
    assert!(out.angle_bits <= 7, "{:?}", out.angle_trials);
    // Both neighbours of the default are measured, whichever way the climb goes.
    for bits in [
        SwingOptions::DEFAULT_ANGLE_BITS - 1,
        SwingOptions::DEFAULT_ANGLE_BITS + 1,
    ] {
        assert!(
            out.angle_trials.iter().any(|t| t.angle_bits == bits),
            "{:?}",
            out.angle_trials
        );
    }
    // For the decoded output the RMS alone decides.
    let best = out
        .angle_trials
        .iter()
        .filter_map(|t| t.rms_pct)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(out.rms_pct, Some(best));
}

#[test]
fn automatic_angle_bits_need_a_target() {
    let e = encode(
        &spot(),
        &SwingOptions::DEFAULT
            .with_rate(Rate::EdgeLength(0.05))
            .with_auto_angle_bits(true),
    )
    .unwrap_err();
    assert!(e.to_string().contains("automatic angle bits"), "{e}");
}

/// Streams optimised for sharpening name the sharpening their encoder measured best
/// (header field 21); others name none.
#[test]
fn sharpened_streams_state_the_sharpening_measured_best() {
    use whet_codec::SharpenHint;
    let header = |b: &[u8]| {
        whet_format::parse(b, &whet_format::Limits::DEFAULT)
            .unwrap()
            .header
    };
    // fandisk at 1.6 bpv: both methods gain about 1.6x over the decoded mesh, the papers'
    // a little more (measured 2026-12-02: extended 0.078 %, papers 0.073 %, decoded 0.123
    // %); rocker_arm at 2.8 bpv has blends and no crease, and the papers' method makes it
    // worse by a fifth (0.038 % against 0.031 % unsharpened).
    // cad_box_hole at 1.9 bpv: the projections do better without the filter for after
    // sharpening (measured 2026-12-05 at 6 angle bits: 0.0103 % with it, 0.0078 % without,
    // 1M Metro samples), so that path is taken and checked too. fandisk at 3 bpv takes the
    // runner-up's path; cad_bracket at 1.2 bpv the gray labels (docs/swing.md section 2,
    // "Gray labels").
    for (name, bpv, not) in [
        ("fandisk.off", 1.6, SharpenHint::Unsharpened),
        ("rocker_arm.off", 2.8, SharpenHint::Papers),
        ("cad_box_hole.off", 1.9, SharpenHint::Unsharpened),
        ("fandisk.off", 3.0, SharpenHint::Unsharpened),
        ("cad_bracket.off", 1.2, SharpenHint::Unsharpened),
    ] {
        let mesh = whet_io::read_path(&shared_fixture(name), None).unwrap();
        let opts = SwingOptions::DEFAULT
            .with_rate(Rate::BitsPerVertex(bpv))
            .with_metro_samples(100_000);
        // A stream for the decoded output measures no sharpening; it states none, or "no
        // sharpening" where most snaps of the default one were vetoed (docs/sharpen.md, "Snap
        // vetoes": rocker_arm's blends).
        let plain = encode(&mesh, &opts).unwrap();
        assert!(matches!(
            plain.sharpen_hint,
            None | Some(SharpenHint::Unsharpened)
        ));
        assert!(plain.sharpen_trials.is_empty());
        assert_eq!(SharpenHint::of(&header(&plain.bytes)), plain.sharpen_hint);

        let out = encode(&mesh, &opts.with_error_of(ErrorOf::Sharpened)).unwrap();
        let hint = out.sharpen_hint.unwrap();
        assert_ne!(hint, not, "{name}: {:?}", out.sharpen_trials);
        // Every field the sharpening choice states after the size search still lands
        // within the rate's tolerance.
        let bpv_out = out.bits_per_original_vertex();
        assert!((bpv_out / bpv - 1.0).abs() <= 0.05, "{name}: {bpv_out} bpv");
        assert_eq!(SharpenHint::of(&header(&out.bytes)), Some(hint));
        // 24 candidates of the grid (each with the filter for after sharpening fitted for
        // it), the grid's best refined (its neighbours in smooth factor and curved walls,
        // then itself in one more pass), the extended method's best so far with gray labels
        // (when there is one),
        // no sharpening; then the chosen sharpening refined by the planar-region projection,
        // by the local quadric one, the one beside creases, the crease one and the apex
        // restoration (each on top of those kept before it); then, when its stream carried
        // a filter for after sharpening, the same without that filter, and its five
        // projections.
        // Then the runners-up, the best sharpening of each other slot (extended, papers,
        // extended with gray labels; `runner_up` trials), each path its vetoes' judged trial
        // when they were kept, its five projections, and without its filter with its five;
        // one is chosen when its end beats the path standing by the margin.
        use whet_swing::SharpenTrial;
        let (runner_up, main): (Vec<&SharpenTrial>, Vec<_>) =
            out.sharpen_trials.iter().partition(|t| t.runner_up);
        let (trials, refined): (Vec<&SharpenTrial>, Vec<_>) = main.into_iter().partition(|t| {
            t.sharpened_filter && !t.planar && !t.quadric && !t.beside && !t.crease && !t.apex
        });
        let input_max = out.sharpen_input_max_pct.unwrap();
        assert_eq!(
            trials.last().map(|t| t.hint),
            Some(SharpenHint::Unsharpened),
            "{name}"
        );
        let none_rms = trials.last().unwrap().rms_pct;
        // The grid's rule: within the bounds, each later one 0.5 % lower in score.
        fn best_of<'a>(
            from: impl Iterator<Item = &'a SharpenTrial>,
            input_max: f64,
            none_rms: f64,
        ) -> Option<&'a SharpenTrial> {
            from.filter(|t| t.max_pct <= input_max && t.rms_pct <= none_rms)
                .fold(None, |b, t| match b {
                    Some(b) if t.score() >= 0.995 * b.score() => Some(b),
                    _ => Some(t),
                })
        }
        let gray = trials[..trials.len() - 1]
            .last()
            .copied()
            .filter(|t| t.gray_labels);
        let around = &trials[24..trials.len() - 1 - usize::from(gray.is_some())];
        let extended_best = best_of(
            trials[..24]
                .iter()
                .chain(around)
                .copied()
                .filter(|t| t.hint == SharpenHint::Extended),
            input_max,
            none_rms,
        );
        if let Some(g) = gray {
            let e = extended_best.unwrap();
            assert_eq!(
                (g.hint, g.smooth_factor, g.curved_walls, g.passes),
                (e.hint, e.smooth_factor, e.curved_walls, e.passes),
                "{name}"
            );
        }
        let grid_best = best_of(trials[..24].iter().copied(), input_max, none_rms);
        match grid_best {
            None => assert!(around.is_empty(), "{name}"),
            Some(c) => {
                let walls = if c.curved_walls > 0.0 { 3 } else { 1 };
                let walls = walls
                    - [c.curved_walls - 1.0, c.curved_walls + 1.0]
                        .iter()
                        .filter(|&&w| c.curved_walls > 0.0 && !(1.0..=4.0).contains(&w))
                        .count();
                assert_eq!(around.len(), 3 * walls, "{name}: {around:?}");
                let (neighbours, more) = around.split_at(around.len() - 1);
                let more = more[0];
                assert_eq!((more.hint, more.passes), (c.hint, c.passes + 1), "{name}");
                assert_eq!(
                    (more.smooth_factor, more.curved_walls),
                    (c.smooth_factor, c.curved_walls),
                    "{name}"
                );
                assert!(!more.gray_labels, "{name}");
                for t in neighbours {
                    assert_eq!((t.hint, t.passes), (c.hint, c.passes), "{name}");
                    assert!(!t.gray_labels, "{name}");
                    assert!((t.smooth_factor - c.smooth_factor).abs() <= 0.25 + 1e-12);
                    assert!((t.curved_walls - c.curved_walls).abs() <= 1.0 + 1e-12);
                    assert_eq!(t.curved_walls > 0.0, c.curved_walls > 0.0, "{name}");
                }
            }
        }
        let sharpened = hint != SharpenHint::Unsharpened;
        // The runners-up are of other slots than the best's path and than one another, in
        // slot order, and only beside a sharpening.
        let slot = |t: &SharpenTrial| match (t.hint, t.gray_labels) {
            (SharpenHint::Papers, _) => 1,
            (_, true) => 2,
            _ => 0,
        };
        let best_hint = refined.first().map(|t| t.hint);
        let best_slot = refined.first().map(|t| slot(t));
        let mut paths: Vec<Vec<&SharpenTrial>> = Vec::new();
        for &t in &runner_up {
            match paths.last_mut() {
                Some(p) if slot(p[0]) == slot(t) => p.push(t),
                _ => paths.push(vec![t]),
            }
        }
        assert!(paths.len() <= 2, "{name}");
        for (k, p) in paths.iter().enumerate() {
            assert!(
                best_slot.is_some() && best_slot != Some(slot(p[0])),
                "{name}"
            );
            assert!(k == 0 || slot(paths[k - 1][0]) < slot(p[0]), "{name}");
        }
        let h = header(&out.bytes);
        let stated = SharpenHint::planar_of(&h);
        assert_eq!(stated.map(|s| s.0), out.planar_factor, "{name}");
        let stated = SharpenHint::quadric_of(&h);
        assert_eq!(stated.map(|s| s.0), out.quadric_factor, "{name}");
        let stated = SharpenHint::beside_of(&h);
        assert_eq!(stated.map(|s| s.0), out.beside_factor, "{name}");
        assert_eq!(SharpenHint::crease_of(&h), out.crease_factor, "{name}");
        assert_eq!(SharpenHint::apex_of(&h), out.apex_factor, "{name}");
        // The encoder's rule on one path: each step is kept when its score beats what it
        // refines by the margin (0.5 %) without raising the max over the input's or the
        // path's sharpening's, nor the RMS over no sharpening's; the path without the filter
        // wins over the one with it by the margin. Returns the path's start and end, and
        // whether it had a path without the filter.
        let replay = |post: &[&SharpenTrial]| -> (SharpenTrial, SharpenTrial, bool) {
            // A judged trial (the vetoes kept) first, else the path starts from its grid
            // record.
            let (judged, post): (Option<&SharpenTrial>, &[&SharpenTrial]) = match post.split_first()
            {
                Some((j, rest))
                    if j.sharpened_filter
                        && !j.planar
                        && !j.quadric
                        && !j.beside
                        && !j.crease
                        && !j.apex =>
                {
                    (Some(*j), rest)
                }
                _ => (None, post),
            };
            let (with, bare): (Vec<&SharpenTrial>, Vec<_>) =
                post.iter().copied().partition(|t| t.sharpened_filter);
            assert_eq!(with.len(), 5, "{name}: {post:?}");
            assert!(bare.is_empty() || bare.len() == 6, "{name}");
            let base = judged.copied().unwrap_or_else(|| {
                **trials
                    .iter()
                    .find(|t| {
                        t.hint == with[0].hint
                            && t.gray_labels == with[0].gray_labels
                            && t.smooth_factor == with[0].smooth_factor
                            && t.curved_walls == with[0].curved_walls
                            && t.passes == with[0].passes
                    })
                    .unwrap()
            });
            let admit = |t: &SharpenTrial| {
                t.max_pct <= input_max.max(base.max_pct) && t.rms_pct <= none_rms
            };
            let path_end = |start: SharpenTrial, steps: &[&SharpenTrial]| {
                let mut current = start;
                for (k, s) in steps.iter().enumerate() {
                    assert_eq!(s.planar, current.planar || k == 0, "{name}: {s:?}");
                    assert_eq!(s.quadric, current.quadric || k == 1, "{name}: {s:?}");
                    assert_eq!(s.beside, current.beside || k == 2, "{name}: {s:?}");
                    assert_eq!(s.crease, current.crease || k == 3, "{name}: {s:?}");
                    assert_eq!(s.apex, k == 4, "{name}: {s:?}");
                    assert_eq!(s.sharpened_filter, start.sharpened_filter, "{name}");
                    if s.score() < 0.995 * current.score() && admit(s) {
                        current = **s;
                    }
                }
                current
            };
            let mut end = path_end(base, &with);
            if let Some((first, steps)) = bare.split_first() {
                assert!(
                    !first.planar
                        && !first.quadric
                        && !first.beside
                        && !first.crease
                        && !first.apex,
                    "{name}"
                );
                let without = path_end(**first, steps);
                if without.score() < 0.995 * end.score() && admit(&without) {
                    end = without;
                }
            }
            (base, end, !bare.is_empty())
        };
        // `unprojected`: the best path's start (a grid candidate); `base`: the start of the
        // path that won; `chosen`: its end's RMS.
        let (unprojected, base, chosen) = if sharpened {
            let (main_base, main_end, main_bare) = replay(&refined);
            let (mut base, mut end, mut had_bare) = (main_base, main_end, main_bare);
            let mut runner_up_won = false;
            for p in &paths {
                let (b, e, h) = replay(p);
                if e.score() < 0.995 * end.score() {
                    (base, end, had_bare) = (b, e, h);
                    runner_up_won = true;
                }
            }
            // fandisk at 3 bpv takes a runner-up's path (measured 2026-12-07 at these
            // options: the papers' method was the grid's best, the extended method's path
            // ended better), so that branch of the replay is exercised.
            if (name, bpv) == ("fandisk.off", 3.0) {
                assert!(runner_up_won, "{name}: {:?}", out.sharpen_trials);
            }
            // cad_bracket at 1.2 bpv states the gray labels (measured 2026-12-07 at these
            // options: the extended method's best with them beat it by the margin, and its
            // path ended best), so the gray candidate's slot is exercised.
            if (name, bpv) == ("cad_bracket.off", 1.2) {
                assert!(
                    gray.is_some() && base.gray_labels,
                    "{name}: {:?}",
                    out.sharpen_trials
                );
            }
            assert_eq!(base.hint, hint, "{name}");
            assert_eq!(out.rms_pct, Some(end.rms_pct), "{name}");
            assert_eq!(out.planar_factor.is_some(), end.planar, "{name}");
            assert_eq!(out.quadric_factor.is_some(), end.quadric, "{name}");
            assert_eq!(out.beside_factor.is_some(), end.beside, "{name}");
            assert_eq!(out.crease_factor.is_some(), end.crease, "{name}");
            assert_eq!(out.apex_factor.is_some(), end.apex, "{name}");
            if let Some(f) = out.planar_factor {
                assert_eq!(f, whet_swing::PLANAR_FACTOR);
            }
            if let Some(f) = out.quadric_factor {
                assert_eq!(f, whet_swing::QUADRIC_FACTOR);
            }
            if let Some(f) = out.beside_factor {
                assert_eq!(f, whet_swing::BESIDE_FACTOR);
            }
            if let Some(f) = out.crease_factor {
                assert_eq!(f, whet_swing::CREASE_MOVE);
            }
            if let Some(f) = out.apex_factor {
                assert_eq!(f, whet_swing::APEX_MOVE);
            }
            if !end.sharpened_filter {
                assert!(out.sharpened_filter.is_none(), "{name}");
            } else if had_bare {
                assert!(!out.sharpened_filter.is_none(), "{name}");
            }
            let stated = whet_codec::SurfaceFilter::after_sharpening_of(&h);
            assert_eq!(stated.factors(), out.sharpened_filter.factors(), "{name}");
            if name == "cad_box_hole.off" {
                assert!(!end.sharpened_filter, "{name}: {:?}", out.sharpen_trials);
            }
            (main_base.rms_pct, Some(base), end.rms_pct)
        } else {
            let r = out.rms_pct.unwrap();
            (r, None, r)
        };
        let best_hint = best_hint.unwrap_or(hint);
        assert!(
            trials
                .iter()
                .any(|t| t.hint == best_hint && t.rms_pct == unprojected),
            "{name}"
        );
        // A later candidate must win by the encoder's margin (0.5 %) in score (RMS times the
        // max to the power MAX_ERROR_WEIGHT), among those that do not raise the max error
        // over the sharpened mesh's nor the RMS error over the plain decoded mesh's; the
        // chosen one does not.
        let chosen_score = trials
            .iter()
            .find(|t| t.hint == best_hint && t.rms_pct == unprojected)
            .unwrap()
            .score();
        assert!(
            trials
                .iter()
                .filter(|t| t.max_pct <= input_max && t.rms_pct <= none_rms)
                .all(|t| chosen_score * 0.995 <= t.score()),
            "{name}"
        );
        let score =
            |t: &whet_swing::SharpenTrial| t.rms_pct * t.max_pct.powf(whet_swing::MAX_ERROR_WEIGHT);
        assert!(trials.iter().all(|t| t.score() == score(t)), "{name}");
        if hint != SharpenHint::Unsharpened {
            let t = trials.iter().find(|t| t.rms_pct == unprojected).unwrap();
            assert!(t.max_pct <= input_max, "{name}: {t:?} over {input_max}");
            assert!(t.rms_pct <= none_rms, "{name}: {t:?} over {none_rms}");
            assert!(chosen <= none_rms, "{name}: {chosen} over {none_rms}");
        }
        // The stream states the choice: method and factor, and curved walls and passes where
        // they are on and more than one.
        let factor = SharpenHint::smooth_factor_of(&h);
        assert_eq!(factor, out.sharpen_smooth_factor, "{name}");
        let walls = SharpenHint::curved_walls_of(&h);
        assert_eq!(walls, out.sharpen_curved_walls, "{name}");
        let passes = SharpenHint::passes_of(&h);
        assert_eq!(passes, out.sharpen_passes, "{name}");
        let gray_labels = SharpenHint::gray_labels_of(&h);
        assert_eq!(gray_labels, out.sharpen_gray_labels, "{name}");
        if let Some(t) = base {
            assert_eq!(factor, Some(t.smooth_factor), "{name}");
            assert_eq!(walls.unwrap_or(0.0), t.curved_walls, "{name}");
            assert_eq!(passes.unwrap_or(1), t.passes, "{name}");
            assert_eq!(gray_labels, t.gray_labels, "{name}");
        }
        // The stream decodes to the encoder's mesh and stays within the size target (the
        // size searches count the hint's two bytes, so the rate may land on another L).
        let decoded = whet_codec::decode(&out.bytes, &whet_codec::DecodeOptions::DEFAULT).unwrap();
        assert!(decoded == out.retiled, "{name}: decodes to another mesh");
        let target = bpv * mesh.positions.len() as f64 / 8.0;
        assert!(
            (out.bytes.len() as f64 / target - 1.0).abs() <= 0.05,
            "{name}"
        );
    }
}
