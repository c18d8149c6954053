//! Caller-chosen bounds on what a hostile stream may make a reader allocate
//! (docs/format.md §5).

use crate::error::Error;

/// Upper bounds checked against declared counts and sizes before anything is allocated.
///
/// Exceeding one is [`Error::LimitExceeded`], not a format error: the stream may be fine and
/// merely larger than the caller allows. The codec uses [`Limits::check_counts`] and
/// [`Limits::check_alloc`] for its own allocations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub struct Limits {
    /// Most vertices a header may declare.
    pub max_vertices: u64,
    /// Most triangles a header may declare.
    pub max_faces: u64,
    /// Most bytes a reader keeps (the header plus kept section payloads); the codec checks its
    /// own buffers against it too: the decoded mesh, estimated from the header's counts
    /// before decoding (`whet_codec::DECODE_BYTES_PER_TRIANGLE`; at the default 4 GiB about
    /// 50M triangles, fewer than `max_faces` admits), and a subdiv stream's levels.
    pub max_alloc_bytes: u64,
    /// Longest section payload (and header body) a reader accepts.
    pub max_section_bytes: u64,
}

impl Limits {
    /// Safe defaults: 2^28 vertices and triangles, 4 GiB kept, 1 GiB per section.
    pub const DEFAULT: Limits = Limits {
        max_vertices: 1 << 28,
        max_faces: 1 << 28,
        max_alloc_bytes: 4 << 30,
        max_section_bytes: 1 << 30,
    };

    /// No limits, for trusted input only.
    pub const UNLIMITED: Limits = Limits {
        max_vertices: u64::MAX,
        max_faces: u64::MAX,
        max_alloc_bytes: u64::MAX,
        max_section_bytes: u64::MAX,
    };

    /// Sets [`Limits::max_vertices`].
    pub const fn with_max_vertices(mut self, max: u64) -> Self {
        self.max_vertices = max;
        self
    }

    /// Sets [`Limits::max_faces`].
    pub const fn with_max_faces(mut self, max: u64) -> Self {
        self.max_faces = max;
        self
    }

    /// Sets [`Limits::max_alloc_bytes`].
    pub const fn with_max_alloc_bytes(mut self, max: u64) -> Self {
        self.max_alloc_bytes = max;
        self
    }

    /// Sets [`Limits::max_section_bytes`].
    pub const fn with_max_section_bytes(mut self, max: u64) -> Self {
        self.max_section_bytes = max;
        self
    }

    /// Checks declared vertex and triangle counts.
    pub fn check_counts(&self, vertices: u64, faces: u64) -> Result<(), Error> {
        check("vertex count", self.max_vertices, vertices)?;
        check("triangle count", self.max_faces, faces)
    }

    /// Checks that `bytes` more bytes may be allocated (for a running total, pass the total).
    pub fn check_alloc(&self, bytes: u64) -> Result<(), Error> {
        check(ALLOCATION_LIMIT, self.max_alloc_bytes, bytes)
    }

    /// Checks a declared section (or header body) length.
    pub fn check_section(&self, len: u64) -> Result<(), Error> {
        check("section length (bytes)", self.max_section_bytes, len)
    }
}

/// The `what` of a [`Error::LimitExceeded`] from [`Limits::check_alloc`] (the bytes a reader
/// keeps).
pub const ALLOCATION_LIMIT: &str = "allocation (bytes)";

fn check(what: &'static str, limit: u64, value: u64) -> Result<(), Error> {
    if value > limit {
        Err(Error::LimitExceeded { what, limit, value })
    } else {
        Ok(())
    }
}

impl Default for Limits {
    fn default() -> Self {
        Limits::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_checks() {
        let l = Limits::default();
        assert_eq!(l, Limits::DEFAULT);
        assert!(l.check_counts(1 << 28, 1 << 28).is_ok());
        let err = l.check_counts(1 << 28, (1 << 28) + 1).unwrap_err();
        assert!(matches!(
            err,
            Error::LimitExceeded {
                what: "triangle count",
                limit: 268_435_456,
                value: 268_435_457
            }
        ));
        assert!(l.check_alloc(4 << 30).is_ok());
        assert!(l.check_alloc((4 << 30) + 1).is_err());
        let small = Limits::DEFAULT
            .with_max_section_bytes(10)
            .with_max_vertices(3);
        assert!(small.check_section(11).is_err());
        assert!(small.check_counts(4, 0).is_err());
        assert!(Limits::UNLIMITED.check_alloc(u64::MAX).is_ok());
        assert_eq!(
            err.to_string(),
            "triangle count 268435457 exceeds the limit of 268435456 \
             (raise the Limits if the input is trusted)"
        );
    }
}
