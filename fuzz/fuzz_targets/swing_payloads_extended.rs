//! The swing decoder behind the container's CRCs with the extended surface filter (see
//! `whet_codec::fuzz_swing_payloads_extended`): the `swing_payloads` input behind three
//! filter factors, so mutations reach the extended filter's fields on hostile meshes.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    whet_codec::fuzz_swing_payloads_extended(data);
});
