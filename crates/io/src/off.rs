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
//! The body is read in blocks of lines parsed in parallel ([`read`]), with the result and
//! errors of a reading line by line.
//!
//! Writes plain `OFF` with coordinates in shortest round-trip form, so a written mesh reads
//! back bit for bit.

use std::io::{BufRead, Write};

use whet_mesh::{DVec3, Mesh};

use rayon::prelude::*;

use crate::text::{
    holds_data, line_spans, parse_f64, parse_i64, pieces, plain_point, show, strip_comment, tokens,
    write_face_line, write_point_line, Chunking, LineBlocks, LineReader,
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
///
/// The header is read line by line; the body in blocks of lines ([`LineBlocks`]) cut into
/// pieces that are parsed in parallel ([`Chunking::DEFAULT`]): parsing (float and integer
/// conversion) is most of the time of reading a large OFF file. The result, errors
/// included, is the one a reading line by line gives: the first error in file order, and
/// nothing read after the last face.
pub(crate) fn read<R: BufRead>(reader: R) -> Result<(Mesh, ReadReport), Error> {
    read_chunked(reader, &Chunking::DEFAULT)
}

/// [`read`] with the blocks and pieces of `chunking` (the tests' small ones give the same
/// result as the default).
pub(crate) fn read_chunked<R: BufRead>(
    reader: R,
    chunking: &Chunking,
) -> Result<(Mesh, ReadReport), Error> {
    let mut lines = LineReader::with_max_len(reader, chunking.max_line);
    let (vertex_count, face_count, prefixes) = read_header(&mut lines)?;
    let first_line = lines.line() + 1;
    let mut blocks = LineBlocks::new(lines.into_inner(), chunking, false);
    let mut body = Body {
        vertex_count,
        face_count,
        positions: Vec::with_capacity(capacity(vertex_count)),
        triangles: Vec::with_capacity(capacity(face_count)),
        faces: 0,
        next_line: first_line,
        extra_vertices: 0,
        extra_faces: 0,
        piece_triangles: Vec::new(),
    };
    while body.lines_wanted() > 0 {
        let Some(block) = blocks.next_block(body.next_line)? else {
            return Err(body.truncated());
        };
        body.parse_block(block, chunking)?;
    }
    let report = report(prefixes, body.extra_vertices, body.extra_faces);
    Ok((Mesh::new(body.positions, body.triangles), report))
}

/// The body of an OFF file as its blocks are parsed.
struct Body {
    vertex_count: u64,
    face_count: u64,
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    /// Face lines read.
    faces: u64,
    /// Number of the next block's first line.
    next_line: usize,
    /// Vertices with columns after `x y z`, and faces with values after their indices.
    extra_vertices: u64,
    extra_faces: u64,
    /// Each piece's triangles, kept from block to block.
    piece_triangles: Vec<Vec<[u32; 3]>>,
}

/// What a first pass over a piece of a block found: its lines and data lines, up to the
/// first line longer than the limit if there is one (its index in the piece).
struct PieceCount {
    lines: usize,
    data: u64,
    too_long: Option<usize>,
}

/// A piece of a block to parse: its byte range, the number of its first line, and the
/// index among the data lines the block's reading still wants of its first data line.
struct PiecePlan {
    range: std::ops::Range<usize>,
    first_line: usize,
    first_data: u64,
}

impl Body {
    /// Data lines still to read: vertices, then faces.
    fn lines_wanted(&self) -> u64 {
        (self.vertex_count - self.positions.len() as u64) + (self.face_count - self.faces)
    }

    /// The error of an input that ends before its vertices and faces.
    fn truncated(&self) -> Error {
        if (self.positions.len() as u64) < self.vertex_count {
            Error::truncated(format!(
                "expected {} vertices, file ended after {}",
                self.vertex_count,
                self.positions.len()
            ))
        } else {
            Error::truncated(format!(
                "expected {} faces, file ended after {}",
                self.face_count, self.faces
            ))
        }
    }

    /// Parses the lines of `block` (whole lines, the first numbered `next_line`) that the
    /// body still wants: its pieces are counted in parallel, placed in order, then parsed
    /// in parallel.
    fn parse_block(&mut self, block: &[u8], chunking: &Chunking) -> Result<(), Error> {
        let max_line = chunking.max_line;
        let pieces = pieces(block, chunking.piece, false);
        let counts: Vec<PieceCount> = pieces
            .par_iter()
            .map(|range| count_piece(&block[range.clone()], max_line))
            .collect();
        // Place the pieces: the lines of those past the last wanted data line are not
        // read, nor those past a line too long that a reading line by line would reach.
        let wanted = self.lines_wanted();
        let vertices_wanted = self.vertex_count - self.positions.len() as u64;
        let mut plans = Vec::new();
        let (mut line, mut data) = (self.next_line, 0);
        let mut too_long = None;
        for (range, count) in pieces.into_iter().zip(&counts) {
            if data >= wanted {
                break;
            }
            plans.push(PiecePlan {
                range,
                first_line: line,
                first_data: data,
            });
            data += count.data;
            if let (Some(k), true) = (count.too_long, data < wanted) {
                too_long = Some(line + k);
                break;
            }
            line += count.lines;
        }
        // Past the block's lines, unless the reading ends in it.
        self.next_line = line;
        let read = data.min(wanted);
        // Both below a block's line count, so they fit usize.
        let vertices = read.min(vertices_wanted);
        let base = self.positions.len();
        self.positions.resize(base + vertices as usize, DVec3::ZERO);
        let mut slots = Vec::with_capacity(plans.len());
        let mut rest = &mut self.positions[base..];
        for (plan, count) in plans.iter().zip(&counts) {
            let end = (plan.first_data + count.data).min(vertices_wanted);
            let n = end.saturating_sub(plan.first_data.min(vertices_wanted)) as usize;
            let whole = std::mem::take(&mut rest);
            let (slot, tail) = whole.split_at_mut(n.min(whole.len()));
            slots.push(slot);
            rest = tail;
        }
        if self.piece_triangles.len() < plans.len() {
            self.piece_triangles.resize_with(plans.len(), Vec::new);
        }
        let piece = PieceParse {
            block,
            wanted,
            vertices_wanted,
            first_vertex: base,
            first_face: self.faces,
            vertex_count: self.vertex_count,
            max_line,
        };
        let results: Vec<Result<(u64, u64), Error>> = plans
            .par_iter()
            .zip(slots)
            .zip(&mut self.piece_triangles)
            .map(|((plan, slot), triangles)| piece.parse(plan, slot, triangles))
            .collect();
        for (result, triangles) in results.into_iter().zip(&self.piece_triangles) {
            let (extra_vertices, extra_faces) = result?;
            self.extra_vertices += extra_vertices;
            self.extra_faces += extra_faces;
            self.triangles.extend_from_slice(triangles);
        }
        self.faces += read - vertices;
        match too_long {
            Some(line) => Err(Error::parse(
                line,
                format!("line is longer than {max_line} bytes"),
            )),
            None => Ok(()),
        }
    }
}

/// A first pass over a piece: its lines and data lines, stopping at a line longer than
/// `max_line` bytes.
fn count_piece(text: &[u8], max_line: usize) -> PieceCount {
    let mut count = PieceCount {
        lines: 0,
        data: 0,
        too_long: None,
    };
    for span in line_spans(text) {
        if span.len() > max_line {
            count.too_long = Some(count.lines);
            break;
        }
        count.data += u64::from(holds_data(&text[span]));
        count.lines += 1;
    }
    count
}

/// What the pieces of one block share: the block, and where its data lines go.
struct PieceParse<'a> {
    block: &'a [u8],
    /// Data lines the body wanted before the block, of which the first `vertices_wanted`
    /// are vertices.
    wanted: u64,
    vertices_wanted: u64,
    /// The indices of the block's first vertex and first face.
    first_vertex: usize,
    first_face: u64,
    /// The file's vertex count, which bounds face indices.
    vertex_count: u64,
    max_line: usize,
}

impl PieceParse<'_> {
    /// Parses the wanted data lines of `plan`'s piece: vertices into `slot` (the piece's
    /// share of the block's new positions), faces onto `triangles` (cleared first); the
    /// count of vertices and faces with extra values.
    fn parse(
        &self,
        plan: &PiecePlan,
        slot: &mut [DVec3],
        triangles: &mut Vec<[u32; 3]>,
    ) -> Result<(u64, u64), Error> {
        triangles.clear();
        let text = &self.block[plan.range.clone()];
        let (mut extra_vertices, mut extra_faces) = (0, 0);
        let mut data = plan.first_data;
        for (k, span) in line_spans(text).enumerate() {
            if data >= self.wanted || span.len() > self.max_line {
                // The end of what is wanted, or a line too long, which the caller reports.
                break;
            }
            let line = &text[span];
            if !holds_data(line) {
                continue;
            }
            let line_no = plan.first_line + k;
            // Indices below the counts of the header, which fit u32 and so usize.
            if data < self.vertices_wanted {
                let index = self.first_vertex + data as usize;
                let (p, extra) = parse_vertex(line, line_no, index)?
                    .ok_or_else(|| Error::parse(line_no, "expected a vertex"))?;
                slot[(data - plan.first_data) as usize] = p;
                extra_vertices += u64::from(extra);
            } else {
                let face = (self.first_face + data - self.vertices_wanted) as usize;
                let vertex_count = self.vertex_count as usize;
                let extra = parse_face(line, line_no, face, vertex_count, triangles)?
                    .ok_or_else(|| Error::parse(line_no, "expected a face"))?;
                extra_faces += u64::from(extra);
            }
            data += 1;
        }
        Ok((extra_vertices, extra_faces))
    }
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
    let line = strip_comment(line);
    // The common line: UTF-8 checked once for the line instead of once per coordinate (a
    // tenth of the time of reading), three coordinates that parse. Anything else takes the
    // path below, which names the problem.
    if let Ok(text) = std::str::from_utf8(line) {
        let mut toks = text.split_ascii_whitespace();
        if let Some(p) = plain_point(&mut toks) {
            let extra = toks.next().is_some();
            return finite_point(p.x, p.y, p.z, index).map(|p| Some((p, extra)));
        }
    }
    let mut toks = tokens(line);
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
    let line = strip_comment(line);
    if let Some(extra) = parse_triangle(line, vertex_count, triangles) {
        return Ok(Some(extra));
    }
    let mut toks = tokens(line);
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

/// The common face line, a triangle of plain indices (`3 i j k`, digits only, each index
/// under `vertex_count`), onto `triangles`, and whether values follow; `None`, with nothing
/// pushed, for any other line, which [`parse_face`] then reads token by token (naming the
/// problem if there is one). A third of the time of reading went to tokenizing and checking
/// face lines the general way.
fn parse_triangle(line: &[u8], vertex_count: usize, triangles: &mut Vec<[u32; 3]>) -> Option<bool> {
    let mut pos = 0;
    // The next whitespace-separated token as a plain decimal under `limit`.
    let mut number = |limit: usize| -> Option<usize> {
        while pos < line.len() && line[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        let mut value: usize = 0;
        while pos < line.len() && line[pos].is_ascii_digit() && pos - start < 10 {
            value = 10 * value + usize::from(line[pos] - b'0');
            pos += 1;
        }
        let ends = pos == line.len() || line[pos].is_ascii_whitespace();
        (pos > start && ends && value < limit).then_some(value)
    };
    if number(4)? != 3 {
        return None;
    }
    let tri = [
        number(vertex_count)?,
        number(vertex_count)?,
        number(vertex_count)?,
    ];
    // Indices under vertex_count <= u32::MAX + 1 fit u32.
    let tri = tri.map(|i| u32::try_from(i).ok());
    let [Some(a), Some(b), Some(c)] = tri else {
        return None;
    };
    triangles.push([a, b, c]);
    Some(line[pos..].iter().any(|b| !b.is_ascii_whitespace()))
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
    use crate::text::{assert_chunkings_agree, MAX_LINE};

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

    /// The body read line by line, as the reader did before it read blocks: the oracle of
    /// the block reader.
    fn read_by_lines(text: &[u8], max_line: usize) -> Result<(Mesh, ReadReport), Error> {
        let mut lines = LineReader::with_max_len(text, max_line);
        let (vertex_count, face_count, prefixes) = read_header(&mut lines)?;
        let (mut extra_vertices, mut extra_faces) = (0, 0);
        let mut positions = Vec::new();
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
        let mut triangles = Vec::new();
        let mut face: u64 = 0;
        while face < face_count {
            if !lines.advance()? {
                return Err(Error::truncated(format!(
                    "expected {face_count} faces, file ended after {face}"
                )));
            }
            let (line, line_no) = (lines.current(), lines.line());
            let vertex_total = positions.len();
            if let Some(extra) =
                parse_face(line, line_no, face as usize, vertex_total, &mut triangles)?
            {
                face += 1;
                extra_faces += u64::from(extra);
            }
        }
        let report = report(prefixes, extra_vertices, extra_faces);
        Ok((Mesh::new(positions, triangles), report))
    }

    /// The block reader against the oracle ([`crate::text::assert_chunkings_agree`]).
    fn assert_reads_as_by_lines(text: &[u8], max_line: usize) {
        assert_chunkings_agree(text, max_line, read_by_lines, |t, c| read_chunked(t, c));
    }

    #[test]
    fn blocks_read_as_lines_do() {
        let cases: &[&str] = &[
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2",
            "\u{feff}OFF 4 2 0\r\n# c\r\n0 0 0\r\n\r\n1 0 0 9\r\n  # x\r\n0 1 0\r\n1 1 0\r\n3 0 1 2 255 0 0\r\n4\t0 1\t3 2\r\ntrailing junk\r\n",
            "COFF\n3 1\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1 # c\n0 1 0\n3 0 1 2\n",
            "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n",
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n+3 00 01 2 # c\n",
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 00000000000000000002\n",
            "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1\n",
            "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n",
            "OFF\n3 1 0\n0 0 0\n1 0 0\n",
            "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
            "OFF\n0 0 0\n",
        ];
        for text in cases {
            assert_reads_as_by_lines(text.as_bytes(), MAX_LINE);
        }
        // Non-UTF-8 bytes in a comment and in a coordinate.
        assert_reads_as_by_lines(
            b"OFF\n3 1 0\n0 0 0 # \xff\n1 0 0\n0 1 0\n3 0 1 2\n",
            MAX_LINE,
        );
        assert_reads_as_by_lines(b"OFF\n3 1 0\n0 0 0\n1 \xff 0\n0 1 0\n3 0 1 2\n", MAX_LINE);
    }

    #[test]
    fn blocks_refuse_long_lines_as_lines_do() {
        let text = b"OFF\n3 1 0\n0 0 0\n1.000000000000000 0 0\n0 1 0\n3 0 1 2";
        for max_line in [5, 11, 19, 20, 21, 22, 40] {
            assert_reads_as_by_lines(text, max_line);
        }
        // A line too long after the last face is never read, in the last face's piece or
        // after it.
        let junk = b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n# a comment far too long\nxx";
        for max_line in [5, 8, 12, 40] {
            assert_reads_as_by_lines(junk, max_line);
        }
        assert!(read_chunked(
            &junk[..],
            &Chunking {
                max_line: 8,
                ..Chunking::DEFAULT
            }
        )
        .is_ok());
        let e = read_chunked(
            &text[..],
            &Chunking {
                max_line: 19,
                ..crate::text::SMALL_CHUNKINGS[2]
            },
        )
        .unwrap_err();
        assert!(
            matches!(&e, Error::Parse { line: 4, message } if message.contains("19 bytes")),
            "{e}"
        );
    }

    proptest::proptest! {
        /// Random OFF texts made of well-formed and broken lines (comments, blank lines, CRLF,
        /// tabs, extra values, polygons, bad tokens, indices out of range, truncation, junk
        /// after the faces) read the same by blocks as line by line.
        #[test]
        fn blocks_read_random_texts_as_lines_do(
            vertices in 0usize..7,
            faces in 0usize..7,
            picks in proptest::collection::vec((0usize..12, 0usize..12), 0..24),
        ) {
            const VERTEX: [&str; 12] = [
                "0 0 0", "1.5 -2 3e-3", "1\t2  3", " 4 5 6 7 8", "0 1 0\r", "# only a comment",
                "", "   ", "1 2", "1 x 3", "nan 0 0", "2 2 2 # tail",
            ];
            const FACE: [&str; 12] = [
                "3 0 1 2", "4 0 1 2 3", "3 0 1 2 255 0 0", "3\t2 1 0\r", "# c", "",
                "3 0 1", "2 0 1", "3 0 1 9", "3 -1 0 1", "+3 01 0 2", "5 0 1 2 3 4",
            ];
            let mut text = format!("OFF\n{vertices} {faces} 0\n");
            for &(v, f) in &picks {
                text.push_str(VERTEX[v]);
                text.push('\n');
                if f % 3 == 0 {
                    text.push_str(FACE[f]);
                    text.push('\n');
                }
            }
            for &(_, f) in &picks {
                text.push_str(FACE[f]);
                text.push('\n');
            }
            assert_reads_as_by_lines(text.as_bytes(), MAX_LINE);
        }
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
