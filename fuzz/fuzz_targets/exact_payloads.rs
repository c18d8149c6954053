//! The exact mode's connectivity and geometry decoders behind the container's CRCs (see
//! `whet_codec::fuzz_exact_payloads`): mutations reach the entropy decoders, the reverse
//! Edgebreaker decoder and the position walk directly.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| whet_codec::fuzz_exact_payloads(data));
