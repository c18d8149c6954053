//! Truncation, bit flips, trailing bytes, hostile sizes and unknown tags: each input gets its
//! exact error from every decoding path, and nothing panics.

use whet_format::{
    parse, peek_header, read_from, read_varint, tag, write_varint, Container, Error, FormatError,
    Header, Limits, Mode, SectionKind,
};

use crate::common::*;

/// Asserts that every decoding path refuses `data` with an error `check` accepts.
fn refuse_all(data: &[u8], limits: &Limits, check: impl Fn(&Error) -> bool) {
    for (how, result) in decode_all(data, limits) {
        match result {
            Ok(_) => panic!("{how}: accepted a corrupt stream"),
            Err(e) => assert!(check(&e), "{how}: unexpected error {e:?}"),
        }
    }
}

#[test]
fn every_truncation_is_truncated() {
    let bytes = sample_bytes();
    for n in 0..bytes.len() {
        refuse_all(
            &bytes[..n],
            &Limits::DEFAULT,
            |e| matches!(e, Error::Truncated { offset, .. } if *offset == n as u64),
        );
    }
}

/// The sample plus unknown optional sections, which are skipped but still checksummed.
fn flip_sample() -> (Container, Vec<u8>) {
    let c = sample()
        .with_section(SectionKind::new(7), vec![7; 5])
        .with_section(SectionKind::new(1001), vec![1; 3]);
    let bytes = c
        .to_bytes()
        .expect("unknown optional sections are writable");
    (c, bytes)
}

/// What each byte of a stream is, for the expected error of a flip.
#[derive(Debug, Clone, PartialEq)]
enum Part {
    Magic,
    Major,
    HeaderLen,
    /// Minor version, header body or header CRC: covered by the header CRC.
    HeaderCovered,
    SectionFraming,
    /// Payload or CRC of the named section.
    SectionData(String),
    EndMarker,
}

fn parts(bytes: &[u8]) -> Vec<Part> {
    let header_end = peek_header(bytes).expect("a valid stream").header_end as usize;
    let mut p = vec![Part::Magic; 4];
    p.push(Part::Major);
    p.push(Part::HeaderCovered);
    let mut pos = 6;
    read_varint(bytes, &mut pos).expect("header length");
    p.resize(pos, Part::HeaderLen);
    p.resize(header_end, Part::HeaderCovered);
    pos = header_end;
    loop {
        let tag = read_varint(bytes, &mut pos).expect("section tag");
        if tag == 0 {
            p.push(Part::EndMarker);
            break;
        }
        let len = read_varint(bytes, &mut pos).expect("section length") as usize;
        p.resize(pos, Part::SectionFraming);
        pos += len + 4;
        p.resize(pos, Part::SectionData(SectionKind::new(tag).to_string()));
    }
    assert_eq!(p.len(), bytes.len());
    p
}

#[test]
fn every_bit_flip_is_an_error() {
    let (_, bytes) = flip_sample();
    let parts = parts(&bytes);
    assert!(parts.contains(&Part::SectionData("section 1001".into())));
    for (i, part) in parts.iter().enumerate() {
        for bit in 0..8 {
            let mut b = bytes.clone();
            b[i] ^= 1 << bit;
            let check = |e: &Error| match part {
                Part::Magic => matches!(e, Error::BadMagic { .. }),
                Part::Major => matches!(e, Error::Unsupported { minor: 0, .. }),
                Part::HeaderCovered => {
                    matches!(e, Error::ChecksumMismatch { section, .. } if section == "header")
                }
                Part::SectionData(name) => {
                    matches!(e, Error::ChecksumMismatch { section, .. } if section == name)
                }
                Part::HeaderLen | Part::SectionFraming | Part::EndMarker => matches!(
                    e,
                    Error::ChecksumMismatch { .. }
                        | Error::Truncated { .. }
                        | Error::Format(_)
                        | Error::LimitExceeded { .. }
                ),
            };
            refuse_all(&b, &Limits::DEFAULT, check);
        }
    }
}

#[test]
fn checksum_mismatch_names_the_section() {
    let mut bytes = sample_bytes();
    let geometry = bytes.windows(3).position(|w| w == [4, 90, 0]).unwrap();
    bytes[geometry + 10] ^= 0x80;
    let err = parse(&bytes, &Limits::DEFAULT).unwrap_err();
    assert!(
        err.to_string()
            .starts_with("checksum mismatch in geometry: stored 0x"),
        "{err}"
    );
}

#[test]
fn trailing_bytes_are_refused() {
    let bytes = sample_bytes();
    for extra in [&[0u8][..], &[1, 2, 3], &bytes] {
        let mut b = bytes.clone();
        b.extend_from_slice(extra);
        refuse_all(
            &b,
            &Limits::DEFAULT,
            |e| matches!(e, Error::Format(FormatError::TrailingBytes { offset }) if *offset == bytes.len() as u64),
        );
    }
}

#[test]
fn bad_magic() {
    let err = parse(b"PK\x03\x04 not a mesh", &Limits::DEFAULT).unwrap_err();
    assert!(
        matches!(&err, Error::BadMagic { found } if found == b"P"),
        "{err:?}"
    );
    assert_eq!(
        err.to_string(),
        "not a .whet stream: it starts with [50], not \"WHET\" (57 48 45 54)"
    );
    refuse_all(
        b"WHEX\x01\x00",
        &Limits::DEFAULT,
        |e| matches!(e, Error::BadMagic { found } if found == b"WHEX"),
    );
    assert!(matches!(peek_header(b"WHy"), Err(Error::BadMagic { .. })));
    assert!(matches!(
        peek_header(b"WH"),
        Err(Error::Truncated { offset: 2, .. })
    ));
}

#[test]
fn huge_counts_are_limit_errors() {
    for (v, t, what) in [
        (1 << 40, 1, "vertex count"),
        (3, u64::MAX, "triangle count"),
    ] {
        let bytes = stream((1, 0), &header_body(0, v, t, 1, &[]), &[0]);
        refuse_all(
            &bytes,
            &Limits::DEFAULT,
            |e| matches!(e, Error::LimitExceeded { what: w, .. } if *w == what),
        );
        assert!(parse(&bytes, &Limits::UNLIMITED).is_ok());
        assert_eq!(
            peek_header(&bytes).unwrap().triangle_count,
            t,
            "peek applies no limits"
        );
    }
}

/// A 2^60-byte section in a 30-byte input: refused on its length, before any allocation.
#[test]
fn huge_section_length_is_refused_before_allocating() {
    let mut after = vec![2];
    write_varint(&mut after, 1 << 60);
    after.extend_from_slice(&[0xAA; 4]);
    let honest = stream(
        (1, 0),
        &header_body(0, 3, 1, after.len() as u64, &[]),
        &after,
    );
    assert!(honest.len() <= 30, "{}", honest.len());
    refuse_all(
        &honest,
        &Limits::DEFAULT,
        |e| matches!(e, Error::LimitExceeded { what: "section length (bytes)", value, .. } if *value == 1 << 60),
    );
    refuse_all(&honest, &Limits::UNLIMITED, |e| {
        matches!(e, Error::Format(FormatError::SectionOverrun { tag: 2, .. }))
    });
    // The header also claims 2^61 bytes: the slice reader says Truncated at once, the streaming
    // readers start the payload (without reserving it) and run out of input.
    let lying = stream((1, 0), &header_body(0, 3, 1, 1 << 61, &[]), &after);
    refuse_all(&lying, &Limits::UNLIMITED, |e| {
        matches!(e, Error::Truncated { .. })
    });
    refuse_all(&lying, &Limits::DEFAULT, |e| {
        matches!(e, Error::Truncated { .. } | Error::LimitExceeded { .. })
    });
}

#[test]
fn huge_lengths_inside_the_header() {
    let bytes = stream((1, 0), &header_body(0, 3, 1, u64::MAX, &[]), &[0]);
    refuse_all(&bytes, &Limits::UNLIMITED, |e| {
        matches!(
            e,
            Error::Format(FormatError::LengthOverflow) | Error::Truncated { .. }
        )
    });
    assert!(matches!(
        peek_header(&bytes),
        Err(Error::Format(FormatError::LengthOverflow))
    ));

    // A bytes field claiming 2^62 bytes inside a 12-byte header body.
    let mut field = Vec::new();
    write_varint(&mut field, tag::ENCODER << 2 | 3);
    write_varint(&mut field, 1 << 62);
    let bytes = stream((1, 0), &header_body(0, 3, 1, 1, &field), &[0]);
    refuse_all(&bytes, &Limits::DEFAULT, |e| {
        matches!(e, Error::Format(FormatError::HeaderOverrun))
    });

    // A header length of 65 535 in a 20-byte input.
    let mut bytes = b"WHET\x01\x00".to_vec();
    write_varint(&mut bytes, 65_535);
    bytes.extend_from_slice(&[0; 11]);
    refuse_all(&bytes, &Limits::DEFAULT, |e| {
        matches!(e, Error::Truncated { .. })
    });
    let small = Limits::DEFAULT.with_max_section_bytes(1000);
    refuse_all(&bytes, &small, |e| {
        matches!(e, Error::LimitExceeded { value: 65_535, .. })
    });
}

#[test]
fn malformed_varints_in_the_header() {
    let overlong = stream((1, 0), &[0x80, 0x00, 3, 1, 1], &[0]);
    refuse_all(&overlong, &Limits::DEFAULT, |e| {
        matches!(e, Error::Format(FormatError::OverlongVarint))
    });
    let mut body = vec![0];
    body.extend_from_slice(&[0xff; 10]);
    let overflow = stream((1, 0), &body, &[0]);
    refuse_all(&overflow, &Limits::DEFAULT, |e| {
        matches!(e, Error::Format(FormatError::VarintOverflow))
    });
    let cut = stream((1, 0), &[0, 3, 1], &[0]);
    refuse_all(&cut, &Limits::DEFAULT, |e| {
        matches!(e, Error::Format(FormatError::HeaderOverrun))
    });
}

#[test]
fn unknown_mode() {
    let bytes = stream((1, 0), &header_body(3, 3, 1, 1, &[]), &[0]);
    refuse_all(&bytes, &Limits::DEFAULT, |e| {
        matches!(e, Error::Format(FormatError::UnknownMode(3)))
    });
    assert!(matches!(
        peek_header(&bytes),
        Err(Error::Format(FormatError::UnknownMode(3)))
    ));
}

fn exact_container(sections: &[(SectionKind, &[u8])]) -> Container {
    let mut c = Container::new(Header::new(Mode::Exact, 3, 1));
    for (kind, payload) in sections {
        c.set_section(*kind, payload.to_vec());
    }
    c
}

#[test]
fn unknown_optional_sections_are_skipped() {
    let bytes = stream_of(
        &[],
        &[
            section(2, b"conn"),
            section(3, b"new optional"),
            section(4, b"geom"),
            section(1 << 40 | 1, b"x"),
        ],
    );
    let expected = exact_container(&[
        (SectionKind::CONNECTIVITY, b"conn"),
        (SectionKind::GEOMETRY, b"geom"),
    ]);
    for (how, result) in decode_all(&bytes, &Limits::DEFAULT) {
        assert_eq!(result.unwrap(), expected, "{how}");
    }
    // Skipped sections do not count against the allocation limit: 4 header bytes + 8 kept.
    let tight = Limits::DEFAULT.with_max_alloc_bytes(12);
    assert_eq!(parse(&bytes, &tight).unwrap(), expected);
    // The writer emits unknown optional sections too, and they are skipped the same way.
    let written = expected
        .clone()
        .with_section(SectionKind::new(3), b"new optional".to_vec());
    assert_eq!(
        parse(&written.to_bytes().unwrap(), &Limits::DEFAULT).unwrap(),
        expected
    );
}

#[test]
fn unknown_required_sections_are_refused() {
    for tag in [10, 1000, 1 << 40] {
        let bytes = stream_of(
            &[],
            &[section(2, b"conn"), section(tag, b"must understand")],
        );
        refuse_all(
            &bytes,
            &Limits::DEFAULT,
            |e| matches!(e, Error::Format(FormatError::UnknownRequiredSection { tag: t }) if *t == tag),
        );
        let err = parse(&bytes, &Limits::DEFAULT).unwrap_err();
        assert_eq!(
            err.to_string(),
            format!("malformed .whet stream: unknown required section {tag}")
        );
    }
}

#[test]
fn sections_must_be_unique_and_ordered() {
    let dup = stream_of(&[], &[section(2, b"a"), section(2, b"b")]);
    refuse_all(&dup, &Limits::DEFAULT, |e| {
        matches!(e, Error::Format(FormatError::DuplicateSection { tag: 2 }))
    });
    let order = stream_of(&[], &[section(4, b"a"), section(2, b"b")]);
    refuse_all(&order, &Limits::DEFAULT, |e| {
        matches!(
            e,
            Error::Format(FormatError::SectionOrder {
                previous: 4,
                found: 2
            })
        )
    });
    let skipped_dup = stream_of(&[], &[section(7, b"a"), section(7, b"b")]);
    refuse_all(&skipped_dup, &Limits::DEFAULT, |e| {
        matches!(e, Error::Format(FormatError::DuplicateSection { tag: 7 }))
    });
}

fn field(tag: u64, ty: u64, value: &[u8]) -> Vec<u8> {
    let mut f = Vec::new();
    write_varint(&mut f, tag << 2 | ty);
    f.extend_from_slice(value);
    f
}

#[test]
fn unknown_optional_fields_are_skipped() {
    let fields = [
        field(tag::QUANT_BITS, 0, &[12]),
        field(13, 0, &[0xff, 0x01]),
        field(15, 1, &[0x03]),
        field(45, 2, &1.5f64.to_le_bytes()),
        field(47, 3, &[3, b'a', b'b', b'c']),
        field((1 << 50) | 1, 0, &[0]),
    ]
    .concat();
    let bytes = stream_of(&fields, &[]);
    let expected = Container::new(Header::new(Mode::Exact, 3, 1).with(tag::QUANT_BITS, 12u64));
    for (how, result) in decode_all(&bytes, &Limits::DEFAULT) {
        assert_eq!(result.unwrap(), expected, "{how}");
    }
}

#[test]
fn bad_fields_are_refused() {
    type Check = fn(&FormatError) -> bool;
    let cases: [(Vec<u8>, Check); 6] = [
        (field(30, 0, &[1]), |e| {
            matches!(e, FormatError::UnknownRequiredField { tag: 30 })
        }),
        ([field(4, 0, &[1]), field(4, 0, &[2])].concat(), |e| {
            matches!(
                e,
                FormatError::FieldOrder {
                    previous: 4,
                    found: 4
                }
            )
        }),
        ([field(8, 2, &[0; 8]), field(4, 0, &[2])].concat(), |e| {
            matches!(
                e,
                FormatError::FieldOrder {
                    previous: 8,
                    found: 4
                }
            )
        }),
        (field(tag::EDGE_LENGTH, 0, &[1]), |e| {
            matches!(e, FormatError::FieldType { tag: 8, .. })
        }),
        (field(tag::BBOX, 3, &[47; 48]), |e| {
            matches!(e, FormatError::FieldValue { tag: 6, .. })
        }),
        (field(tag::EDGE_LENGTH, 2, &[0; 7]), |e| {
            matches!(e, FormatError::HeaderOverrun)
        }),
    ];
    for (fields, check) in cases {
        let bytes = stream_of(&fields, &[]);
        refuse_all(
            &bytes,
            &Limits::DEFAULT,
            |e| matches!(e, Error::Format(f) if check(f)),
        );
    }
}

#[test]
fn io_errors_pass_through() {
    struct Broken;
    impl std::io::Read for Broken {
        fn read(&mut self, _: &mut [u8]) -> std::io::Result<usize> {
            Err(std::io::ErrorKind::ConnectionReset.into())
        }
    }
    let err = read_from(Broken, &Limits::DEFAULT).unwrap_err();
    assert!(matches!(&err, Error::Io(e) if e.kind() == std::io::ErrorKind::ConnectionReset));
    assert!(!err.is_input_error());
}
