//! Names of the file formats and their encodings, and the options of the writers.

use std::fmt;
use std::path::Path;
use std::str::FromStr;

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Object File Format (`.off`), text.
    Off,
    /// Wavefront OBJ (`.obj`), text.
    Obj,
    /// Stanford Polygon File Format (`.ply`), text or binary.
    Ply,
    /// Stereolithography (`.stl`), text or binary.
    Stl,
}

impl Format {
    /// Every format, in a fixed order.
    pub const ALL: [Format; 4] = [Format::Off, Format::Obj, Format::Ply, Format::Stl];

    /// The format named by the path's extension, compared case-insensitively (`MESH.PLY` is
    /// PLY); `None` when the path has no extension or an unknown one.
    pub fn from_path(path: &Path) -> Option<Format> {
        path.extension()?.to_str()?.parse().ok()
    }

    /// The lower-case file extension of the format, without the dot (`"off"`).
    pub const fn extension(self) -> &'static str {
        match self {
            Format::Off => "off",
            Format::Obj => "obj",
            Format::Ply => "ply",
            Format::Stl => "stl",
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.extension())
    }
}

/// The error of [`Format::from_str`]: the string names no known format.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown mesh format '{0}': expected one of off, obj, ply, stl")]
pub struct ParseFormatError(
    /// The string that was not recognised.
    pub String,
);

impl FromStr for Format {
    type Err = ParseFormatError;

    /// Parses `"off"`, `"obj"`, `"ply"` or `"stl"`, ignoring ASCII case.
    fn from_str(s: &str) -> Result<Format, ParseFormatError> {
        Format::ALL
            .into_iter()
            .find(|f| s.eq_ignore_ascii_case(f.extension()))
            .ok_or_else(|| ParseFormatError(s.to_owned()))
    }
}

/// How a PLY file stores its elements.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PlyEncoding {
    /// `format ascii 1.0`: whitespace-separated numbers.
    Ascii,
    /// `format binary_little_endian 1.0` (the default: compact, exact and what most tools write).
    #[default]
    BinaryLittleEndian,
    /// `format binary_big_endian 1.0`.
    BinaryBigEndian,
}

/// How an STL file stores its facets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum StlEncoding {
    /// `solid ... endsolid` text; whet writes coordinates in shortest round-trip form, so the
    /// text is exact for f64.
    Ascii,
    /// 80-byte header, triangle count, 50-byte records of f32 (the default). Coordinates are
    /// rounded to f32.
    #[default]
    Binary,
}

/// Options of [`write`](crate::write()) and [`write_path`](crate::write_path) for formats that
/// have several encodings.
///
/// The struct is `#[non_exhaustive]`: start from [`WriteOptions::DEFAULT`] (or `Default`) and
/// change fields with the `with_*` methods or by assignment.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub struct WriteOptions {
    /// Encoding of PLY files (default binary little-endian).
    pub ply: PlyEncoding,
    /// Encoding of STL files (default binary).
    pub stl: StlEncoding,
}

impl WriteOptions {
    /// Binary little-endian PLY and binary STL.
    pub const DEFAULT: WriteOptions = WriteOptions {
        ply: PlyEncoding::BinaryLittleEndian,
        stl: StlEncoding::Binary,
    };

    /// These options with the PLY encoding replaced.
    #[must_use]
    pub const fn with_ply(mut self, ply: PlyEncoding) -> WriteOptions {
        self.ply = ply;
        self
    }

    /// These options with the STL encoding replaced.
    #[must_use]
    pub const fn with_stl(mut self, stl: StlEncoding) -> WriteOptions {
        self.stl = stl;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_path_is_case_insensitive() {
        assert_eq!(Format::from_path(Path::new("a/b.OFF")), Some(Format::Off));
        assert_eq!(Format::from_path(Path::new("x.obj")), Some(Format::Obj));
        assert_eq!(Format::from_path(Path::new("x.Ply")), Some(Format::Ply));
        assert_eq!(Format::from_path(Path::new("x.stl")), Some(Format::Stl));
        assert_eq!(Format::from_path(Path::new("x.txt")), None);
        assert_eq!(Format::from_path(Path::new("stl")), None);
    }

    #[test]
    fn from_str_and_display_agree() {
        for f in Format::ALL {
            assert_eq!(f.to_string().parse::<Format>(), Ok(f));
        }
        assert_eq!("STL".parse::<Format>(), Ok(Format::Stl));
        let err = "vrml".parse::<Format>().unwrap_err();
        assert!(err.to_string().contains("vrml"));
    }

    #[test]
    fn default_options() {
        assert_eq!(WriteOptions::default(), WriteOptions::DEFAULT);
        assert_eq!(WriteOptions::DEFAULT.ply, PlyEncoding::BinaryLittleEndian);
        assert_eq!(WriteOptions::DEFAULT.stl, StlEncoding::Binary);
        let o = WriteOptions::DEFAULT
            .with_ply(PlyEncoding::Ascii)
            .with_stl(StlEncoding::Ascii);
        assert_eq!((o.ply, o.stl), (PlyEncoding::Ascii, StlEncoding::Ascii));
    }
}
