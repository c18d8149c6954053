//! The entry point for cargo-fuzz: every reader on the same bytes, cross-checked.

use crate::decoder::{parse, read_from, Progress, StreamingDecoder};
use crate::header::peek_header;
use crate::limits::Limits;
use crate::{Container, Error};

/// Runs every reader on `data` and checks that they agree.
///
/// Never panics on any input unless whet-format has a bug: the slice, `Read` and streaming
/// (in chunks chosen by the first byte) readers must accept the same streams with the same
/// result, [`peek_header`] must agree with an accepted header, and re-encoding an accepted
/// container must give a stream that parses back to it and, unless unknown optional fields or
/// sections were dropped, exactly the input bytes (the format is canonical).
pub fn fuzz_parse(data: &[u8]) {
    let limits = Limits::DEFAULT;
    let peeked = peek_header(data);
    let whole = parse(data, &limits);
    let chunk = 1 + usize::from(data.first().copied().unwrap_or(0) % 17);
    let streamed = parse_chunked(data, chunk, &limits);
    let read = read_from(data, &limits);
    let Ok(container) = whole else {
        assert!(streamed.is_err(), "streaming accepted what parse refused");
        assert!(read.is_err(), "read_from accepted what parse refused");
        return;
    };
    assert!(
        streamed.as_ref().ok() == Some(&container),
        "streaming disagrees with parse"
    );
    assert!(
        read.as_ref().ok() == Some(&container),
        "read_from disagrees with parse"
    );
    let h = &container.header;
    assert!(
        matches!(peeked, Ok(info) if info.version == h.version
            && info.mode == h.mode
            && info.vertex_count == h.vertex_count
            && info.triangle_count == h.triangle_count
            && info.total_len == data.len() as u64),
        "peek_header disagrees with parse"
    );
    let again = container.to_bytes();
    assert!(
        matches!(&again, Ok(bytes) if bytes.len() < data.len() || bytes == data),
        "re-encoding is not canonical"
    );
    if let Ok(bytes) = again {
        assert!(
            parse(&bytes, &limits).ok() == Some(container),
            "re-encoded stream does not parse back"
        );
    }
}

/// [`parse`] through the streaming decoder, `chunk` bytes at a time.
pub(crate) fn parse_chunked(
    data: &[u8],
    chunk: usize,
    limits: &Limits,
) -> Result<Container, Error> {
    let mut decoder = StreamingDecoder::new(*limits);
    for piece in data.chunks(chunk.max(1)) {
        let mut rest = piece;
        while !rest.is_empty() {
            let (used, progress) = decoder.update(rest)?;
            rest = rest.get(used..).unwrap_or_default();
            if progress == Progress::NeedMore {
                break;
            }
        }
    }
    decoder.finish()
}
