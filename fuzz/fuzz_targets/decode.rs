//! The `.whet` decoder on arbitrary bytes (see `whet_codec::fuzz_decode`), then the
//! sharpening the stream states on small decoded meshes, as `whet decode --sharpen` runs it
//! (`whet_swing::fuzz_decode_sharpen`): an error or a valid mesh, never a panic, a hang or an
//! unbounded allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| whet_swing::fuzz_decode_sharpen(data));
