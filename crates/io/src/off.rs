//! OFF (Object File Format), text only.
//!
//! Reads: an `OFF` keyword line, optionally with `C`, `N` and `ST` prefixes (`COFF`, `NOFF`,
//! `STOFF`, `CNOFF`...; the extra per-vertex values are ignored), with the `V F E` counts on the
//! same line or on the next one (`E` may be missing and is ignored); `#` comments and blank
//! lines anywhere; one vertex per line (`x y z` and any extra columns, ignored); one face per
//! line (`n i0 ... i(n-1)` with 0-based indices, any trailing colour values ignored). Polygons
//! are fan-triangulated. Anything after the last face is ignored.
//!
//! Does not read: binary OFF (`OFF BINARY`), 4D and n-dimensional OFF (`4OFF`, `nOFF`),
//! vertices or faces split across several lines.
//!
//! The read report ([`crate::ReadReport`]) counts, in this order: vertex normals (`N` prefix),
//! vertex colours (`C`) and texture coordinates (`ST`), each as the vertices whose line has
//! columns after `x y z` when the keyword has that prefix; extra vertex values (the vertices
//! with columns after `x y z` when the keyword has no prefix); face colours (the faces with
//! values after their indices).
//!
//! Writes plain `OFF` with coordinates in shortest round-trip form, so a written mesh reads
//! back bit for bit.

use std::io::{BufRead, Write};

use whet_mesh::{DVec3, Mesh};

use crate::text::{
    parse_f64, parse_i64, show, strip_comment, tokens, write_face_line, write_point_line,
    LineReader,
};
use crate::{capacity, check_index, finite_point, Error, Fan, ReadReport, Skipped};

/// The prefixes of the OFF keyword that announce per-vertex values after `x y z`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Prefixes {
    /// `ST`: texture coordinates.
    st: bool,
    /// `C`: colours.
    c: bool,
    /// `N`: normals.
    n: bool,
}

/// Reads an OFF file and reports what it skipped.
pub(crate) fn read<R: BufRead>(reader: R) -> Result<(Mesh, ReadReport), Error> {
    let mut lines = LineReader::new(reader);
    let (vertex_count, face_count, prefixes) = read_header(&mut lines)?;
    // Vertices with columns after `x y z`, and faces with values after their indices.
    let mut extra_vertices: u64 = 0;
    let mut extra_faces: u64 = 0;

    let mut positions = Vec::with_capacity(capacity(vertex_count));
    while (positions.len() as u64) < vertex_count {
        if !lines.advance()? {
            return Err(Error::truncated(format!(
                "expected {vertex_count} vertices, file ended after {}",
                positions.len()
            )));
        }
        let index = positions.len();
        if let Some((p, extra)) = parse_vertex(lines.current(), lines.line(), index)? {
            positions.push(p);
            extra_vertices += u64::from(extra);
        }
    }

    let vertex_total = positions.len();
    let mut triangles = Vec::with_capacity(capacity(face_count));
    let mut face: u64 = 0;
    while face < face_count {
        if !lines.advance()? {
            return Err(Error::truncated(format!(
                "expected {face_count} faces, file ended after {face}"
            )));
        }
        // face < face_count <= u32::MAX, so it fits usize.
        let face_index = face as usize;
        if let Some(extra) = parse_face(
            lines.current(),
            lines.line(),
            face_index,
            vertex_total,
            &mut triangles,
        )? {
            face += 1;
            extra_faces += u64::from(extra);
        }
    }
    let report = report(prefixes, extra_vertices, extra_faces);
    Ok((Mesh::new(positions, triangles), report))
}

/// What the reader skipped: `extra_vertices` vertices with columns after `x y z`, whose
/// meaning `prefixes` tells, and `extra_faces` faces with values after their indices.
fn report(prefixes: Prefixes, extra_vertices: u64, extra_faces: u64) -> ReadReport {
    let mut r = ReadReport::default();
    let announced = |flag: bool| if flag { extra_vertices } else { 0 };
    r.push(Skipped::items(
        "vertex normals",
        "vertex normal",
        announced(prefixes.n),
    ));
    r.push(Skipped::items(
        "vertex colours",
        "vertex colour",
        announced(prefixes.c),
    ));
    r.push(Skipped::items(
        "texture coordinates",
        "texture coordinate",
        announced(prefixes.st),
    ));
    let unnamed = if prefixes == Prefixes::default() {
        extra_vertices
    } else {
        0
    };
    r.push(Skipped::of(
        "extra vertex values".to_owned(),
        unnamed,
        "on ",
        "vertex",
        "vertices",
    ));
    r.push(Skipped::items("face colours", "face colour", extra_faces));
    r
}

/// Parses the vertex line `line` into the position and whether columns follow `x y z`; `None`
/// for a blank or comment line.
fn parse_vertex(line: &[u8], line_no: usize, index: usize) -> Result<Option<(DVec3, bool)>, Error> {
    let mut toks = tokens(strip_comment(line));
    let Some(first) = toks.next() else {
        return Ok(None);
    };
    let mut xyz = [0.0; 3];
    for (k, tok) in [Some(first), toks.next(), toks.next()]
        .into_iter()
        .enumerate()
    {
        let Some(tok) = tok else {
            return Err(Error::parse(
                line_no,
                format!("vertex {index} has {k} coordinates; 3 are needed"),
            ));
        };
        xyz[k] = parse_f64(tok).ok_or_else(|| {
            Error::parse(
                line_no,
                format!("invalid coordinate '{}' in vertex {index}", show(tok)),
            )
        })?;
    }
    let extra = toks.next().is_some();
    finite_point(xyz[0], xyz[1], xyz[2], index).map(|p| Some((p, extra)))
}

/// Parses the face line `line` into `triangles`, and whether values (a colour) follow the
/// indices; `None` for a blank or comment line.
fn parse_face(
    line: &[u8],
    line_no: usize,
    face: usize,
    vertex_count: usize,
    triangles: &mut Vec<[u32; 3]>,
) -> Result<Option<bool>, Error> {
    let mut toks = tokens(strip_comment(line));
    let Some(count_tok) = toks.next() else {
        return Ok(None);
    };
    let n = match parse_i64(count_tok) {
        Some(n) if n >= 3 => n,
        Some(n) => {
            return Err(Error::parse(
                line_no,
                format!("face {face} has {n} vertices; at least 3 are needed"),
            ))
        }
        None => {
            return Err(Error::parse(
                line_no,
                format!("invalid vertex count '{}' in face {face}", show(count_tok)),
            ))
        }
    };
    let mut fan = Fan::new();
    for k in 0..n {
        let Some(tok) = toks.next() else {
            return Err(Error::parse(
                line_no,
                format!("face {face} declares {n} vertices but lists {k}"),
            ));
        };
        let index = parse_i64(tok).ok_or_else(|| {
            Error::parse(
                line_no,
                format!("invalid vertex index '{}' in face {face}", show(tok)),
            )
        })?;
        fan.push(check_index(index, face, vertex_count)?, triangles);
    }
    Ok(Some(toks.next().is_some()))
}

/// Reads the keyword and the vertex and face counts.
fn read_header<R: BufRead>(lines: &mut LineReader<R>) -> Result<(u64, u64, Prefixes), Error> {
    let mut seen_keyword = false;
    let mut prefixes = Prefixes::default();
    let mut counts: Vec<u64> = Vec::with_capacity(3);
    loop {
        if !lines.advance()? {
            return Err(Error::truncated(if seen_keyword {
                "the OFF header has no vertex and face counts"
            } else {
                "the file is empty: expected an OFF header"
            }));
        }
        let line_no = lines.line();
        let mut toks = tokens(strip_comment(lines.current()));
        if !seen_keyword {
            let Some(keyword) = toks.next() else { continue };
            prefixes = check_keyword(keyword, line_no)?;
            seen_keyword = true;
        }
        for tok in toks {
            if tok.eq_ignore_ascii_case(b"BINARY") {
                return Err(Error::unsupported("binary OFF"));
            }
            if counts.len() == 3 {
                break;
            }
            let what = ["vertex", "face", "edge"][counts.len()];
            let count = parse_i64(tok)
                .and_then(|c| u64::try_from(c).ok())
                .ok_or_else(|| {
                    Error::parse(line_no, format!("invalid {what} count '{}'", show(tok)))
                })?;
            if count > u64::from(u32::MAX) && counts.len() < 2 {
                return Err(Error::TooLarge {
                    what: format!("OFF {what}"),
                    count,
                });
            }
            counts.push(count);
        }
        if counts.len() >= 2 {
            return Ok((counts[0], counts[1], prefixes));
        }
    }
}

/// Accepts `OFF` with the optional `ST`, `C`, `N` prefixes, and returns them; refuses `4OFF`
/// and `nOFF`.
fn check_keyword(keyword: &[u8], line: usize) -> Result<Prefixes, Error> {
    let not_off = || {
        Error::parse(
            line,
            format!("not an OFF file: expected 'OFF', found '{}'", show(keyword)),
        )
    };
    let split = keyword.len().checked_sub(3).ok_or_else(not_off)?;
    let (prefix, suffix) = keyword.split_at(split);
    if !suffix.eq_ignore_ascii_case(b"OFF") {
        return Err(not_off());
    }
    if prefix.contains(&b'4') || prefix.contains(&b'n') {
        return Err(Error::unsupported(format!(
            "'{}' (4D or n-dimensional OFF)",
            show(keyword)
        )));
    }
    // The prefixes in any order, each at most once (MeshLab writes `NCOFF`).
    let mut rest = prefix;
    let mut seen = [false; 3];
    loop {
        let before = rest.len();
        for (i, p) in [&b"ST"[..], b"C", b"N"].iter().enumerate() {
            if !seen[i] {
                if let Some(r) = rest.strip_prefix(*p) {
                    rest = r;
                    seen[i] = true;
                }
            }
        }
        if rest.len() == before {
            break;
        }
    }
    if rest.is_empty() {
        let [st, c, n] = seen;
        Ok(Prefixes { st, c, n })
    } else {
        Err(not_off())
    }
}

/// Writes `mesh` as plain OFF.
pub(crate) fn write<W: Write>(w: &mut W, mesh: &Mesh) -> std::io::Result<()> {
    writeln!(w, "OFF")?;
    writeln!(w, "{} {} 0", mesh.positions.len(), mesh.triangles.len())?;
    for &p in &mesh.positions {
        write_point_line(w, b"", p)?;
    }
    for t in &mesh.triangles {
        write_face_line(w, b"3", t.map(u64::from))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read<R: BufRead>(reader: R) -> Result<Mesh, Error> {
        super::read(reader).map(|(mesh, _)| mesh)
    }

    fn read_str(s: &str) -> Result<Mesh, Error> {
        read(s.as_bytes())
    }

    fn report_of(s: &str) -> ReadReport {
        super::read(s.as_bytes()).unwrap().1
    }

    #[test]
    fn report_names_what_the_prefixes_announce() {
        // COFF: RGBA per vertex (one vertex without), RGB per face (one face without).
        let coff = "COFF\n4 2 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n\
                    1 1 0 0 0 255 255 # blue\n0 1 0\n\
                    3 0 1 2 255 255 255\n3 0 2 3\n";
        let r = report_of(coff);
        assert_eq!(r.pairs(), vec![("vertex colours", 3), ("face colours", 1)]);
        assert_eq!(r.to_string(), "3 vertex colours and 1 face colour");
        // NOFF on the keyword line with the counts, comments between the vertices.
        let noff = "NOFF 3 1 0\n0 0 0 0 0 1\n# normal up\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n";
        let r = report_of(noff);
        assert_eq!(r.pairs(), vec![("vertex normals", 3)]);
        assert_eq!(r.to_string(), "3 vertex normals");
        // STCNOFF names every kind for each vertex with extra columns.
        let stcnoff = "STCNOFF\n3 1 0\n0 0 0 0 0 1 1 0 0 1 0 0\n\
                       1 0 0 0 0 1 0 1 0 1 1 0\n0 1 0 0 0 1 0 0 1 1 0 1\n3 0 1 2\n";
        assert_eq!(
            report_of(stcnoff).pairs(),
            vec![
                ("vertex normals", 3),
                ("vertex colours", 3),
                ("texture coordinates", 3),
            ]
        );
        // Plain OFF with stray columns: values the file does not name.
        let r = report_of("OFF\n3 1 0\n0 0 0 7\n1 0 0\n0 1 0\n3 0 1 2\n");
        assert_eq!(r.pairs(), vec![("extra vertex values", 1)]);
        assert_eq!(r.to_string(), "extra vertex values (on 1 vertex)");
        // A prefix whose values are missing, and comments after the data, skip nothing.
        assert!(report_of("COFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0 # c\n3 0 1 2 # c\n").is_empty());
    }

    #[test]
    fn plain_cube_quads() {
        let m = read_str(
            "OFF\n8 6 12\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n\
             4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n",
        )
        .unwrap();
        assert_eq!(m.positions.len(), 8);
        assert_eq!(m.triangles.len(), 12);
        assert_eq!(m.triangles[0], [0, 3, 2]);
        assert_eq!(m.triangles[1], [0, 2, 1]);
    }

    #[test]
    fn counts_on_keyword_line_comments_and_colours() {
        let m = read_str(
            "# leading comment\nCOFF 3 1 0 # counts here\n\n# between\n\
             0 0 0 255 0 0 255\n1 0 0 0 255 0 255 # red\n0 1 0 0 0 255 255\n\
             3 0 1 2 0.5 0.5 0.5\n",
        )
        .unwrap();
        assert_eq!(m.positions[1], DVec3::X);
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn keyword_variants() {
        for kw in [
            "OFF", "COFF", "NOFF", "CNOFF", "NCOFF", "STOFF", "STCNOFF", "NSTOFF", "off",
        ] {
            assert!(check_keyword(kw.as_bytes(), 1).is_ok(), "{kw}");
        }
        assert_eq!(
            check_keyword(b"NCOFF", 1).unwrap(),
            Prefixes {
                st: false,
                c: true,
                n: true
            }
        );
        assert_eq!(check_keyword(b"OFF", 1).unwrap(), Prefixes::default());
        assert!(matches!(
            check_keyword(b"4OFF", 1),
            Err(Error::Unsupported { .. })
        ));
        assert!(matches!(
            check_keyword(b"nOFF", 1),
            Err(Error::Unsupported { .. })
        ));
        assert!(matches!(
            check_keyword(b"PLY", 3),
            Err(Error::Parse { line: 3, .. })
        ));
        assert!(matches!(
            read_str("OFF BINARY\n"),
            Err(Error::Unsupported { .. })
        ));
    }

    #[test]
    fn errors_name_the_line() {
        let e = read_str("OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n").unwrap_err();
        assert!(
            matches!(&e, Error::Parse { line: 4, message } if message.contains("vertex 1")),
            "{e}"
        );
        let e = read_str("OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n").unwrap_err();
        assert!(matches!(e, Error::Parse { line: 4, .. }), "{e}");
        let e = read_str("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n").unwrap_err();
        assert!(matches!(e, Error::Parse { line: 6, .. }), "{e}");
        let e = read_str("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n").unwrap_err();
        assert!(matches!(e, Error::Parse { line: 6, .. }), "{e}");
        let e = read_str("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n").unwrap_err();
        assert!(matches!(
            e,
            Error::IndexOutOfRange {
                face: 0,
                index: 3,
                vertex_count: 3
            }
        ));
        let e = read_str("OFF\n3 1 0\n0 0 0\nnan 0 0\n").unwrap_err();
        assert!(matches!(e, Error::NonFinite { vertex: 1 }));
        let e = read_str("OFF\n3 1 0\n0 0 0\n1e999 0 0\n").unwrap_err();
        assert!(matches!(e, Error::NonFinite { vertex: 1 }));
    }

    #[test]
    fn truncation_and_absurd_counts() {
        let e = read_str("OFF\n6475 12946 0\n0 0 0\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "file is truncated: expected 6475 vertices, file ended after 1"
        );
        let e = read_str("OFF\n1000000000000 1 0\n0 0 0\n").unwrap_err();
        assert!(matches!(e, Error::TooLarge { .. }));
        let e = read_str("OFF\n4000000000 4000000000 0\n0 0 0\n").unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }));
        let e = read_str("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n").unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }));
        assert!(matches!(read_str(""), Err(Error::Truncated { .. })));
        assert!(matches!(read_str("OFF\n"), Err(Error::Truncated { .. })));
        assert!(matches!(
            read_str("OFF\n-1 2 0\n"),
            Err(Error::Parse { .. })
        ));
    }

    #[test]
    fn write_then_read_is_exact() {
        let m = Mesh::new(
            vec![
                DVec3::new(0.1, -0.0, 1e-300),
                DVec3::new(1.0 / 3.0, 2e20, -7.25),
                DVec3::new(f64::MIN_POSITIVE, 5e-324, 123456.789),
            ],
            vec![[0, 1, 2], [2, 1, 0]],
        );
        let mut out = Vec::new();
        write(&mut out, &m).unwrap();
        let back = read(&out[..]).unwrap();
        assert_eq!(back.triangles, m.triangles);
        for (a, b) in back.positions.iter().zip(&m.positions) {
            assert_eq!(
                a.to_array().map(f64::to_bits),
                b.to_array().map(f64::to_bits)
            );
        }
    }
}
