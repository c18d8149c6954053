//! The error type shared by every reader and writer.

use std::io;
use std::path::PathBuf;

/// Everything that can go wrong while reading or writing a mesh file.
///
/// [`Error::is_input_error`] separates "this file cannot be read as a mesh" from failures of the
/// machine (a disk that is full, a directory that cannot be written).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An error from the underlying reader or writer.
    #[error("I/O error: {0}")]
    Io(#[from] io::Error),

    /// No format was given and the file name's extension names none of the known formats.
    #[error(
        "cannot tell the mesh format of {}: the extension must be .off, .obj, .ply or .stl",
        path.display()
    )]
    UnknownFormat {
        /// The path whose extension was not recognised.
        path: PathBuf,
    },

    /// The text of the file (or the PLY header) does not follow the format.
    #[error("{}", parse_message(*line, message))]
    Parse {
        /// 1-based line number for text formats and PLY headers; 0 for binary data, which has
        /// no lines.
        line: usize,
        /// What is wrong.
        message: String,
    },

    /// The file ended before the data its header or structure announced.
    #[error("file is truncated: {what}")]
    Truncated {
        /// What was expected and where the file ended, e.g.
        /// "expected 6475 vertices, file ended after 12".
        what: String,
    },

    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate (NaN or infinity)")]
    NonFinite {
        /// 0-based index of the offending vertex.
        vertex: usize,
    },

    /// A face refers to a vertex that does not exist.
    #[error(
        "face {face} refers to vertex {index}, but the mesh has {vertex_count} vertices \
         (valid indices are 0..{vertex_count})"
    )]
    IndexOutOfRange {
        /// 0-based index of the face (polygon) in file order, before triangulation. Writers
        /// report the triangle index.
        face: usize,
        /// The offending index, 0-based (OBJ's 1-based and negative indices are converted).
        index: i64,
        /// Number of vertices of the mesh.
        vertex_count: usize,
    },

    /// The file uses a feature of its format that whet does not read.
    #[error("unsupported: {what}")]
    Unsupported {
        /// The feature, e.g. "PLY file has no vertex element".
        what: String,
    },

    /// A count is larger than whet can represent (indices are `u32`).
    #[error("{what} count {count} is too large (at most 4294967295)")]
    TooLarge {
        /// What was counted, e.g. "PLY vertex".
        what: String,
        /// The count found in the file or the mesh.
        count: u64,
    },

    /// An argument given to a writer does not fit the mesh (a caller's mistake, not bad data).
    #[error("{what} has {actual} entries, but the mesh has {expected} vertices")]
    LengthMismatch {
        /// The argument, e.g. "quality".
        what: &'static str,
        /// The required length.
        expected: usize,
        /// The length given.
        actual: usize,
    },
}

fn parse_message(line: usize, message: &str) -> String {
    if line == 0 {
        format!("malformed binary data: {message}")
    } else {
        format!("line {line}: {message}")
    }
}

impl Error {
    /// True when the error means "this input cannot be read as a mesh": malformed, truncated or
    /// unsupported content, a non-finite coordinate, an out-of-range index, an absurd count, an
    /// unknown format, and I/O errors of kind `InvalidData` or `UnexpectedEof`. False for other
    /// I/O errors (file not found, permission denied, disk full) and for writer argument
    /// mistakes.
    pub fn is_input_error(&self) -> bool {
        match self {
            Error::Io(e) => matches!(
                e.kind(),
                io::ErrorKind::InvalidData | io::ErrorKind::UnexpectedEof
            ),
            Error::LengthMismatch { .. } => false,
            Error::UnknownFormat { .. }
            | Error::Parse { .. }
            | Error::Truncated { .. }
            | Error::NonFinite { .. }
            | Error::IndexOutOfRange { .. }
            | Error::Unsupported { .. }
            | Error::TooLarge { .. } => true,
        }
    }

    pub(crate) fn parse(line: usize, message: impl Into<String>) -> Error {
        Error::Parse {
            line,
            message: message.into(),
        }
    }

    pub(crate) fn truncated(what: impl Into<String>) -> Error {
        Error::Truncated { what: what.into() }
    }

    pub(crate) fn unsupported(what: impl Into<String>) -> Error {
        Error::Unsupported { what: what.into() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_problem() {
        let e = Error::parse(12, "expected 3 coordinates");
        assert_eq!(e.to_string(), "line 12: expected 3 coordinates");
        let e = Error::parse(0, "face 3 has 2 vertices");
        assert_eq!(
            e.to_string(),
            "malformed binary data: face 3 has 2 vertices"
        );
        let e = Error::IndexOutOfRange {
            face: 4,
            index: 9,
            vertex_count: 8,
        };
        assert!(e.to_string().contains("face 4 refers to vertex 9"));
        let e = Error::truncated("expected 6475 vertices, file ended after 12");
        assert!(e.to_string().contains("6475"));
    }

    #[test]
    fn input_errors_are_classified() {
        assert!(Error::truncated("x").is_input_error());
        assert!(Error::NonFinite { vertex: 0 }.is_input_error());
        assert!(Error::TooLarge {
            what: "PLY vertex".into(),
            count: 1 << 40
        }
        .is_input_error());
        assert!(Error::UnknownFormat {
            path: PathBuf::from("a.txt")
        }
        .is_input_error());
        assert!(Error::Io(io::Error::from(io::ErrorKind::UnexpectedEof)).is_input_error());
        assert!(Error::Io(io::Error::from(io::ErrorKind::InvalidData)).is_input_error());
        assert!(!Error::Io(io::Error::from(io::ErrorKind::PermissionDenied)).is_input_error());
        assert!(!Error::LengthMismatch {
            what: "quality",
            expected: 3,
            actual: 2
        }
        .is_input_error());
    }
}
