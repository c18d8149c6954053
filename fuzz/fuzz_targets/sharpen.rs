//! The sharpener, the projections after it and one level of Bender on arbitrary small
//! meshes (see `whet_sharpen::fuzz_sharpen` and `whet_bend::fuzz_bend`): a clean refusal
//! or a valid oriented manifold, never a panic, an internal error or a broken guarantee.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Some((mesh, sharp_edges)) = whet_sharpen::fuzz_sharpen(data) {
        whet_bend::fuzz_bend(&mesh, &sharp_edges);
    }
});
