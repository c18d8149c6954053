//! Rate control: size targets land within the tolerance, error targets are met.

use whet_swing::{encode, Rate, SwingOptions};
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
