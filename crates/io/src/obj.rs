//! Wavefront OBJ, geometry only.
//!
//! Reads: `v x y z [w]` vertices (`w` and any trailing colour values ignored) and `f` faces
//! whose references are `i`, `i/t`, `i//n` or `i/t/n`, 1-based or negative (relative to the
//! vertices read so far), with polygons fan-triangulated; positive references to vertices
//! defined later in the file are allowed and checked at the end. `#` comments, lines continued
//! with a trailing `\`, and every other statement (`vt`, `vn`, `vp`, `g`, `o`, `s`, `usemtl`,
//! `mtllib`, `l`, `p`, curves and surfaces...) are accepted and ignored.
//!
//! Does not read: texture coordinates, normals, vertex colours, groups or materials (they are
//! skipped), free-form geometry (skipped), points and lines (skipped). The read report
//! ([`crate::ReadReport`]) counts, in this order: texture coordinates (`vt` lines), vertex
//! normals (`vn`), vertex colours (`v` lines with three or more values after `x y z`),
//! parameter-space vertices (`vp`), points (`p` statements), lines (`l` statements) and
//! free-form curves/surfaces (`curv`, `curv2` and `surf` statements). Names (`g`, `o`, `s`,
//! `usemtl`, `mtllib`), the `w` of `v x y z w` (a weight of rational curves, which does not
//! move a polygon's vertex), display and rendering statements and the texture and normal
//! references of `f` (their data is the `vt` and `vn` lines) are not counted.
//!
//! The file is read in blocks of statements parsed in parallel ([`read`]), with the result
//! and errors of a reading line by line.
//!
//! Writes `v` and `f` lines (1-based) with coordinates in shortest round-trip form, so a
//! written mesh reads back bit for bit.

use std::io::{BufRead, Write};

use whet_mesh::Mesh;

use rayon::prelude::*;

use crate::text::{
    line_spans, parse_f64, parse_i64, pieces, plain_point, show, strip_comment, tokens,
    write_face_line, write_point_line, Chunking, LineBlocks, BOM,
};
use crate::{finite_point, Error, Fan, ReadReport, Skipped};

/// Reads an OBJ file and reports what it skipped.
///
/// The file is read in blocks of statements ([`LineBlocks`]) cut into pieces that are
/// first counted (lines, `v` and `f` statements) and then parsed in parallel, each piece
/// knowing the vertices and faces before it ([`Chunking::DEFAULT`]). The result, errors
/// included, is the one a reading line by line gives (`read_by_lines` in the tests).
pub(crate) fn read<R: BufRead>(reader: R) -> Result<(Mesh, ReadReport), Error> {
    read_chunked(reader, &Chunking::DEFAULT)
}

/// [`read`] with the blocks and pieces of `chunking`.
pub(crate) fn read_chunked<R: BufRead>(
    reader: R,
    chunking: &Chunking,
) -> Result<(Mesh, ReadReport), Error> {
    let mut blocks = LineBlocks::new(reader, chunking, true);
    let mut state = State::default();
    let mut line = 1;
    while let Some(block) = blocks.next_block(line)? {
        line = state.parse_block(block, line, chunking)?;
    }
    state.finish()
}

/// What a first pass over a piece found: its lines and its `v` and `f` statements, up to
/// the first line longer than the limit if there is one (its index in the piece).
#[derive(Default)]
struct PieceCount {
    lines: usize,
    vertices: usize,
    faces: usize,
    too_long: Option<usize>,
}

/// Calls `each` on the statements of `text` (whole statements: it ends at the end of one)
/// with the index of their last line, joining lines continued with a trailing `\\` as a
/// reading line by line does ([`crate::text::LineReader`]: a trailing `\r` is not part of a line, nor,
/// with `first`, a byte order mark at the start of the file's first line). Stops at the
/// first error `each` returns, or at a line longer than `max_line` bytes: `Err(Some(error))`
/// or `Err(None)`, with the lines read before.
fn for_each_statement<E>(
    text: &[u8],
    first: bool,
    max_line: usize,
    mut each: impl FnMut(&[u8], usize) -> Result<(), E>,
) -> (usize, Result<(), Option<E>>) {
    let mut joined: Vec<u8> = Vec::new();
    let mut lines = 0;
    for span in line_spans(text) {
        if span.len() > max_line {
            return (lines, Err(None));
        }
        let k = lines;
        lines += 1;
        let line = &text[span];
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let line = match line.strip_prefix(BOM) {
            Some(rest) if first && k == 0 => rest,
            _ => line,
        };
        if let Some(head) = line.strip_suffix(b"\\") {
            joined.extend_from_slice(head);
            joined.push(b' ');
            continue;
        }
        let done = if joined.is_empty() {
            each(line, k)
        } else {
            joined.extend_from_slice(line);
            let done = each(&joined, k);
            joined.clear();
            done
        };
        if let Err(e) = done {
            return (lines, Err(Some(e)));
        }
    }
    if !joined.is_empty() {
        if let Err(e) = each(&joined, lines.saturating_sub(1)) {
            return (lines, Err(Some(e)));
        }
    }
    (lines, Ok(()))
}

/// The keyword of statement `line`, if it has one: its first token before any `#`
/// comment (found without scanning the rest of the line).
fn keyword(line: &[u8]) -> Option<&[u8]> {
    let start = line.iter().position(|b| !b.is_ascii_whitespace())?;
    let rest = &line[start..];
    let len = rest
        .iter()
        .position(|&b| b.is_ascii_whitespace() || b == b'#')
        .unwrap_or(rest.len());
    (len > 0).then_some(&rest[..len])
}

#[derive(Default)]
struct State {
    /// Vertices and faces before this state's (a piece's state starts after those of the
    /// pieces before it).
    vertex_base: usize,
    face_base: usize,
    positions: Vec<whet_mesh::DVec3>,
    triangles: Vec<[u32; 3]>,
    /// Number of `f` statements read.
    faces: usize,
    /// References past the vertices read so far, as (face, 0-based index), checked at the end.
    forward: Vec<(usize, i64)>,
    /// Statements and values that hold data the mesh does not keep.
    skipped: Counts,
}

/// Counts of what the reader skips, for the [`ReadReport`].
#[derive(Default)]
struct Counts {
    /// `vt` lines.
    texture_coordinates: u64,
    /// `vn` lines.
    normals: u64,
    /// `v` lines with three or more values after `x y z`.
    colours: u64,
    /// `vp` lines.
    parameter_vertices: u64,
    /// `p` statements.
    points: u64,
    /// `l` statements.
    lines: u64,
    /// `curv`, `curv2` and `surf` statements.
    free_form: u64,
}

impl Counts {
    fn report(&self) -> ReadReport {
        let mut r = ReadReport::default();
        r.push(Skipped::items(
            "texture coordinates",
            "texture coordinate",
            self.texture_coordinates,
        ));
        r.push(Skipped::items(
            "vertex normals",
            "vertex normal",
            self.normals,
        ));
        r.push(Skipped::items(
            "vertex colours",
            "vertex colour",
            self.colours,
        ));
        r.push(Skipped::items(
            "parameter-space vertices (`vp`)",
            "parameter-space vertex (`vp`)",
            self.parameter_vertices,
        ));
        r.push(Skipped::items("points (`p`)", "point (`p`)", self.points));
        r.push(Skipped::items("lines (`l`)", "line (`l`)", self.lines));
        r.push(Skipped::items(
            "free-form curves/surfaces",
            "free-form curve/surface",
            self.free_form,
        ));
        r
    }
}

impl State {
    /// Parses the statements of `block` (whole statements, the first line numbered
    /// `first_line`): its pieces are counted in parallel, then parsed in parallel from
    /// their place, and their results appended in order. The number of the line after the
    /// block.
    fn parse_block(
        &mut self,
        block: &[u8],
        first_line: usize,
        chunking: &Chunking,
    ) -> Result<usize, Error> {
        let max_line = chunking.max_line;
        let pieces = pieces(block, chunking.piece, true);
        // Whether a piece holds the file's first line.
        let first = |range: &std::ops::Range<usize>| first_line == 1 && range.start == 0;
        let counts: Vec<PieceCount> = pieces
            .par_iter()
            .map(|range| {
                let mut count = PieceCount::default();
                let text = &block[range.clone()];
                let (lines, end) = for_each_statement(text, first(range), max_line, |s, _| {
                    match keyword(s) {
                        Some(b"v") => count.vertices += 1,
                        Some(b"f") => count.faces += 1,
                        _ => {}
                    }
                    Ok::<(), ()>(())
                });
                count.lines = lines;
                if end.is_err() {
                    count.too_long = Some(lines);
                }
                count
            })
            .collect();
        // Each piece's first line and the vertices and faces before it; none past a line
        // too long.
        let mut starts = Vec::with_capacity(pieces.len());
        let (mut line, mut vertices, mut faces) = (
            first_line,
            self.vertex_base + self.positions.len(),
            self.face_base + self.faces,
        );
        let mut too_long = None;
        for count in &counts {
            starts.push((line, vertices, faces));
            if let Some(k) = count.too_long {
                too_long = Some(line + k);
                break;
            }
            line += count.lines;
            vertices += count.vertices;
            faces += count.faces;
        }
        let parsed: Vec<Result<State, Error>> = pieces
            .par_iter()
            .zip(&starts)
            .zip(&counts)
            .map(|((range, &(line, vertex_base, face_base)), count)| {
                // Sized by the count: a triangle a face is the common case.
                let mut piece = State {
                    vertex_base,
                    face_base,
                    positions: Vec::with_capacity(count.vertices),
                    triangles: Vec::with_capacity(count.faces),
                    ..State::default()
                };
                let text = &block[range.clone()];
                let (_, end) = for_each_statement(text, first(range), max_line, |s, k| {
                    piece.statement(s, line + k)
                });
                match end {
                    Err(Some(e)) => Err(e),
                    // A line too long: reported below, after the pieces before it.
                    Ok(()) | Err(None) => Ok(piece),
                }
            })
            .collect();
        for piece in parsed {
            self.append(piece?);
        }
        match too_long {
            Some(line) => Err(Error::parse(
                line,
                format!("line is longer than {max_line} bytes"),
            )),
            None => Ok(line),
        }
    }

    /// Appends what `piece`, parsed from the end of this state, read.
    fn append(&mut self, piece: State) {
        self.positions.extend_from_slice(&piece.positions);
        self.triangles.extend_from_slice(&piece.triangles);
        self.faces += piece.faces;
        self.forward.extend_from_slice(&piece.forward);
        let (a, b) = (&mut self.skipped, &piece.skipped);
        a.texture_coordinates += b.texture_coordinates;
        a.normals += b.normals;
        a.colours += b.colours;
        a.parameter_vertices += b.parameter_vertices;
        a.points += b.points;
        a.lines += b.lines;
        a.free_form += b.free_form;
    }

    fn statement(&mut self, line: &[u8], line_no: usize) -> Result<(), Error> {
        if self.plain_statement(line) {
            return Ok(());
        }
        self.statement_by_tokens(line, line_no)
    }

    /// Reads statement `line` token by token, whatever it is.
    fn statement_by_tokens(&mut self, line: &[u8], line_no: usize) -> Result<(), Error> {
        let mut toks = tokens(strip_comment(line));
        let Some(keyword) = toks.next() else {
            return Ok(());
        };
        match keyword {
            b"v" => self.vertex(toks, line_no),
            b"f" => self.face(toks, line_no),
            b"vt" => Self::count(&mut self.skipped.texture_coordinates),
            b"vn" => Self::count(&mut self.skipped.normals),
            b"vp" => Self::count(&mut self.skipped.parameter_vertices),
            b"p" => Self::count(&mut self.skipped.points),
            b"l" => Self::count(&mut self.skipped.lines),
            b"curv" | b"curv2" | b"surf" => Self::count(&mut self.skipped.free_form),
            _ if keyword
                .iter()
                .all(|&b| b.is_ascii_alphanumeric() || b == b'_') =>
            {
                Ok(())
            }
            _ => Err(Error::parse(
                line_no,
                format!("not an OBJ statement: '{}'", show(keyword)),
            )),
        }
    }

    /// The common statements the quick way: a `v` whose coordinates parse, or an `f` of
    /// three to eight references that are plain or negative numbers (with any `/t/n` after
    /// them) naming vertices before it or after. True when `line` was such a statement and
    /// is read; false, with nothing read, for any other line, which [`State::statement`]
    /// then reads token by token (naming the problem if there is one). Parsing tokens the
    /// general way was a third of the time of reading a large OBJ file.
    fn plain_statement(&mut self, line: &[u8]) -> bool {
        let line = strip_comment(line);
        let Ok(text) = std::str::from_utf8(line) else {
            return false;
        };
        let mut toks = text.split_ascii_whitespace();
        match toks.next() {
            Some("v") => {
                let index = self.vertex_base + self.positions.len();
                let Some(p) = plain_point(&mut toks) else {
                    return false;
                };
                if index >= u32::MAX as usize || !p.is_finite() {
                    return false;
                }
                // `v x y z w` carries a weight, `v x y z r g b` a colour.
                if toks.nth(2).is_some() {
                    self.skipped.colours += 1;
                }
                self.positions.push(p);
                true
            }
            Some("f") => {
                let vertex_count = self.vertex_base + self.positions.len();
                let mut refs = [0u32; 8];
                let mut n = 0;
                for tok in toks {
                    let Some(slot) = refs.get_mut(n) else {
                        return false;
                    };
                    let reference = tok.split('/').next().unwrap_or_default();
                    let Ok(raw) = reference.parse::<i32>() else {
                        return false;
                    };
                    // Zero and references before the first vertex are errors: the general way.
                    let index = match raw {
                        r if r > 0 => i64::from(r) - 1,
                        r if r < 0 => vertex_count as i64 + i64::from(r),
                        _ => return false,
                    };
                    let Ok(index) = u32::try_from(index) else {
                        return false;
                    };
                    *slot = index;
                    n += 1;
                }
                if n < 3 {
                    return false;
                }
                let face = self.face_base + self.faces;
                let mut fan = Fan::new();
                for &index in &refs[..n] {
                    if index as usize >= vertex_count {
                        self.forward.push((face, i64::from(index)));
                    }
                    fan.push(index, &mut self.triangles);
                }
                self.faces += 1;
                true
            }
            _ => false,
        }
    }

    fn count(counter: &mut u64) -> Result<(), Error> {
        *counter += 1;
        Ok(())
    }

    fn vertex<'a>(
        &mut self,
        mut toks: impl Iterator<Item = &'a [u8]>,
        line_no: usize,
    ) -> Result<(), Error> {
        let index = self.vertex_base + self.positions.len();
        let mut xyz = [0.0; 3];
        for (k, c) in xyz.iter_mut().enumerate() {
            let Some(tok) = toks.next() else {
                return Err(Error::parse(
                    line_no,
                    format!("vertex {} has {k} coordinates; 3 are needed", index + 1),
                ));
            };
            *c = parse_f64(tok).ok_or_else(|| {
                Error::parse(
                    line_no,
                    format!("invalid coordinate '{}' in vertex {}", show(tok), index + 1),
                )
            })?;
        }
        // `v x y z w` carries a weight, `v x y z r g b` a colour.
        if toks.nth(2).is_some() {
            self.skipped.colours += 1;
        }
        if index >= u32::MAX as usize {
            return Err(Error::TooLarge {
                what: "OBJ vertex".into(),
                count: index as u64 + 1,
            });
        }
        self.positions
            .push(finite_point(xyz[0], xyz[1], xyz[2], index)?);
        Ok(())
    }

    fn face<'a>(
        &mut self,
        toks: impl Iterator<Item = &'a [u8]>,
        line_no: usize,
    ) -> Result<(), Error> {
        let face = self.face_base + self.faces;
        let vertex_count = self.vertex_base + self.positions.len();
        let mut fan = Fan::new();
        for tok in toks {
            let reference = tok.split(|&b| b == b'/').next().unwrap_or_default();
            let raw = parse_i64(reference).ok_or_else(|| {
                Error::parse(
                    line_no,
                    format!("invalid vertex reference '{}' in face", show(tok)),
                )
            })?;
            let index = match raw {
                0 => {
                    return Err(Error::parse(
                        line_no,
                        "vertex reference 0 in face: OBJ indices start at 1",
                    ))
                }
                r if r > 0 => r - 1,
                // `r` is negative, so the sum cannot overflow.
                r => vertex_count as i64 + r,
            };
            let Ok(index_u32) = u32::try_from(index) else {
                return Err(Error::IndexOutOfRange {
                    face,
                    index,
                    vertex_count,
                });
            };
            if index_u32 as usize >= vertex_count {
                self.forward.push((face, index));
            }
            fan.push(index_u32, &mut self.triangles);
        }
        if fan.len < 3 {
            return Err(Error::parse(
                line_no,
                format!("face has {} vertices; at least 3 are needed", fan.len),
            ));
        }
        self.faces += 1;
        Ok(())
    }

    fn finish(self) -> Result<(Mesh, ReadReport), Error> {
        let vertex_count = self.positions.len();
        if let Some(&(face, index)) = self
            .forward
            .iter()
            .find(|&&(_, index)| index >= vertex_count as i64)
        {
            return Err(Error::IndexOutOfRange {
                face,
                index,
                vertex_count,
            });
        }
        Ok((
            Mesh::new(self.positions, self.triangles),
            self.skipped.report(),
        ))
    }
}

/// Writes `mesh` as OBJ `v` and `f` lines.
pub(crate) fn write<W: Write>(w: &mut W, mesh: &Mesh) -> std::io::Result<()> {
    writeln!(
        w,
        "# {} vertices, {} triangles",
        mesh.positions.len(),
        mesh.triangles.len()
    )?;
    for &p in &mesh.positions {
        write_point_line(w, b"v", p)?;
    }
    for t in &mesh.triangles {
        write_face_line(w, b"f", t.map(|i| u64::from(i) + 1))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::{assert_chunkings_agree, LineReader, MAX_LINE};
    use whet_mesh::DVec3;

    fn read<R: BufRead>(reader: R) -> Result<Mesh, Error> {
        super::read(reader).map(|(mesh, _)| mesh)
    }

    fn read_str(s: &str) -> Result<Mesh, Error> {
        read(s.as_bytes())
    }

    #[test]
    fn references_of_every_kind() {
        let m = read_str(
            "# comment\nmtllib x.mtl\no thing\ng group\n\
             v 0 0 0\nv 1 0 0 1.0\nv 1 1 0 0.5 0.5 0.5\nv 0 1 0\n\
             vt 0 0\nvn 0 0 1\nusemtl red\ns off\n\
             f 1 2 3\nf 1/1 3/2 4/3\nf 1//1 2//1 3//1\nf -4/1/1 -3/2/1 -2/3/1 -1/4/1\nl 1 2\n",
        )
        .unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.positions[2], DVec3::new(1.0, 1.0, 0.0));
        assert_eq!(
            m.triangles,
            vec![[0, 1, 2], [0, 2, 3], [0, 1, 2], [0, 1, 2], [0, 2, 3]]
        );
    }

    #[test]
    fn report_counts_uvs_normals_colours_points_lines_and_curves() {
        let text = "# a quad with texture coordinates and normals\nmtllib m.mtl\no quad\n\
                    g top\ns 1\nusemtl red\n\
                    v 0 0 0\nv 1 0 0 1.0\nv 1 1 0 0.5 0.5 0.5\nv 0 1 0\n\
                    vt 0 0\nvt 1 0\nvt 1 \\\n 1\nvt 0 1\nvn 0 0 1\nvn 0 0 -1\n\
                    f 1/1/1 2/2/1 3/3/2 4/4/2\nl 1 2 3\np 1\np 2\n\
                    vp 0.5\ncstype bspline\ndeg 1\ncurv 0.0 1.0 1 2\nparm u 0 0 1 1\nend\n";
        let (mesh, report) = super::read(text.as_bytes()).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(
            report.pairs(),
            vec![
                ("texture coordinates", 4),
                ("vertex normals", 2),
                ("vertex colours", 1),
                ("parameter-space vertices (`vp`)", 1),
                ("points (`p`)", 2),
                ("lines (`l`)", 1),
                ("free-form curves/surfaces", 1),
            ]
        );
        assert_eq!(
            report.to_string(),
            "4 texture coordinates, 2 vertex normals, 1 vertex colour, \
             1 parameter-space vertex (`vp`), 2 points (`p`), 1 line (`l`) and \
             1 free-form curve/surface"
        );
        // Names, comments and `w` weights hold nothing a mesh user misses.
        let names = "# c\nmtllib d.mtl\no a\ng b\ns off\nusemtl c\n\
                     v 0 0 0 1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        let (_, report) = super::read(names.as_bytes()).unwrap();
        assert!(report.is_empty(), "{report:?}");
    }

    #[test]
    fn negative_indices_are_relative_to_vertices_so_far() {
        let m = read_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nf -1 -2 -3\n").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [3, 2, 1]]);
        let e = read_str("v 0 0 0\nv 1 0 0\nf -1 -2 -3\n").unwrap_err();
        assert!(
            matches!(
                e,
                Error::IndexOutOfRange {
                    face: 0,
                    index: -1,
                    vertex_count: 2
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn forward_references_are_checked_at_the_end() {
        let m = read_str("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        let e = read_str("v 0 0 0\nv 1 0 0\nf 1 2 3\nf 1 2 9\nv 0 1 0\n").unwrap_err();
        assert!(
            matches!(
                e,
                Error::IndexOutOfRange {
                    face: 1,
                    index: 8,
                    vertex_count: 3
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn continuation_lines() {
        let m = read_str("v 0 0 \\\n 0\nv 1 0 0\nv 0 1 0\nf 1 \\\n2 \\\n3\n").unwrap();
        assert_eq!(m.positions.len(), 3);
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }

    /// The reading line by line as it was before blocks, every statement read token by
    /// token: the oracle of the block reader and of its quick statements.
    fn read_by_lines(text: &[u8], max_line: usize) -> Result<(Mesh, ReadReport), Error> {
        let mut lines = LineReader::with_max_len(text, max_line);
        let mut state = State::default();
        let mut joined: Vec<u8> = Vec::new();
        while lines.advance()? {
            let line_no = lines.line();
            let line = lines.current();
            if let Some(head) = line.strip_suffix(b"\\") {
                joined.extend_from_slice(head);
                joined.push(b' ');
                continue;
            }
            if joined.is_empty() {
                state.statement_by_tokens(line, line_no)?;
            } else {
                joined.extend_from_slice(line);
                state.statement_by_tokens(&joined, line_no)?;
                joined.clear();
            }
        }
        if !joined.is_empty() {
            state.statement_by_tokens(&joined, lines.line())?;
        }
        state.finish()
    }

    /// The block reader against the oracle ([`crate::text::assert_chunkings_agree`]).
    fn assert_reads_as_by_lines(text: &[u8], max_line: usize) {
        assert_chunkings_agree(text, max_line, read_by_lines, |t, c| read_chunked(t, c));
    }

    /// A reader whose data ends in a failure, as a broken pipe's does.
    struct Failing;

    impl std::io::Read for Failing {
        fn read(&mut self, _: &mut [u8]) -> std::io::Result<usize> {
            Err(std::io::Error::other("the pipe broke"))
        }
    }

    #[test]
    fn what_was_read_before_a_failing_read_is_parsed_first() {
        use std::io::Read;
        // An error in the lines read before the failure is the one reported, as a reading
        // line by line reports it; a failure where more lines are needed is an I/O error.
        let reader = std::io::BufReader::new(b"v 1 x 0\n".chain(Failing));
        let e = super::read(reader).unwrap_err();
        assert!(matches!(&e, Error::Parse { line: 1, .. }), "{e}");
        let reader = std::io::BufReader::new(b"v 1 2 0\n".chain(Failing));
        let e = super::read(reader).unwrap_err();
        assert!(matches!(e, Error::Io(_)), "{e}");
        // OFF stops after its last face, before the failure.
        let off = b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        let reader = std::io::BufReader::new(off.chain(Failing));
        assert!(crate::read(reader, crate::Format::Off).is_ok());
    }

    #[test]
    fn blocks_read_as_lines_do() {
        let cases: &[&[u8]] = &[
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            b"\xEF\xBB\xBFv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3",
            b"\xEF\xBB\xBF\\\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3",
            b"v 0 0 \\\n 0\nv 1 0 0\nv 0 1 0\nf 1 \\\r\n2 \\\n3\n",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \\",
            b"v 0 0 0 # c \\\n f 1 2 3\nv 1 0 0\nv 0 1 0\n",
            b"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nf 1 2 4\n",
            b"v 0 0 0\nv 1 0 0\nf -1 -2 -3\n",
            b"v 0 0 0\nv 1 0\n",
            b"v 0 0 0\nvt 0 0\nvn 0 0 1\nv 1 0 0 1\nv 0 1 0 1 1 1\nf 1/1/1 2//1 3/1\nl 1 2\np 1\n",
            b"v 0 0 0\n\x01garbage\n",
            b"v 0 0 0\nv 1 \xff 0\n",
            b"",
            b"\\",
        ];
        for text in cases {
            assert_reads_as_by_lines(text, MAX_LINE);
        }
        // Lines too long, before, inside and after continued statements and errors.
        let long = b"v 0 0 0\nv 1 x 0\nf 1 2 \\\n3 # a rather long comment\nv 0.000000001 1 0\n";
        for max_line in [3, 7, 8, 9, 12, 20, 30, 40] {
            assert_reads_as_by_lines(long, max_line);
            assert_reads_as_by_lines(&long[8..], max_line);
        }
    }

    proptest::proptest! {
        /// Random OBJ texts of well-formed and broken statements (continuations, CRLF,
        /// comments, negative and forward references, ignored statements, bad tokens) read
        /// the same by blocks as line by line.
        #[test]
        fn blocks_read_random_texts_as_lines_do(
            picks in proptest::collection::vec(0usize..32, 0..30),
        ) {
            const STATEMENTS: [&str; 20] = [
                "v 0 0 0", "v 1.5 -2 3e-3", "v 1 2 3 1", "v 4 5 6 0.1 0.2 0.3", "v 1 2 \\\n 3",
                "f 1 2 3", "f -1 -2 -3", "f 1/1 2/2 3/3 4/4", "f 1//2 \\\r\n 2//2 3//2", "f 1 2 9",
                "vt 0 0", "vn 0 0 1", "# comment \\", "", "g name", "l 1 2", "v 1 x 2",
                "f 0 1 2", "f 1 2", "\u{1}junk",
            ];
            const MORE: [&str; 12] = [
                "f +1 02 3", "f -1/2 -2/ -3//4", "f 1 2 3 4 5 6 7 8 9", "f 1 2 3#c", "v 1 2 3#c",
                "v 1 2 3 4 5", "f 1/x 2 3", "f -9 1 2", "f 4294967296 1 2", "v nan 0 0",
                "v\t1\t2\t3", "f 1 / 2 3",
            ];
            let mut text = String::new();
            for &k in &picks {
                text.push_str(if k < 20 { STATEMENTS[k] } else { MORE[k - 20] });
                text.push_str(if k % 4 == 0 { "\r\n" } else { "\n" });
            }
            assert_reads_as_by_lines(text.as_bytes(), MAX_LINE);
            assert_reads_as_by_lines(text.as_bytes(), 12);
        }
    }

    #[test]
    fn errors() {
        let e = read_str("v 0 0 0\nv 1 0\n").unwrap_err();
        assert!(matches!(e, Error::Parse { line: 2, .. }), "{e}");
        let e = read_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n").unwrap_err();
        assert!(matches!(e, Error::Parse { line: 4, .. }), "{e}");
        let e = read_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n").unwrap_err();
        assert!(matches!(e, Error::Parse { line: 4, .. }), "{e}");
        let e = read_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n").unwrap_err();
        assert!(matches!(e, Error::Parse { line: 4, .. }), "{e}");
        let e = read_str("v 0 0 0\nv inf 0 0\n").unwrap_err();
        assert!(matches!(e, Error::NonFinite { vertex: 1 }), "{e}");
        let e = read_str("v 0 0 0\n\u{1}\u{2}garbage\n").unwrap_err();
        assert!(matches!(e, Error::Parse { line: 2, .. }), "{e}");
        let e = read_str("f 1 2 99999999999\n").unwrap_err();
        assert!(matches!(e, Error::IndexOutOfRange { .. }), "{e}");
    }

    #[test]
    fn write_then_read_is_exact() {
        let m = Mesh::new(
            vec![
                DVec3::new(0.1, -0.0, 1e-300),
                DVec3::new(1.0 / 3.0, 2e20, -7.25),
                DVec3::new(1.0, 2.0, 3.0),
            ],
            vec![[0, 1, 2], [2, 1, 0]],
        );
        let mut out = Vec::new();
        write(&mut out, &m).unwrap();
        let back = read(&out[..]).unwrap();
        assert_eq!(back, m);
        assert_eq!(back.positions[0].y.to_bits(), (-0.0f64).to_bits());
    }
}
