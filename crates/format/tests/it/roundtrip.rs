//! Containers survive writing and every way of reading, byte-exactly.

use proptest::prelude::*;
use whet_format::{fuzz_parse, parse, peek_header, read_from, tag, Limits, Mode, SectionKind};

use crate::common::*;

#[test]
fn sample_round_trips_every_way() {
    let bytes = sample_bytes();
    for (how, result) in decode_all(&bytes, &Limits::DEFAULT) {
        assert_eq!(result.unwrap(), sample(), "{how}");
    }
    let back = parse(&bytes, &Limits::DEFAULT).unwrap();
    assert_eq!(
        back.header.bbox(),
        Some(([-1.5, -2.0, 0.0], [1.5, 2.0, 0.75]))
    );
    assert_eq!(back.header.get_f64(tag::EDGE_LENGTH), Some(0.03125));
    assert_eq!(
        back.header.get_bytes(tag::ENCODER),
        Some(&b"whet 0.1.0"[..])
    );
    fuzz_parse(&bytes);
}

#[test]
fn write_to_equals_to_bytes() {
    let mut out = Vec::new();
    sample().write_to(&mut out).unwrap();
    assert_eq!(out, sample_bytes());
}

#[test]
fn peek_reads_only_the_header() {
    let bytes = sample_bytes();
    let info = peek_header(&bytes).unwrap();
    assert_eq!(info.mode, Mode::Swing);
    assert_eq!((info.vertex_count, info.triangle_count), (1234, 2460));
    assert_eq!(info.total_len, bytes.len() as u64);
    // The first 16 bytes hold the preamble and the counts; the CRC is not needed.
    let mut prefix = bytes[..16].to_vec();
    assert_eq!(peek_header(&prefix).unwrap(), info);
    prefix[15] ^= 0xff;
    assert_eq!(
        peek_header(&prefix).unwrap(),
        info,
        "peek does not check CRCs"
    );
}

#[test]
fn empty_container() {
    let c = whet_format::Container::new(whet_format::Header::new(Mode::Subdiv, 0, 0));
    let bytes = c.to_bytes().unwrap();
    assert_eq!(bytes.len(), 6 + 1 + 4 + 4 + 1);
    assert_eq!(parse(&bytes, &Limits::DEFAULT).unwrap(), c);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn random_containers_round_trip(c in arb_container(), splits in proptest::collection::vec(0usize..2000, 0..12)) {
        let bytes = c.to_bytes().unwrap();
        prop_assert_eq!(&parse(&bytes, &Limits::DEFAULT).unwrap(), &c);
        prop_assert_eq!(&read_from(&bytes[..], &Limits::DEFAULT).unwrap(), &c);
        let (_, streamed) = decode_split(&bytes, &splits, &Limits::DEFAULT);
        prop_assert_eq!(&streamed.unwrap(), &c);
        let info = peek_header(&bytes).unwrap();
        prop_assert_eq!(info.total_len, bytes.len() as u64);
        prop_assert_eq!(info.version, c.header.version);
        // Canonical: writing what was read gives the same bytes.
        prop_assert_eq!(parse(&bytes, &Limits::DEFAULT).unwrap().to_bytes().unwrap(), bytes.clone());
        fuzz_parse(&bytes);
    }
}

#[test]
fn kinds_round_trip_in_tag_order() {
    let bytes = sample_bytes();
    let kinds: Vec<SectionKind> = parse(&bytes, &Limits::DEFAULT)
        .unwrap()
        .sections
        .iter()
        .map(|s| s.kind)
        .collect();
    assert_eq!(kinds, SectionKind::KNOWN);
}
