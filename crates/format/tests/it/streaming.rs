//! The streaming decoder's results do not depend on how the input is split.

use proptest::prelude::*;
use whet_format::{Limits, Progress, SectionKind};

use crate::common::*;

fn expected_events() -> Vec<Progress> {
    let mut events = vec![Progress::HeaderReady];
    events.extend(SectionKind::KNOWN.map(Progress::SectionReady));
    events.push(Progress::Done);
    events
}

#[test]
fn every_chunk_size_gives_the_same_events_and_result() {
    let bytes = sample_bytes();
    for chunk in 1..=17 {
        let (events, result) = decode_chunked(&bytes, chunk, &Limits::DEFAULT);
        assert_eq!(events, expected_events(), "chunk {chunk}");
        assert_eq!(result.unwrap(), sample(), "chunk {chunk}");
    }
}

/// Corrupt and truncated streams give the same error, message included, for every chunking.
#[test]
fn errors_do_not_depend_on_chunking() {
    let bytes = sample_bytes();
    let mut inputs: Vec<Vec<u8>> = (0..bytes.len())
        .step_by(7)
        .map(|n| bytes[..n].to_vec())
        .collect();
    for i in (0..bytes.len()).step_by(5) {
        let mut b = bytes.clone();
        b[i] ^= 0x10;
        inputs.push(b);
    }
    for input in inputs {
        let (events1, reference) = decode_chunked(&input, 1, &Limits::DEFAULT);
        let reference = reference.unwrap_err().to_string();
        for chunk in 2..=17 {
            let (events, result) = decode_chunked(&input, chunk, &Limits::DEFAULT);
            assert_eq!(events, events1, "chunk {chunk}");
            assert_eq!(result.unwrap_err().to_string(), reference, "chunk {chunk}");
        }
    }
}

#[test]
fn one_byte_after_another_with_empty_chunks() {
    let bytes = sample_bytes();
    let mut d = whet_format::StreamingDecoder::default();
    for b in &bytes {
        assert_eq!(d.update(&[]).unwrap().0, 0);
        let (used, _) = d.update(std::slice::from_ref(b)).unwrap();
        assert_eq!(used, 1);
    }
    assert!(d.is_done());
    assert_eq!(d.finish().unwrap(), sample());
}

proptest! {
    #[test]
    fn random_splits(splits in proptest::collection::vec(0usize..200, 0..30)) {
        let bytes = sample_bytes();
        let (events, result) = decode_split(&bytes, &splits, &Limits::DEFAULT);
        prop_assert_eq!(events, expected_events());
        prop_assert_eq!(result.unwrap(), sample());
    }

    #[test]
    fn random_splits_of_random_containers(
        c in arb_container(),
        splits in proptest::collection::vec(0usize..1500, 0..30),
    ) {
        let bytes = c.to_bytes().unwrap();
        let (events, result) = decode_split(&bytes, &splits, &Limits::DEFAULT);
        let (one_shot, _) = decode_split(&bytes, &[], &Limits::DEFAULT);
        prop_assert_eq!(events, one_shot);
        prop_assert_eq!(result.unwrap(), c);
    }
}
