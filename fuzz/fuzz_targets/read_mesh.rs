//! The mesh file readers on arbitrary bytes: an error or a mesh, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for format in whet_io::Format::ALL {
        let _ = whet_io::read(data, format);
    }
});
