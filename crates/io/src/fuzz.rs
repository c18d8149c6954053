//! The entry point of the `read_mesh` cargo-fuzz target (`fuzz/`), shared with the replay
//! test of its corpus (`tests/it/fuzz_replay.rs`).
//!
//! The OFF and OBJ readers cut their input into blocks and pieces parsed in parallel; a
//! fuzzer's inputs are far smaller than a block, so besides reading every format with the
//! default cut, this reads OFF and OBJ again in blocks and pieces of a few bytes (sizes
//! taken from the input's last bytes) and checks that both readings agree, errors included.

use crate::text::{Chunking, MAX_LINE};
use crate::Format;

/// Reads `data` in every format (an error or a mesh, never a panic), and OFF and OBJ again
/// with small blocks and pieces.
///
/// # Panics
///
/// When a small cut reads `data` otherwise than the default one: the bug the target looks
/// for.
pub fn read_every_way(data: &[u8]) {
    for format in Format::ALL {
        let _ = crate::read(data, format);
    }
    let at = |k: usize| usize::from(data.len().checked_sub(k).map_or(0, |i| data[i]));
    let small = Chunking {
        block: 1 + at(1) % 64,
        max_line: if at(2) % 4 == 0 {
            1 + at(3) % 48
        } else {
            MAX_LINE
        },
        piece: 1 + at(4) % 32,
    };
    let default = Chunking {
        max_line: small.max_line,
        ..Chunking::DEFAULT
    };
    let off = |c| format!("{:?}", crate::off::read_chunked(data, &c));
    assert_eq!(off(small), off(default), "OFF read with {small:?}");
    let obj = |c| format!("{:?}", crate::obj::read_chunked(data, &c));
    assert_eq!(obj(small), obj(default), "OBJ read with {small:?}");
}
