//! whet-io owns whet's mesh files: streaming readers and writers of OFF, OBJ, PLY (ascii and
//! binary, both byte orders) and STL (ascii and binary) that turn a file into a
//! [`whet_mesh::Mesh`] and back, the per-vertex quality/colour PLY export used for error maps,
//! and the [`Error`] that says why a file could not be read. Readers never trust header counts
//! for allocation, reject non-finite coordinates and out-of-range indices, fan-triangulate
//! polygons, and never panic on any input; text writers print coordinates in shortest
//! round-trip form, so OFF, OBJ, ascii STL and every PLY encoding reproduce f64 positions bit
//! for bit (binary STL stores f32).
//!
//! A mesh holds positions and triangles only: the readers skip texture coordinates, normals,
//! colours and every other attribute a file carries. [`read_with_report`] and
//! [`read_path_with_report`] also return a [`ReadReport`] that names what was skipped and how
//! much of it, so that an application can tell its user what a conversion drops.
//!
//! ```
//! use whet_io::{read, write, Format, WriteOptions};
//! use whet_mesh::{DVec3, Mesh};
//!
//! // A tetrahedron whose vertices appear in the triangles in index order.
//! let mesh = Mesh::new(
//!     vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.1, 0.2, -1.0 / 3.0)],
//!     vec![[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]],
//! );
//! for format in Format::ALL {
//!     let mut bytes = Vec::new();
//!     write(&mut bytes, &mesh, format, &WriteOptions::DEFAULT)?;
//!     let back = read(&bytes[..], format)?;
//!     // STL welds vertices in order of first appearance, so the triangles match here too.
//!     assert_eq!(back.triangles, mesh.triangles);
//!     if format != Format::Stl {
//!         assert_eq!(back, mesh); // binary STL rounds coordinates to f32
//!     }
//! }
//! # Ok::<(), whet_io::Error>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod binary;
mod error;
mod format;
#[doc(hidden)]
pub mod fuzz;
mod obj;
mod off;
mod ply;
mod report;
mod stl;
mod text;

use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::Path;

use whet_mesh::{DVec3, Mesh};

pub use error::Error;
pub use format::{Format, ParseFormatError, PlyEncoding, StlEncoding, WriteOptions};
pub use report::{ReadReport, Skipped};

/// Readers reserve at most this many vertices or triangles up front, whatever a header claims;
/// beyond it vectors grow as data actually arrives.
const MAX_PREALLOC: u64 = 1 << 20;

/// Buffer size of the readers and writers made by [`read_path`], [`write_path`] and [`write()`].
const BUF_SIZE: usize = 1 << 16;

/// Reads the mesh file at `path`.
///
/// With `format` `None` the format comes from the extension ([`Format::from_path`]); an
/// unknown extension gives [`Error::UnknownFormat`]. The file is streamed through a
/// `BufReader`. For STL the file size decides between ascii and binary when the header starts
/// with `solid` (see [`read()`]). Attributes the file holds besides positions and polygons are
/// skipped without a word; [`read_path_with_report`] says which.
pub fn read_path(path: &Path, format: Option<Format>) -> Result<Mesh, Error> {
    read_path_with_report(path, format).map(|(mesh, _)| mesh)
}

/// Reads the mesh file at `path` as [`read_path`] does, and reports what the file held that
/// the mesh does not keep (texture coordinates, normals, colours, other PLY properties and
/// elements...; see [`ReadReport`]).
pub fn read_path_with_report(
    path: &Path,
    format: Option<Format>,
) -> Result<(Mesh, ReadReport), Error> {
    let format = resolve_format(path, format)?;
    let file = File::open(path)?;
    let size = file
        .metadata()
        .ok()
        .filter(|m| m.is_file())
        .map(|m| m.len());
    read_impl(BufReader::with_capacity(BUF_SIZE, file), format, size)
}

/// Reads a mesh in `format` from a buffered reader.
///
/// Binary data is decoded record by record and text line by line, except OFF bodies and OBJ
/// files, which are read in blocks of 4 MiB whose lines are parsed on rayon's threads;
/// nothing is read in one piece. Reading may consume bytes past the end of the mesh (up to
/// a block after an OFF file's last face). Polygons are fan-triangulated. STL vertices are welded exactly (identical
/// coordinates become one vertex, in order of first appearance). An STL stream whose first
/// bytes are `solid` is read as ascii when its first 84 bytes are all text and as binary
/// otherwise; [`read_path`] decides by the file size instead. Attributes besides positions and
/// polygons are skipped without a word; [`read_with_report`] says which.
pub fn read<R: BufRead>(reader: R, format: Format) -> Result<Mesh, Error> {
    read_with_report(reader, format).map(|(mesh, _)| mesh)
}

/// Reads a mesh in `format` from a buffered reader as [`read()`] does, and reports what the
/// file held that the mesh does not keep (see [`ReadReport`]). The report is made of counters:
/// reading stays streaming and allocates nothing more for it as the input grows.
pub fn read_with_report<R: BufRead>(
    reader: R,
    format: Format,
) -> Result<(Mesh, ReadReport), Error> {
    read_impl(reader, format, None)
}

fn read_impl<R: BufRead>(
    reader: R,
    format: Format,
    size: Option<u64>,
) -> Result<(Mesh, ReadReport), Error> {
    match format {
        Format::Off => off::read(reader),
        Format::Obj => obj::read(reader),
        Format::Ply => ply::read(reader),
        Format::Stl => stl::read(reader, size),
    }
}

/// Writes `mesh` to a new file at `path` (replacing any file there).
///
/// With `format` `None` the format comes from the extension; an unknown extension gives
/// [`Error::UnknownFormat`]. See [`write()`] for what is checked and how each format is written.
/// On error a partly written file may remain.
pub fn write_path(
    path: &Path,
    mesh: &Mesh,
    format: Option<Format>,
    opts: &WriteOptions,
) -> Result<(), Error> {
    let format = resolve_format(path, format)?;
    check_writable(mesh)?;
    write(File::create(path)?, mesh, format, opts)
}

/// Writes `mesh` in `format` to `w`, buffering internally (pass a `File` or `&mut Vec<u8>`
/// directly).
///
/// The mesh is checked first, so that whatever is written reads back: a non-finite coordinate
/// gives [`Error::NonFinite`] and an index past the vertex count [`Error::IndexOutOfRange`]
/// (with the triangle's index as `face`), before anything is written. Coordinates of the text
/// encodings are printed in shortest round-trip form and PLY stores doubles, so everything but
/// binary STL (f32) reads back bit for bit.
pub fn write<W: Write>(
    w: W,
    mesh: &Mesh,
    format: Format,
    opts: &WriteOptions,
) -> Result<(), Error> {
    check_writable(mesh)?;
    let mut w = BufWriter::with_capacity(BUF_SIZE, w);
    match format {
        Format::Off => off::write(&mut w, mesh)?,
        Format::Obj => obj::write(&mut w, mesh)?,
        Format::Ply => ply::write(&mut w, mesh, &[], &[], opts.ply)?,
        Format::Stl => stl::write(&mut w, mesh, opts.stl)?,
    }
    w.flush()?;
    Ok(())
}

/// Writes `mesh` as PLY with per-vertex `property double quality` and `property uchar red`,
/// `green`, `blue` after `x y z`, the layout MeshLab shows as a quality or colour map.
///
/// `quality` and `colors` each hold one entry per vertex, or are empty to leave that property
/// out; any other length gives [`Error::LengthMismatch`]. Quality values are written as given
/// (not checked for finiteness); the mesh is checked as in [`write()`].
pub fn write_ply_with_quality<W: Write>(
    w: W,
    mesh: &Mesh,
    quality: &[f64],
    colors: &[[u8; 3]],
    encoding: PlyEncoding,
) -> Result<(), Error> {
    let n = mesh.positions.len();
    if !quality.is_empty() && quality.len() != n {
        return Err(Error::LengthMismatch {
            what: "quality",
            expected: n,
            actual: quality.len(),
        });
    }
    if !colors.is_empty() && colors.len() != n {
        return Err(Error::LengthMismatch {
            what: "colors",
            expected: n,
            actual: colors.len(),
        });
    }
    check_writable(mesh)?;
    let mut w = BufWriter::with_capacity(BUF_SIZE, w);
    ply::write(&mut w, mesh, quality, colors, encoding)?;
    w.flush()?;
    Ok(())
}

fn resolve_format(path: &Path, format: Option<Format>) -> Result<Format, Error> {
    match format {
        Some(f) => Ok(f),
        None => Format::from_path(path).ok_or_else(|| Error::UnknownFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// Checks that every coordinate is finite and every index names a vertex.
fn check_writable(mesh: &Mesh) -> Result<(), Error> {
    if let Some(vertex) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinite { vertex });
    }
    let vertex_count = mesh.positions.len();
    for (face, t) in mesh.triangles.iter().enumerate() {
        if let Some(&i) = t.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(Error::IndexOutOfRange {
                face,
                index: i64::from(i),
                vertex_count,
            });
        }
    }
    Ok(())
}

/// Initial capacity for `declared` items: the declared count, but at most [`MAX_PREALLOC`].
fn capacity(declared: u64) -> usize {
    // MAX_PREALLOC fits every usize of 32 bits or more.
    usize::try_from(declared.min(MAX_PREALLOC)).unwrap_or(0)
}

/// A position read from a file, or [`Error::NonFinite`] naming vertex `index`.
fn finite_point(x: f64, y: f64, z: f64, index: usize) -> Result<DVec3, Error> {
    let p = DVec3::new(x, y, z);
    if p.is_finite() {
        Ok(p)
    } else {
        Err(Error::NonFinite { vertex: index })
    }
}

/// Checks a 0-based index read from a file against the vertex count.
#[inline]
fn check_index(index: i64, face: usize, vertex_count: usize) -> Result<u32, Error> {
    match usize::try_from(index) {
        Ok(i) if i < vertex_count => u32::try_from(i).map_err(|_| Error::TooLarge {
            what: "vertex index".into(),
            count: i as u64,
        }),
        _ => Err(Error::IndexOutOfRange {
            face,
            index,
            vertex_count,
        }),
    }
}

/// Fan-triangulates one polygon as its vertices arrive: vertex k >= 2 adds the triangle
/// (v0, v(k-1), vk).
struct Fan {
    first: u32,
    prev: u32,
    len: u64,
}

impl Fan {
    fn new() -> Fan {
        Fan {
            first: 0,
            prev: 0,
            len: 0,
        }
    }

    #[inline]
    fn push(&mut self, v: u32, triangles: &mut Vec<[u32; 3]>) {
        match self.len {
            0 => self.first = v,
            1 => self.prev = v,
            _ => {
                triangles.push([self.first, self.prev, v]);
                self.prev = v;
            }
        }
        self.len += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fan_triangulates_in_order() {
        let mut tris = Vec::new();
        let mut fan = Fan::new();
        for v in [4, 5, 6, 7, 8] {
            fan.push(v, &mut tris);
        }
        assert_eq!(tris, vec![[4, 5, 6], [4, 6, 7], [4, 7, 8]]);
    }

    #[test]
    fn index_checks() {
        assert_eq!(check_index(2, 0, 3).unwrap(), 2);
        assert!(matches!(
            check_index(3, 7, 3),
            Err(Error::IndexOutOfRange {
                face: 7,
                index: 3,
                vertex_count: 3
            })
        ));
        assert!(matches!(
            check_index(-1, 0, 3),
            Err(Error::IndexOutOfRange { index: -1, .. })
        ));
    }

    #[test]
    fn writers_refuse_bad_meshes() {
        let bad = Mesh::new(vec![DVec3::new(f64::NAN, 0.0, 0.0)], vec![]);
        let mut out = Vec::new();
        let e = write(&mut out, &bad, Format::Off, &WriteOptions::DEFAULT).unwrap_err();
        assert!(matches!(e, Error::NonFinite { vertex: 0 }));
        let bad = Mesh::new(vec![DVec3::ZERO; 3], vec![[0, 1, 2], [0, 1, 3]]);
        let e = write(&mut out, &bad, Format::Ply, &WriteOptions::DEFAULT).unwrap_err();
        assert!(matches!(
            e,
            Error::IndexOutOfRange {
                face: 1,
                index: 3,
                ..
            }
        ));
        assert!(out.is_empty());
        let ok = Mesh::new(vec![DVec3::ZERO; 3], vec![[0, 1, 2]]);
        let e = write_ply_with_quality(&mut out, &ok, &[1.0], &[], PlyEncoding::Ascii);
        assert!(matches!(
            e,
            Err(Error::LengthMismatch {
                what: "quality",
                ..
            })
        ));
    }

    #[test]
    fn unknown_extension() {
        let e = read_path(Path::new("mesh.xyz"), None).unwrap_err();
        assert!(matches!(e, Error::UnknownFormat { .. }));
        assert!(e.is_input_error());
        let e = read_path(Path::new("/nonexistent/whet/mesh.off"), None).unwrap_err();
        assert!(matches!(e, Error::Io(_)));
        assert!(!e.is_input_error());
    }
}
