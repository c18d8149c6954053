//! The swing encoder on arbitrary small meshes (see `whet_swing::fuzz_encode`): a clean
//! refusal, or a stream that decodes bit for bit to the encoder's retiled mesh; never a
//! panic or an internal error.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| whet_swing::fuzz_encode(data));
