//! Corrupted swing streams give errors, never panics or garbage meshes.

use whet_codec::{decode, DecodeOptions};
use whet_format::{parse, tag, Container, Limits, SectionKind};
use whet_swing::{encode, Rate, SwingOptions};
use whet_testkit::meshes::icosphere;

fn stream() -> Vec<u8> {
    encode(
        &icosphere(3),
        &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(0.08)),
    )
    .unwrap()
    .bytes
}

fn decode_ok_or_err(bytes: &[u8]) {
    if let Ok(m) = decode(bytes, &DecodeOptions::DEFAULT) {
        assert!(m.validate().is_ok());
        assert!(m.positions.iter().all(|p| p.is_finite()));
    }
}

#[test]
fn every_truncation_is_an_error() {
    let good = stream();
    for n in 0..good.len() {
        assert!(decode(&good[..n], &DecodeOptions::DEFAULT).is_err(), "{n}");
    }
}

/// Rebuilds the container with `f` applied to its geometry section (CRCs recomputed, so
/// the swing decoder itself sees the damage).
fn with_geometry(good: &[u8], f: impl Fn(&mut Vec<u8>)) -> Vec<u8> {
    let c = parse(good, &Limits::DEFAULT).unwrap();
    let mut geom = c.section(SectionKind::GEOMETRY).unwrap().to_vec();
    f(&mut geom);
    let conn = c.section(SectionKind::CONNECTIVITY).unwrap().to_vec();
    Container::new(c.header.clone())
        .with_section(SectionKind::CONNECTIVITY, conn)
        .with_section(SectionKind::GEOMETRY, geom)
        .to_bytes()
        .unwrap()
}

#[test]
fn damaged_geometry_never_panics() {
    let good = stream();
    let len = parse(&good, &Limits::DEFAULT)
        .unwrap()
        .section(SectionKind::GEOMETRY)
        .unwrap()
        .len();
    for i in 0..len {
        for bit in [0x01u8, 0x10, 0x80] {
            decode_ok_or_err(&with_geometry(&good, |g| g[i] ^= bit));
        }
    }
    for n in 0..len {
        let b = with_geometry(&good, |g| g.truncate(n));
        assert!(
            decode(&b, &DecodeOptions::DEFAULT).is_err(),
            "geometry cut to {n}"
        );
    }
    // An unknown geometry kind, and the payload read as another kind (the other forward
    // coding among them: kinds 7 and 9 read the same labels but different index codes).
    let written = parse(&good, &Limits::DEFAULT)
        .unwrap()
        .section(SectionKind::GEOMETRY)
        .unwrap()[0];
    let other_forward = if written == 9 { 7 } else { 9 };
    for kind in [5, 6, other_forward, 11, 255] {
        let err = decode(
            &with_geometry(&good, |g| g[0] = kind),
            &DecodeOptions::DEFAULT,
        );
        assert!(err.is_err(), "kind {kind}");
    }
}

#[test]
fn bad_header_fields_are_errors() {
    let good = stream();
    let c = parse(&good, &Limits::DEFAULT).unwrap();
    let rebuild = |f: &dyn Fn(&mut whet_format::Header)| {
        let mut h = c.header.clone();
        f(&mut h);
        let mut out = Container::new(h);
        for kind in [SectionKind::CONNECTIVITY, SectionKind::GEOMETRY] {
            out = out.with_section(kind, c.section(kind).unwrap().to_vec());
        }
        out.to_bytes().unwrap()
    };
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("negative L", rebuild(&|h| h.set(tag::EDGE_LENGTH, -1.0))),
        ("NaN L", rebuild(&|h| h.set(tag::EDGE_LENGTH, f64::NAN))),
        ("angle bits 2", rebuild(&|h| h.set(tag::ANGLE_BITS, 2u64))),
        ("angle bits 99", rebuild(&|h| h.set(tag::ANGLE_BITS, 99u64))),
        ("quant bits 0", rebuild(&|h| h.set(tag::QUANT_BITS, 0u64))),
        (
            "components",
            rebuild(&|h| h.set(tag::COMPONENT_COUNT, 3u64)),
        ),
        (
            "no L",
            rebuild(&|h| {
                h.remove(tag::EDGE_LENGTH);
            }),
        ),
        (
            "no angle bits",
            rebuild(&|h| {
                h.remove(tag::ANGLE_BITS);
            }),
        ),
    ];
    for (name, bytes) in cases {
        let e = decode(&bytes, &DecodeOptions::DEFAULT);
        assert!(e.is_err(), "{name}");
        assert!(e.unwrap_err().is_input_error(), "{name}");
    }
    // A different L changes nothing structurally: it decodes (to another shape) or fails
    // cleanly when some gate becomes longer than 2L.
    decode_ok_or_err(&rebuild(&|h| h.set(tag::EDGE_LENGTH, 1e-6)));
    decode_ok_or_err(&rebuild(&|h| h.set(tag::EDGE_LENGTH, 1e6)));
}

#[test]
fn any_surface_filter_in_range_decodes_to_finite_positions_and_others_are_refused() {
    let good = stream();
    let c = parse(&good, &Limits::DEFAULT).unwrap();
    let rebuilt = |normal: i64, smoothed: i64| {
        let header = c
            .header
            .clone()
            .with(tag::FILTER_NORMAL, normal)
            .with(tag::FILTER_SMOOTHED, smoothed);
        let mut out = Container::new(header);
        for kind in [SectionKind::CONNECTIVITY, SectionKind::GEOMETRY] {
            out = out.with_section(kind, c.section(kind).unwrap().to_vec());
        }
        out.to_bytes().unwrap()
    };
    let max = whet_codec::surface_filter::MAX_CODED;
    for (a, b) in [
        (0, 0),
        (max, max),
        (-max, -max),
        (max, -max),
        (1, -1),
        (-2000, 3000),
    ] {
        let bytes = rebuilt(a, b);
        let m = decode(&bytes, &DecodeOptions::DEFAULT).unwrap();
        assert!(m.validate().is_ok());
        assert!(m.positions.iter().all(|p| p.is_finite()), "{a} {b}");
        // The filter moves vertices only: the same triangles as without it.
        let plain = decode(&bytes, &DecodeOptions::DEFAULT.with_surface_filter(false)).unwrap();
        assert_eq!(m.triangles, plain.triangles);
    }
    for (a, b) in [(max + 1, 0), (0, -max - 1), (i64::MIN, 0), (0, i64::MAX)] {
        let err = decode(&rebuilt(a, b), &DecodeOptions::DEFAULT).unwrap_err();
        assert!(err.to_string().contains("surface filter"), "{err}");
    }
}

/// A swing stream's walk may hold more triangles than its header declares (triangles deleted
/// over holes), so the decoder holds the walk's own count to the byte limit too: a header
/// shrunk to one triangle passes the estimate from the counts, and the walk is refused
/// before it runs (it used to decode in full and fail only on the count mismatch).
#[test]
fn a_walk_longer_than_the_header_says_is_held_to_the_byte_limit() {
    let mesh = whet_testkit::meshes::icosphere(3);
    let out = crate::round_trip(&mesh, 0.1);
    let n = out.retiled.triangles.len() as u64;
    let mut c = whet_format::parse(&out.bytes, &whet_format::Limits::DEFAULT).unwrap();
    c.header.triangle_count = 1;
    c.header.vertex_count = 3;
    // Room for the declared counts, not for the walk.
    let budget = n * whet_codec::DECODE_BYTES_PER_TRIANGLE - 1;
    let opts = whet_codec::DecodeOptions::DEFAULT
        .with_limits(whet_format::Limits::DEFAULT.with_max_alloc_bytes(budget));
    match whet_codec::decode_container(&c, &opts) {
        Err(whet_codec::Error::Format(whet_format::Error::LimitExceeded {
            what, value, ..
        })) => {
            assert!(what.contains("decoding allocates"), "{what}");
            assert!(value > budget);
        }
        other => panic!("{other:?}"),
    }
    // With room for the walk it decodes, and the count mismatch is what is reported.
    let roomy = whet_codec::DecodeOptions::DEFAULT;
    assert!(matches!(
        whet_codec::decode_container(&c, &roomy),
        Err(whet_codec::Error::Corrupt(_))
    ));
}
