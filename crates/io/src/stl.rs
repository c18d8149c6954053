//! STL (stereolithography), ascii and binary.
//!
//! Reads: binary STL (80-byte header, `u32` little-endian triangle count, 50-byte records;
//! normals and attribute bytes ignored, data after the last record ignored) and ascii STL
//! (`solid` / `facet normal` / `outer loop` / `vertex x y z` / `endloop` / `endfacet` /
//! `endsolid`, keywords in any case, several solids in one file, facets of more than three
//! vertices fan-triangulated, normals ignored). A file whose first word is `solid` may still be
//! binary (many exporters write that header): when the file size is known it is binary exactly
//! when the size is `84 + 50 n` for the count `n` in bytes 80..84; for a stream of unknown size
//! it is binary when its first 84 bytes contain a control character (a binary count below
//! 2^24 always does), ascii otherwise.
//!
//! STL stores every triangle's corners separately; the reader welds vertices *exactly*:
//! corners with bit-identical coordinates (with `-0.0` equal to `0.0`) become one vertex, in
//! order of first appearance. Nothing else is merged.
//!
//! Does not read: colour or material conventions of the attribute bytes, ascii files without
//! `endsolid`.
//!
//! The read report ([`crate::ReadReport`]) lists the binary attribute bytes only when some are
//! not zero, as "STL attribute bytes" counting the facets whose two bytes are not both zero
//! (almost every exporter writes zeros, and some readers take non-zero ones for a colour).
//! Facet normals follow from the triangles and are not reported; nor is the 80-byte header.
//!
//! Writes ascii (coordinates in shortest round-trip form: exact for f64) or binary (f32:
//! coordinates round to the nearest f32, so a round trip is exact only for f32-representable
//! coordinates, and a coordinate beyond f32's range is refused). Facet normals are the unit
//! face normals (zero for a degenerate triangle).

use std::collections::HashMap;
use std::hash::Hash;
use std::io::{BufRead, ErrorKind, Read, Write};

use whet_mesh::{DVec3, Mesh};

use crate::binary::{array, ended, BinReader};
use crate::text::{parse_f64, show, tokens, write_point_line, LineReader};
use crate::{capacity, Error, Fan, ReadReport, Skipped, StlEncoding};

/// Size of the binary header plus count.
const HEAD: usize = 84;
/// Size of one binary triangle record.
const RECORD: u64 = 50;

/// Reads an STL file and reports what it skipped; `size` is the total file size when known
/// (it decides ascii vs binary for files that start with `solid`).
pub(crate) fn read<R: BufRead>(
    mut reader: R,
    size: Option<u64>,
) -> Result<(Mesh, ReadReport), Error> {
    let mut head = [0u8; HEAD];
    let got = read_up_to(&mut reader, &mut head)?;
    let head = &head[..got];
    if is_binary(head, size) {
        read_binary(BinReader::with_prefix(reader, head))
    } else {
        let mesh = read_ascii(LineReader::new(head.chain(reader)))?;
        Ok((mesh, ReadReport::default()))
    }
}

/// Fills `buf` as far as the input allows; the number of bytes read.
fn read_up_to<R: Read>(reader: &mut R, buf: &mut [u8]) -> Result<usize, Error> {
    let mut got = 0;
    while got < buf.len() {
        match reader.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(k) => got += k,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e.into()),
        }
    }
    Ok(got)
}

/// Decides the encoding from the first (up to) 84 bytes and the file size.
fn is_binary(head: &[u8], size: Option<u64>) -> bool {
    let text = head.trim_ascii_start();
    let solid = text.len() >= 5 && text[..5].eq_ignore_ascii_case(b"solid");
    if !solid {
        return true;
    }
    if head.len() < HEAD {
        return false;
    }
    let count = u32::from_le_bytes(array(&head[80..]));
    match size {
        Some(size) => size == HEAD as u64 + RECORD * u64::from(count),
        None => head
            .iter()
            .any(|&b| (b < 0x20 && !b.is_ascii_whitespace()) || b == 0x7f),
    }
}

/// Exact vertex welding: one vertex per distinct coordinate key, in order of first appearance.
struct Welder<K> {
    map: HashMap<K, u32>,
    positions: Vec<DVec3>,
}

impl<K: Hash + Eq> Welder<K> {
    fn new(corners: u64) -> Self {
        // A closed mesh has about half as many vertices as triangles, a sixth of its corners.
        // The map is kept smaller than `capacity` allows: unlike a vector's, its allocation is
        // initialised, and the count comes from an untrusted header.
        let vertices = capacity(corners / 6);
        Welder {
            map: HashMap::with_capacity(vertices.min(1 << 16)),
            positions: Vec::with_capacity(vertices),
        }
    }

    /// The index of the vertex at `p`, whose bits (zeros unified) are `key`.
    fn vertex(&mut self, key: K, p: DVec3) -> Result<u32, Error> {
        let next = self.positions.len();
        if !p.is_finite() {
            return Err(Error::NonFinite { vertex: next });
        }
        let next = u32::try_from(next).map_err(|_| Error::TooLarge {
            what: "STL vertex".into(),
            count: next as u64,
        })?;
        let index = *self.map.entry(key).or_insert(next);
        if index == next {
            self.positions.push(p);
        }
        Ok(index)
    }
}

/// Bits of an f32 with `-0.0` mapped to `0.0`.
fn key32(x: f32) -> u32 {
    if x == 0.0 {
        0
    } else {
        x.to_bits()
    }
}

/// Bits of an f64 with `-0.0` mapped to `0.0`.
fn key64(x: f64) -> u64 {
    if x == 0.0 {
        0
    } else {
        x.to_bits()
    }
}

fn read_binary<R: Read>(mut bin: BinReader<R>) -> Result<(Mesh, ReadReport), Error> {
    let head = bin.get(HEAD).map_err(|e| {
        if e.kind() == ErrorKind::UnexpectedEof {
            Error::truncated(
                "a binary STL starts with an 84-byte header and count; the file is shorter",
            )
        } else {
            Error::Io(e)
        }
    })?;
    let n = u32::from_le_bytes(array(&head[80..]));
    let n = u64::from(n);
    let mut weld = Welder::new(3 * n);
    let mut triangles = Vec::with_capacity(capacity(n));
    // Facets whose attribute bytes are not zero.
    let mut attributes: u64 = 0;
    for i in 0..n {
        let rec = bin
            .get(RECORD as usize)
            .map_err(|e| ended(e, n, "triangles", i))?;
        attributes += u64::from(rec[48] | rec[49] != 0);
        let mut t = [0; 3];
        for (k, corner) in t.iter_mut().enumerate() {
            let o = 12 + 12 * k;
            let c = [0, 4, 8].map(|d| f32::from_le_bytes(array(&rec[o + d..])));
            let p = DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2]));
            *corner = weld.vertex(c.map(key32), p)?;
        }
        triangles.push(t);
    }
    let mut report = ReadReport::default();
    report.push(Skipped::of(
        "STL attribute bytes".to_owned(),
        attributes,
        "non-zero on ",
        "facet",
        "facets",
    ));
    Ok((Mesh::new(weld.positions, triangles), report))
}

fn read_ascii<R: BufRead>(mut lines: LineReader<R>) -> Result<Mesh, Error> {
    let mut weld = Welder::new(0);
    let mut triangles = Vec::new();
    let mut seen_solid = false;
    let mut in_solid = false;
    let mut fan: Option<Fan> = None;
    let mut facets = 0usize;
    while lines.advance()? {
        let line_no = lines.line();
        let mut toks = tokens(lines.current());
        let Some(keyword) = toks.next() else { continue };
        let kw = keyword.to_ascii_lowercase();
        let misplaced = || {
            Error::parse(
                line_no,
                format!("'{}' is out of place in an ascii STL", show(keyword)),
            )
        };
        match kw.as_slice() {
            b"solid" => {
                if in_solid {
                    return Err(misplaced());
                }
                in_solid = true;
                seen_solid = true;
            }
            b"facet" => {
                if !in_solid || fan.is_some() {
                    return Err(misplaced());
                }
                fan = Some(Fan::new());
            }
            b"outer" | b"endloop" => {
                if fan.is_none() {
                    return Err(misplaced());
                }
            }
            b"vertex" => {
                let Some(fan) = fan.as_mut() else {
                    return Err(misplaced());
                };
                let mut xyz = [0.0; 3];
                for (k, c) in xyz.iter_mut().enumerate() {
                    let tok = toks.next().ok_or_else(|| {
                        Error::parse(line_no, format!("vertex has {k} coordinates; 3 are needed"))
                    })?;
                    *c = parse_f64(tok).ok_or_else(|| {
                        Error::parse(line_no, format!("invalid coordinate '{}'", show(tok)))
                    })?;
                }
                let p = DVec3::from_array(xyz);
                let index = weld.vertex(xyz.map(key64), p)?;
                fan.push(index, &mut triangles);
            }
            b"endfacet" => {
                let Some(done) = fan.take() else {
                    return Err(misplaced());
                };
                if done.len < 3 {
                    return Err(Error::parse(
                        line_no,
                        format!(
                            "facet {facets} has {} vertices; at least 3 are needed",
                            done.len
                        ),
                    ));
                }
                facets += 1;
            }
            b"endsolid" => {
                if !in_solid || fan.is_some() {
                    return Err(misplaced());
                }
                in_solid = false;
            }
            _ => {
                return Err(Error::parse(
                    line_no,
                    format!("unexpected '{}' in an ascii STL", show(keyword)),
                ))
            }
        }
    }
    if fan.is_some() {
        return Err(Error::truncated(format!(
            "ascii STL ended inside facet {facets}"
        )));
    }
    if in_solid || !seen_solid {
        return Err(Error::truncated(format!(
            "ascii STL ended without 'endsolid' after {facets} facets"
        )));
    }
    Ok(Mesh::new(weld.positions, triangles))
}

/// Unit normal of a triangle, zero when it is degenerate.
fn normal(mesh: &Mesh, t: &[u32; 3]) -> DVec3 {
    let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
    (b - a).cross(c - a).normalize_or_zero()
}

/// Writes `mesh` as STL (the caller has checked its indices and coordinates).
pub(crate) fn write<W: Write>(w: &mut W, mesh: &Mesh, encoding: StlEncoding) -> Result<(), Error> {
    match encoding {
        StlEncoding::Ascii => write_ascii(w, mesh)?,
        StlEncoding::Binary => write_binary(w, mesh)?,
    }
    Ok(())
}

fn write_ascii<W: Write>(w: &mut W, mesh: &Mesh) -> std::io::Result<()> {
    writeln!(w, "solid whet")?;
    for t in &mesh.triangles {
        write_point_line(w, b"  facet normal", normal(mesh, t))?;
        w.write_all(b"    outer loop\n")?;
        for &i in t {
            write_point_line(w, b"      vertex", mesh.positions[i as usize])?;
        }
        w.write_all(b"    endloop\n  endfacet\n")?;
    }
    writeln!(w, "endsolid whet")
}

fn write_binary<W: Write>(w: &mut W, mesh: &Mesh) -> Result<(), Error> {
    let count = u32::try_from(mesh.triangles.len()).map_err(|_| Error::TooLarge {
        what: "STL triangle".into(),
        count: mesh.triangles.len() as u64,
    })?;
    if let Some(vertex) = mesh.positions.iter().position(|p| !p.as_vec3().is_finite()) {
        return Err(Error::unsupported(format!(
            "vertex {vertex} at {} does not fit binary STL's f32 coordinates",
            mesh.positions[vertex]
        )));
    }
    let mut head = [0u8; HEAD];
    let title = b"binary STL written by whet";
    head[..title.len()].copy_from_slice(title);
    head[80..].copy_from_slice(&count.to_le_bytes());
    w.write_all(&head)?;
    let mut rec = [0u8; RECORD as usize];
    for t in &mesh.triangles {
        let n = normal(mesh, t);
        let points = [
            n,
            mesh.positions[t[0] as usize],
            mesh.positions[t[1] as usize],
            mesh.positions[t[2] as usize],
        ];
        for (k, p) in points.iter().enumerate() {
            for (d, c) in p.as_vec3().to_array().iter().enumerate() {
                let o = 12 * k + 4 * d;
                rec[o..o + 4].copy_from_slice(&c.to_le_bytes());
            }
        }
        w.write_all(&rec)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read<R: BufRead>(reader: R, size: Option<u64>) -> Result<Mesh, Error> {
        super::read(reader, size).map(|(mesh, _)| mesh)
    }

    fn f32_mesh() -> Mesh {
        Mesh::new(
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.25, 0.5, f64::from(0.1f32)),
            ],
            // Vertices in order of first appearance, as welding numbers them.
            vec![[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]],
        )
    }

    #[test]
    fn round_trip_both_encodings() {
        let m = f32_mesh();
        for enc in [StlEncoding::Ascii, StlEncoding::Binary] {
            let mut out = Vec::new();
            write(&mut out, &m, enc).unwrap();
            let size = out.len() as u64;
            assert_eq!(read(&out[..], None).unwrap(), m, "{enc:?}");
            assert_eq!(read(&out[..], Some(size)).unwrap(), m, "{enc:?}");
        }
    }

    #[test]
    fn report_counts_facets_with_non_zero_attribute_bytes() {
        let m = f32_mesh();
        let mut out = Vec::new();
        write(&mut out, &m, StlEncoding::Binary).unwrap();
        let size = Some(out.len() as u64);
        // whet writes zeros: nothing to report.
        let (back, report) = super::read(&out[..], size).unwrap();
        assert_eq!(back, m);
        assert!(report.is_empty(), "{report:?}");
        // A colour in the attribute bytes of facets 1 and 3 (low byte, then high byte only).
        let attr = |facet: usize| HEAD + RECORD as usize * facet + 48;
        out[attr(1)] = 0x1f;
        out[attr(3) + 1] = 0x80;
        for size in [size, None] {
            let (back, report) = super::read(&out[..], size).unwrap();
            assert_eq!(back, m);
            assert_eq!(report.pairs(), vec![("STL attribute bytes", 2)]);
            assert_eq!(
                report.to_string(),
                "STL attribute bytes (non-zero on 2 facets)"
            );
        }
        // Ascii STL has no attribute bytes, and its facet normals are not reported.
        let mut text = Vec::new();
        write(&mut text, &m, StlEncoding::Ascii).unwrap();
        assert!(super::read(&text[..], None).unwrap().1.is_empty());
    }

    #[test]
    fn ascii_is_exact_for_f64() {
        let mut m = f32_mesh();
        m.positions[3] = DVec3::new(0.1, 1.0 / 3.0, 1e-300);
        let mut out = Vec::new();
        write(&mut out, &m, StlEncoding::Ascii).unwrap();
        assert_eq!(read(&out[..], None).unwrap(), m);
    }

    #[test]
    fn binary_refuses_coordinates_beyond_f32() {
        let mut m = f32_mesh();
        m.positions[1].x = 1e300;
        let e = write(&mut Vec::new(), &m, StlEncoding::Binary).unwrap_err();
        assert!(matches!(e, Error::Unsupported { .. }), "{e}");
    }

    #[test]
    fn welding_unifies_signed_zeros_only() {
        let text = "solid t\nfacet normal 0 0 1\nouter loop\n\
                    vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n\
                    facet normal 0 0 1\nouter loop\n\
                    vertex -0 0 0.0\nvertex 1 0 0\nvertex 1.0000000000000002 1 0\n\
                    endloop\nendfacet\nendsolid t\n";
        let m = read(text.as_bytes(), None).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 1, 3]]);
    }

    #[test]
    fn binary_header_starting_with_solid() {
        let m = f32_mesh();
        let mut out = Vec::new();
        write(&mut out, &m, StlEncoding::Binary).unwrap();
        out[..8].copy_from_slice(b"solid ab");
        assert_eq!(read(&out[..], None).unwrap(), m);
        assert_eq!(read(&out[..], Some(out.len() as u64)).unwrap(), m);
        // With the header all text and a size that does not match, the size decides ascii.
        for b in &mut out[8..80] {
            *b = b' ';
        }
        assert_eq!(read(&out[..], Some(out.len() as u64)).unwrap(), m);
        assert!(read(&out[..], Some(out.len() as u64 + 1)).is_err());
    }

    #[test]
    fn quads_and_case() {
        let text =
            "SOLID\nFACET NORMAL 0 0 1\nOUTER LOOP\nVERTEX 0 0 0\nVERTEX 1 0 0\nVERTEX 1 1 0\n\
                    VERTEX 0 1 0\nENDLOOP\nENDFACET\nENDSOLID\nsolid second\nendsolid\n";
        let m = read(text.as_bytes(), None).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn errors() {
        let e = read(&b"solid x\nvertex 0 0 0\n"[..], None).unwrap_err();
        assert!(matches!(e, Error::Parse { line: 2, .. }), "{e}");
        let e = read(&b"solid x\nfacet\nouter loop\nvertex 0 0 nan\n"[..], None).unwrap_err();
        assert!(matches!(e, Error::NonFinite { vertex: 0 }), "{e}");
        let e = read(
            &b"solid x\nfacet\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nendloop\nendfacet\n"[..],
            None,
        )
        .unwrap_err();
        assert!(matches!(e, Error::Parse { line: 7, .. }), "{e}");
        let e = read(&b"solid x\nfacet\nouter loop\nvertex 0 0 0\n"[..], None).unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }), "{e}");
        let e = read(&b"solid x\n"[..], None).unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }), "{e}");
        let e = read(&b""[..], None).unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }), "{e}");
        let e = read(&[1u8; 30][..], None).unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }), "{e}");
        let mut bin = vec![0u8; 84];
        bin[80..].copy_from_slice(&u32::MAX.to_le_bytes());
        bin.extend_from_slice(&[0; 10]);
        let e = read(&bin[..], None).unwrap_err();
        assert!(
            matches!(&e, Error::Truncated { what } if what.contains("4294967295 triangles")),
            "{e}"
        );
    }
}
