//! docs/format.md §6: unknown majors are refused with a clear message, newer minors are read.

use whet_format::{parse, peek_header, Error, Limits, Version};

use crate::common::*;

fn with_version(major: u8, minor: u8) -> Vec<u8> {
    let mut bytes = sample_bytes();
    bytes[4] = major;
    bytes[5] = minor;
    fix_header_crc(&mut bytes);
    bytes
}

#[test]
fn next_major_is_refused() {
    let bytes = with_version(2, 0);
    for (how, result) in decode_all(&bytes, &Limits::DEFAULT) {
        let err = result.unwrap_err();
        assert!(
            matches!(err, Error::Unsupported { major: 2, minor: 0 }),
            "{how}: {err:?}"
        );
        assert_eq!(
            err.to_string(),
            "stream format version 2.0 is newer than this whet (reads 1.x); upgrade whet"
        );
    }
    assert!(matches!(
        peek_header(&bytes),
        Err(Error::Unsupported { major: 2, .. })
    ));
    // Refused from the version bytes alone, before the header CRC is read.
    assert!(matches!(
        peek_header(b"WHET\x03\x00"),
        Err(Error::Unsupported { major: 3, .. })
    ));
    assert!(matches!(
        parse(b"WHET\xff\x07", &Limits::DEFAULT),
        Err(Error::Unsupported {
            major: 255,
            minor: 7
        })
    ));
}

#[test]
fn major_zero_is_refused() {
    let err = parse(&with_version(0, 9), &Limits::DEFAULT).unwrap_err();
    assert!(matches!(err, Error::Unsupported { major: 0, minor: 9 }));
    assert!(err.to_string().contains("older"), "{err}");
}

#[test]
fn next_minor_is_read() {
    for minor in [1, 2, 255] {
        let bytes = with_version(1, minor);
        for (how, result) in decode_all(&bytes, &Limits::DEFAULT) {
            let c = result.unwrap();
            assert_eq!(c.header.version, Version::new(1, minor), "{how}");
            assert_eq!(c.sections, sample().sections, "{how}");
        }
        assert_eq!(peek_header(&bytes).unwrap().version, Version::new(1, minor));
    }
}

#[test]
fn writer_writes_the_requested_version() {
    let mut c = sample();
    c.header = c.header.with_version(Version::new(1, 3));
    let bytes = c.to_bytes().unwrap();
    assert_eq!(&bytes[4..6], &[1, 3]);
    assert_eq!(parse(&bytes, &Limits::DEFAULT).unwrap(), c);
    c.header.version = Version::new(2, 0);
    assert!(matches!(c.to_bytes(), Err(Error::Parameter(_))));
    assert_eq!(Version::CURRENT.to_string(), "1.0");
    assert_eq!(
        whet_format::Header::new(whet_format::Mode::Exact, 0, 0).version,
        Version::CURRENT
    );
}
