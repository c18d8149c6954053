//! Shared helpers: sample containers, a raw stream builder that computes CRCs (to craft
//! streams the writer refuses to produce), every way of decoding, and proptest strategies.

use proptest::prelude::*;
use whet_format::{
    parse, read_from, tag, write_varint, Container, Error, Header, HeaderValue, Limits, Mode,
    Progress, SectionKind, StreamingDecoder, Version,
};

/// A swing-mode container using every field and section kind this crate knows.
pub fn sample() -> Container {
    let mut header = Header::new(Mode::Swing, 1234, 2460)
        .with(tag::ENCODER, &b"whet 0.1.0"[..])
        .with(tag::COMPONENT_COUNT, 2u64)
        .with(tag::QUANT_BITS, 14u64)
        .with(tag::EDGE_LENGTH, 0.03125)
        .with(tag::ANGLE_BITS, 9u64);
    header.set_bbox([-1.5, -2.0, 0.0], [1.5, 2.0, 0.75]);
    Container::new(header)
        .with_section(SectionKind::METADATA, b"name=bunny".to_vec())
        .with_section(SectionKind::CONNECTIVITY, (0..40u8).collect::<Vec<_>>())
        .with_section(
            SectionKind::GEOMETRY,
            (0..90u8).map(|i| i.wrapping_mul(37)).collect::<Vec<_>>(),
        )
        .with_section(SectionKind::ATTRIBUTES, vec![])
        .with_section(SectionKind::CONTROL, b"control".to_vec())
        .with_section(SectionKind::SHARPNESS, vec![3, 1, 4])
}

pub fn sample_bytes() -> Vec<u8> {
    sample().to_bytes().expect("the sample is writable")
}

/// A header body: mode, counts, `body_len`, then raw field bytes.
pub fn header_body(
    mode: u64,
    vertices: u64,
    triangles: u64,
    body_len: u64,
    fields: &[u8],
) -> Vec<u8> {
    let mut b = Vec::new();
    for v in [mode, vertices, triangles, body_len] {
        write_varint(&mut b, v);
    }
    b.extend_from_slice(fields);
    b
}

/// Preamble, `header_len`, `body` and a correct header CRC, then `after` verbatim.
pub fn stream(version: (u8, u8), body: &[u8], after: &[u8]) -> Vec<u8> {
    let mut out = b"WHET".to_vec();
    out.extend_from_slice(&[version.0, version.1]);
    write_varint(&mut out, body.len() as u64);
    out.extend_from_slice(body);
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out.extend_from_slice(after);
    out
}

/// One framed section with a correct CRC.
pub fn section(tag: u64, payload: &[u8]) -> Vec<u8> {
    let mut s = Vec::new();
    write_varint(&mut s, tag);
    write_varint(&mut s, payload.len() as u64);
    s.extend_from_slice(payload);
    let crc = crc32fast::hash(&s);
    s.extend_from_slice(&crc.to_le_bytes());
    s
}

/// A complete exact-mode stream (3 vertices, 1 triangle) with raw fields and framed sections,
/// `body_len` and the end marker filled in.
pub fn stream_of(fields: &[u8], sections: &[Vec<u8>]) -> Vec<u8> {
    let mut after: Vec<u8> = sections.concat();
    after.push(0);
    stream(
        (1, 0),
        &header_body(0, 3, 1, after.len() as u64, fields),
        &after,
    )
}

/// Recomputes the header CRC after the header was patched.
pub fn fix_header_crc(bytes: &mut [u8]) {
    let mut pos = 6;
    let len = whet_format::read_varint(bytes, &mut pos).expect("header length") as usize;
    let end = pos + len;
    let crc = crc32fast::hash(&bytes[..end]);
    bytes[end..end + 4].copy_from_slice(&crc.to_le_bytes());
}

/// The streaming decoder fed at the given split points; returns the events (without
/// `NeedMore`) and the result.
pub fn decode_split(
    data: &[u8],
    splits: &[usize],
    limits: &Limits,
) -> (Vec<Progress>, Result<Container, Error>) {
    let mut decoder = StreamingDecoder::new(*limits);
    let mut events = Vec::new();
    let mut start = 0;
    let mut bounds: Vec<usize> = splits.iter().map(|&s| s.min(data.len())).collect();
    bounds.sort_unstable();
    bounds.push(data.len());
    for end in bounds {
        let mut rest = &data[start..end];
        start = end;
        while !rest.is_empty() {
            match decoder.update(rest) {
                Ok((used, progress)) => {
                    assert!(used <= rest.len());
                    rest = &rest[used..];
                    if progress != Progress::NeedMore {
                        events.push(progress);
                    } else {
                        assert!(rest.is_empty(), "NeedMore before the chunk was consumed");
                    }
                }
                Err(e) => return (events, Err(e)),
            }
        }
    }
    (events, decoder.finish())
}

/// The streaming decoder fed `chunk` bytes at a time.
pub fn decode_chunked(
    data: &[u8],
    chunk: usize,
    limits: &Limits,
) -> (Vec<Progress>, Result<Container, Error>) {
    let splits: Vec<usize> = (chunk..data.len()).step_by(chunk).collect();
    decode_split(data, &splits, limits)
}

/// A reader that hands out at most `step` bytes per call and is interrupted every other call.
pub struct Trickle<'a> {
    pub data: &'a [u8],
    pub step: usize,
    pub calls: usize,
}

impl std::io::Read for Trickle<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.calls += 1;
        if self.calls % 2 == 0 {
            return Err(std::io::ErrorKind::Interrupted.into());
        }
        let n = self.step.min(buf.len()).min(self.data.len());
        buf[..n].copy_from_slice(&self.data[..n]);
        self.data = &self.data[n..];
        Ok(n)
    }
}

/// Every decoding path on `data`, labelled: slice, `Read` (whole and trickled), streaming in
/// chunks of 1..=17 bytes.
pub fn decode_all(data: &[u8], limits: &Limits) -> Vec<(String, Result<Container, Error>)> {
    let mut out = vec![
        ("parse".to_string(), parse(data, limits)),
        ("read_from".to_string(), read_from(data, limits)),
        (
            "read_from trickle".to_string(),
            read_from(
                Trickle {
                    data,
                    step: 3,
                    calls: 0,
                },
                limits,
            ),
        ),
    ];
    for chunk in 1..=17 {
        out.push((
            format!("chunks of {chunk}"),
            decode_chunked(data, chunk, limits).1,
        ));
    }
    out
}

fn arb_field() -> impl Strategy<Value = (u64, HeaderValue)> {
    prop_oneof![
        proptest::collection::vec(any::<u8>(), 0..40).prop_map(|b| (tag::ENCODER, b.into())),
        any::<u64>().prop_map(|v| (tag::COMPONENT_COUNT, v.into())),
        (0u64..=64).prop_map(|v| (tag::QUANT_BITS, v.into())),
        proptest::collection::vec(any::<u8>(), 48).prop_map(|b| (tag::BBOX, b.into())),
        any::<f64>().prop_map(|v| (tag::EDGE_LENGTH, v.into())),
        any::<u64>().prop_map(|v| (tag::ANGLE_BITS, v.into())),
    ]
}

pub fn arb_header() -> impl Strategy<Value = Header> {
    (
        0usize..3,
        any::<u8>(),
        0u64..=1 << 28,
        0u64..=1 << 28,
        proptest::collection::vec(arb_field(), 0..8),
    )
        .prop_map(|(mode, minor, v, t, fields)| {
            let mut h = Header::new(Mode::ALL[mode], v, t).with_version(Version::new(1, minor));
            for (tag, value) in fields {
                h.set(tag, value);
            }
            h
        })
}

pub fn arb_container() -> impl Strategy<Value = Container> {
    (
        arb_header(),
        proptest::collection::vec(
            (0usize..4, proptest::collection::vec(any::<u8>(), 0..300)),
            0..6,
        ),
    )
        .prop_map(|(header, sections)| {
            let mut c = Container::new(header);
            for (kind, payload) in sections {
                c.set_section(SectionKind::KNOWN[kind], payload);
            }
            c
        })
}
