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
//! Writes `v` and `f` lines (1-based) with coordinates in shortest round-trip form, so a
//! written mesh reads back bit for bit.

use std::io::{BufRead, Write};

use whet_mesh::Mesh;

use crate::text::{
    parse_f64, parse_i64, show, strip_comment, tokens, write_face_line, write_point_line,
    LineReader,
};
use crate::{finite_point, Error, Fan, ReadReport, Skipped};

/// Reads an OBJ file and reports what it skipped.
pub(crate) fn read<R: BufRead>(reader: R) -> Result<(Mesh, ReadReport), Error> {
    let mut lines = LineReader::new(reader);
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
            state.statement(line, line_no)?;
        } else {
            joined.extend_from_slice(line);
            state.statement(&joined, line_no)?;
            joined.clear();
        }
    }
    if !joined.is_empty() {
        state.statement(&joined, lines.line())?;
    }
    state.finish()
}

#[derive(Default)]
struct State {
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
    fn statement(&mut self, line: &[u8], line_no: usize) -> Result<(), Error> {
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

    fn count(counter: &mut u64) -> Result<(), Error> {
        *counter += 1;
        Ok(())
    }

    fn vertex<'a>(
        &mut self,
        mut toks: impl Iterator<Item = &'a [u8]>,
        line_no: usize,
    ) -> Result<(), Error> {
        let index = self.positions.len();
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
        if self.positions.len() >= u32::MAX as usize {
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
        let face = self.faces;
        let vertex_count = self.positions.len();
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
