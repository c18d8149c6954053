//! Truncated, bit-flipped, random and version-bumped streams give clear errors.

use whet_codec::{
    decode, decode_reusing, encode, DecodeBuffers, DecodeOptions, EncodeOptions, Error,
};
use whet_testkit::meshes::*;

fn sample_stream() -> Vec<u8> {
    sample_stream_with(whet_codec::ExactPrediction::Degree)
}

fn sample_stream_with(prediction: whet_codec::ExactPrediction) -> Vec<u8> {
    let m = shuffle(
        &union(torus(6, 5), &punch(&icosphere(2), |i| i % 9 == 0), 4.0),
        1,
    );
    let opts = EncodeOptions::DEFAULT
        .with_quant_bits(11)
        .with_prediction(prediction);
    encode(&m, &opts).unwrap().bytes
}

/// Streams of every exact prediction.
fn sample_streams() -> [Vec<u8>; 3] {
    [
        sample_stream(),
        sample_stream_with(whet_codec::ExactPrediction::Traversal),
        sample_stream_with(whet_codec::ExactPrediction::TraversalStatic),
    ]
}

#[test]
fn every_truncation_is_an_error() {
    for bytes in sample_streams() {
        for cut in 0..bytes.len() {
            let e = decode(&bytes[..cut], &DecodeOptions::DEFAULT).unwrap_err();
            assert!(e.is_input_error(), "cut {cut}: {e}");
        }
    }
}

#[test]
fn every_bit_flip_is_an_error() {
    for bytes in sample_streams() {
        // Decoders that keep their buffers across the corrupt streams fail the same way.
        let mut buffers = DecodeBuffers::new();
        for i in 0..bytes.len() * 8 {
            let mut b = bytes.clone();
            b[i / 8] ^= 1 << (i % 8);
            let r = decode(&b, &DecodeOptions::DEFAULT);
            assert!(r.is_err(), "flip of bit {i} decoded silently");
            let reused = decode_reusing(&b, &DecodeOptions::DEFAULT, &mut buffers);
            assert_eq!(
                reused.map_err(|e| e.to_string()),
                r.map_err(|e| e.to_string())
            );
        }
        let clean = decode_reusing(&bytes, &DecodeOptions::DEFAULT, &mut buffers).unwrap();
        assert_eq!(clean, decode(&bytes, &DecodeOptions::DEFAULT).unwrap());
    }
}

#[test]
fn crc_mismatch_names_the_section() {
    let bytes = sample_stream();
    // The last bytes are the geometry section's payload, its CRC, and the end marker.
    let mut b = bytes.clone();
    let i = b.len() - 8;
    b[i] ^= 0x10;
    let e = decode(&b, &DecodeOptions::DEFAULT).unwrap_err();
    assert!(e.to_string().contains("geometry"), "{e}");
}

#[test]
fn newer_major_version_is_refused() {
    let mut bytes = sample_stream();
    bytes[4] = 2;
    let e = decode(&bytes, &DecodeOptions::DEFAULT).unwrap_err();
    assert!(
        matches!(
            e,
            Error::Format(whet_format::Error::Unsupported { major: 2, .. })
        ),
        "{e}"
    );
    assert!(e.to_string().contains("newer"), "{e}");
}

#[test]
fn random_bytes_never_panic() {
    let mut x = 0x1234_5678_9abc_def0u64;
    for len in [0usize, 1, 5, 16, 64, 300] {
        for _ in 0..200 {
            let mut b: Vec<u8> = (0..len)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    x as u8
                })
                .collect();
            if len > 6 {
                b[..6].copy_from_slice(b"WHET\x01\x00");
            }
            assert!(decode(&b, &DecodeOptions::DEFAULT).is_err());
        }
    }
}

/// The decoded mesh's memory is estimated from the header's counts and held against
/// `max_alloc_bytes` before decoding: a budget under the estimate refuses the stream, with
/// the estimate named; the estimate itself passes.
#[test]
fn decoding_is_refused_past_the_byte_limit() {
    let bytes = sample_stream();
    let info = whet_codec::peek_header(&bytes).unwrap();
    let estimate = info.triangle_count * whet_codec::DECODE_BYTES_PER_TRIANGLE
        + info.vertex_count * whet_codec::DECODE_BYTES_PER_VERTEX;
    let with = |max: u64| {
        whet_codec::decode(
            &bytes,
            &DecodeOptions::DEFAULT
                .with_limits(whet_codec::Limits::DEFAULT.with_max_alloc_bytes(max)),
        )
    };
    assert!(with(estimate).is_ok());
    match with(estimate - 1) {
        Err(whet_codec::Error::Format(whet_format::Error::LimitExceeded {
            what,
            limit,
            value,
        })) => {
            assert!(what.contains("decoding"), "{what}");
            assert_eq!((limit, value), (estimate - 1, estimate));
        }
        other => panic!("{other:?}"),
    }
}

/// The traversal prediction's streams say so in header field 40 and are format 1.5; the
/// default's carry no such field and keep their version. A value this whet does not know is
/// refused by name, with valid CRCs (a newer writer's stream), and a 1.4 reader, which does
/// not know the required field, refuses it by tag rather than misreading the geometry.
#[test]
fn the_exact_prediction_field_is_written_read_and_refused_when_unknown() {
    use whet_codec::ExactPrediction;
    use whet_format::{parse, tag, Limits};
    let m = punch(&icosphere(3), |i| i % 17 == 3);
    let traversal = EncodeOptions::DEFAULT.with_prediction(ExactPrediction::Traversal);
    let t = encode(&m, &traversal).unwrap().bytes;
    let d = encode(&m, &EncodeOptions::DEFAULT).unwrap().bytes;
    let (ct, cd) = (
        parse(&t, &Limits::DEFAULT).unwrap(),
        parse(&d, &Limits::DEFAULT).unwrap(),
    );
    assert_eq!(ct.header.get_u64(tag::EXACT_PREDICTION), Some(1));
    assert_eq!(ct.header.version, whet_codec::Version::new(1, 5));
    assert_eq!(cd.header.get_u64(tag::EXACT_PREDICTION), None);
    assert_eq!(cd.header.version, whet_codec::Version::new(1, 0));
    // Both decode to the same mesh: the same connectivity, hence the same vertex order
    // and triangles, and the same grid positions (the prediction changes the residuals,
    // not the coded values).
    let (mt, md) = (
        decode(&t, &DecodeOptions::DEFAULT).unwrap(),
        decode(&d, &DecodeOptions::DEFAULT).unwrap(),
    );
    assert_eq!(mt, md);
    // The static residual code: value 2, format 1.6, the same mesh again; its payload read
    // as the adaptive traversal code's is refused or another mesh.
    let static_opts = EncodeOptions::DEFAULT.with_prediction(ExactPrediction::TraversalStatic);
    let st = encode(&m, &static_opts).unwrap().bytes;
    let cs = parse(&st, &Limits::DEFAULT).unwrap();
    assert_eq!(cs.header.get_u64(tag::EXACT_PREDICTION), Some(2));
    assert_eq!(cs.header.version, whet_codec::Version::new(1, 6));
    assert_eq!(decode(&st, &DecodeOptions::DEFAULT).unwrap(), mt);
    let mut c = cs.clone();
    c.header.set(tag::EXACT_PREDICTION, 1u64);
    match decode(&c.to_bytes().unwrap(), &DecodeOptions::DEFAULT) {
        Ok(other) => assert_ne!(other, mt),
        Err(e) => assert!(e.is_input_error(), "{e}"),
    }
    // An unknown value, with valid CRCs.
    let mut c = ct.clone();
    c.header.set(tag::EXACT_PREDICTION, 3u64);
    let e = decode(&c.to_bytes().unwrap(), &DecodeOptions::DEFAULT).unwrap_err();
    assert!(e.is_input_error(), "{e}");
    assert!(e.to_string().contains("exact prediction 3"), "{e}");
    // Without the field the traversal payload is read as the degree order's: refused or a
    // different mesh, never the same one (the field is what keeps old readers out).
    let mut c = ct;
    c.header.remove(tag::EXACT_PREDICTION);
    match decode(&c.to_bytes().unwrap(), &DecodeOptions::DEFAULT) {
        Ok(other) => assert_ne!(other, mt),
        Err(e) => assert!(e.is_input_error(), "{e}"),
    }
}
