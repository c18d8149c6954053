//! `fuzz_parse` on random and mutated inputs: it must never panic.

use proptest::prelude::*;
use whet_format::fuzz_parse;

use crate::common::*;

#[test]
fn truncations_and_flips() {
    let bytes = sample_bytes();
    for n in 0..=bytes.len() {
        fuzz_parse(&bytes[..n]);
    }
    for i in 0..bytes.len() {
        for bit in 0..8 {
            let mut b = bytes.clone();
            b[i] ^= 1 << bit;
            fuzz_parse(&b);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn random_bytes(data in proptest::collection::vec(any::<u8>(), 0..200)) {
        fuzz_parse(&data);
        let mut prefixed = b"WHET\x01\x00".to_vec();
        prefixed.extend_from_slice(&data);
        fuzz_parse(&prefixed);
    }

    #[test]
    fn mutated_streams(
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>(), 0u8..3), 1..6),
    ) {
        let mut b = sample_bytes();
        for (at, byte, op) in edits {
            let i = at.index(b.len());
            match op {
                0 => b[i] = byte,
                1 => b.insert(i, byte),
                _ => { b.remove(i); }
            }
        }
        fuzz_parse(&b);
    }
}
