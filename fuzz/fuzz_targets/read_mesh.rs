//! The mesh file readers on arbitrary bytes: an error or a mesh, never a panic; OFF and OBJ
//! read alike in small blocks and in the default ones (`whet_io::fuzz`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    whet_io::fuzz::read_every_way(data);
});
