//! The `.whet` decoder on arbitrary bytes (see `whet_codec::fuzz_decode`): an error or a
//! valid mesh, never a panic, a hang or an unbounded allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| whet_codec::fuzz_decode(data));
