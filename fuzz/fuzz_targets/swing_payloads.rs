//! The swing decoder behind the container's CRCs (see `whet_codec::fuzz_swing_payloads`):
//! mutations reach the swing walk, the deletion flags and the surface filter directly.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    whet_codec::fuzz_swing_payloads(data);
});
