//! Sharp-edge tags (seed 001 section 4.1) and their sidecar text file.
//!
//! The format (docs/sharpen.md, "Sharp-edge tags"), line oriented, ASCII:
//!
//! ```text
//! whet-sharp-tags 1
//! # comment lines start with '#'; blank lines are ignored
//! mesh <vertex count> <triangle count>
//! vertices <k>
//! <vertex index>            k lines, strictly increasing
//! edges <m>
//! <a> <b>                   m lines, a < b, strictly increasing by (a, b)
//! ```
//!
//! The `mesh` line ties the file to the mesh it was written for; reading checks it, the
//! ranges, the order, and that every edge is an edge of the mesh.

use std::io::{BufRead, BufWriter, Write};
use std::path::Path;

use whet_mesh::{Mesh, VertexId};

use crate::Error;

/// First line of a tag file.
const MAGIC: &str = "whet-sharp-tags";
/// The one format version.
const VERSION: u32 = 1;
/// Largest count a tag file may declare before any allocation (a tag file never holds more
/// entries than 32-bit vertex indices allow; the mesh check below is the real bound).
const MAX_DECLARED: u64 = u32::MAX as u64;

/// The sharp vertices and edges of a mesh, for Bender.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SharpTags {
    /// Tagged vertices, strictly increasing.
    pub vertices: Vec<VertexId>,
    /// Sharp edges as `[a, b]` with `a < b`, strictly increasing: the edges of the mesh whose
    /// two ends are tagged.
    pub edges: Vec<[VertexId; 2]>,
}

impl SharpTags {
    /// Tags from a per-vertex flag: the flagged vertices, and every edge of `mesh` whose two
    /// ends are flagged. `tagged.len()` must be the vertex count (shorter means untagged).
    pub fn from_vertex_flags(mesh: &Mesh, tagged: &[bool]) -> SharpTags {
        let is = |v: u32| tagged.get(v as usize).copied().unwrap_or(false);
        let vertices: Vec<VertexId> = (0..tagged.len().min(mesh.positions.len()))
            .filter(|&v| tagged[v])
            .map(VertexId::from_index)
            .collect();
        // Packed as one word (lower end high), so the sort compares words; the same order as
        // the pairs.
        let mut packed: Vec<u64> = Vec::new();
        for tri in &mesh.triangles {
            for (a, b) in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
                if a != b && is(a) && is(b) {
                    packed.push(u64::from(a.min(b)) << 32 | u64::from(a.max(b)));
                }
            }
        }
        packed.sort_unstable();
        packed.dedup();
        let edges = packed
            .iter()
            .map(|&e| [VertexId((e >> 32) as u32), VertexId(e as u32)])
            .collect();
        SharpTags { vertices, edges }
    }

    /// True when `v` is tagged.
    pub fn is_tagged(&self, v: VertexId) -> bool {
        self.vertices.binary_search(&v).is_ok()
    }

    /// True when the edge `{a, b}` is sharp.
    pub fn is_sharp(&self, a: VertexId, b: VertexId) -> bool {
        let key = if a < b { [a, b] } else { [b, a] };
        self.edges.binary_search(&key).is_ok()
    }

    /// Writes the sidecar file for `mesh` (the mesh these tags belong to).
    pub fn write<W: Write>(&self, mut w: W, mesh: &Mesh) -> Result<(), Error> {
        writeln!(w, "{MAGIC} {VERSION}")?;
        writeln!(
            w,
            "# sharp-edge tags written by whet-sharpen (seed 001 section 4.1)"
        )?;
        writeln!(w, "mesh {} {}", mesh.positions.len(), mesh.triangles.len())?;
        writeln!(w, "vertices {}", self.vertices.len())?;
        for v in &self.vertices {
            writeln!(w, "{v}")?;
        }
        writeln!(w, "edges {}", self.edges.len())?;
        for [a, b] in &self.edges {
            writeln!(w, "{a} {b}")?;
        }
        w.flush()?;
        Ok(())
    }

    /// Writes the sidecar file to `path`.
    pub fn write_path(&self, path: &Path, mesh: &Mesh) -> Result<(), Error> {
        let f = std::fs::File::create(path)?;
        self.write(BufWriter::new(f), mesh)
    }

    /// Reads a sidecar file and checks it against `mesh`: counts on the `mesh` line, indices
    /// in range, strictly increasing lists, `a < b`, and every edge an edge of `mesh`.
    pub fn read<R: BufRead>(reader: R, mesh: &Mesh) -> Result<SharpTags, Error> {
        let mut lines = Lines {
            inner: reader.lines(),
            number: 0,
        };
        let (n, header) = lines.next_content()?;
        let mut it = header.split_ascii_whitespace();
        if it.next() != Some(MAGIC) {
            return Err(Error::format(n, format!("expected \"{MAGIC} {VERSION}\"")));
        }
        match it.next().map(str::parse::<u32>) {
            Some(Ok(VERSION)) => {}
            Some(Ok(v)) => {
                return Err(Error::format(
                    n,
                    format!("unsupported version {v} (this reader knows {VERSION})"),
                ))
            }
            _ => return Err(Error::format(n, "missing or bad version".to_string())),
        }
        let nv = mesh.positions.len() as u64;
        let nt = mesh.triangles.len() as u64;
        let (n, fields) = lines.keyword("mesh", 2)?;
        if fields != [nv, nt] {
            return Err(Error::format(
                n,
                format!(
                    "the tags are for a mesh of {} vertices and {} triangles, this one has {nv} and {nt}",
                    fields[0], fields[1]
                ),
            ));
        }
        let (_, k) = lines.keyword("vertices", 1)?;
        let k = k[0];
        if k > nv {
            return Err(Error::format(
                lines.number,
                format!("{k} tagged vertices declared, the mesh has {nv}"),
            ));
        }
        let mut vertices = Vec::with_capacity(k as usize);
        for _ in 0..k {
            let (n, v) = lines.numbers(1)?;
            let v = v[0];
            if v >= nv {
                return Err(Error::format(
                    n,
                    format!("vertex {v} out of range ({nv} vertices)"),
                ));
            }
            let v = VertexId(v as u32);
            if vertices.last().is_some_and(|&last| last >= v) {
                return Err(Error::format(
                    n,
                    "vertices not strictly increasing".to_string(),
                ));
            }
            vertices.push(v);
        }
        let (_, m) = lines.keyword("edges", 1)?;
        let m = m[0];
        // A manifold mesh has at most 3T/2 edges; allow 3T for any input.
        if m > 3 * nt {
            return Err(Error::format(
                lines.number,
                format!("{m} edges declared, the mesh has at most {} edges", 3 * nt),
            ));
        }
        let mesh_edges = mesh.undirected_edges();
        let mut edges = Vec::with_capacity(m as usize);
        for _ in 0..m {
            let (n, e) = lines.numbers(2)?;
            let (a, b) = (e[0], e[1]);
            if a >= nv || b >= nv {
                return Err(Error::format(
                    n,
                    format!("edge ({a}, {b}) out of range ({nv} vertices)"),
                ));
            }
            if a >= b {
                return Err(Error::format(n, format!("edge ({a}, {b}) must have a < b")));
            }
            let e = [VertexId(a as u32), VertexId(b as u32)];
            if edges.last().is_some_and(|last| *last >= e) {
                return Err(Error::format(
                    n,
                    "edges not strictly increasing".to_string(),
                ));
            }
            if mesh_edges.binary_search(&[a as u32, b as u32]).is_err() {
                return Err(Error::format(
                    n,
                    format!("({a}, {b}) is not an edge of the mesh"),
                ));
            }
            edges.push(e);
        }
        if let Some((n, line)) = lines.next_content_opt()? {
            return Err(Error::format(
                n,
                format!("unexpected content after the edges: {line:?}"),
            ));
        }
        Ok(SharpTags { vertices, edges })
    }

    /// Reads the sidecar file at `path` for `mesh`.
    pub fn read_path(path: &Path, mesh: &Mesh) -> Result<SharpTags, Error> {
        let f = std::fs::File::open(path)?;
        SharpTags::read(std::io::BufReader::new(f), mesh)
    }
}

/// Content lines (comments and blank lines skipped) with their 1-based numbers.
struct Lines<B> {
    inner: std::io::Lines<B>,
    number: usize,
}

impl<B: BufRead> Lines<B> {
    fn next_content_opt(&mut self) -> Result<Option<(usize, String)>, Error> {
        for line in self.inner.by_ref() {
            self.number += 1;
            let line = line?;
            let t = line.trim();
            if t.is_empty() || t.starts_with('#') {
                continue;
            }
            return Ok(Some((self.number, t.to_string())));
        }
        Ok(None)
    }

    fn next_content(&mut self) -> Result<(usize, String), Error> {
        self.next_content_opt()?
            .ok_or_else(|| Error::format(self.number + 1, "unexpected end of file".to_string()))
    }

    /// A line of exactly `count` unsigned integers.
    fn numbers(&mut self, count: usize) -> Result<(usize, Vec<u64>), Error> {
        let (n, line) = self.next_content()?;
        let v = parse_numbers(n, line.split_ascii_whitespace(), count)?;
        Ok((n, v))
    }

    /// A line `keyword` followed by exactly `count` unsigned integers.
    fn keyword(&mut self, keyword: &str, count: usize) -> Result<(usize, Vec<u64>), Error> {
        let (n, line) = self.next_content()?;
        let mut it = line.split_ascii_whitespace();
        if it.next() != Some(keyword) {
            return Err(Error::format(n, format!("expected a \"{keyword}\" line")));
        }
        let v = parse_numbers(n, it, count)?;
        Ok((n, v))
    }
}

fn parse_numbers<'a>(
    n: usize,
    it: impl Iterator<Item = &'a str>,
    count: usize,
) -> Result<Vec<u64>, Error> {
    let v: Vec<&str> = it.collect();
    if v.len() != count {
        return Err(Error::format(
            n,
            format!("expected {count} numbers, found {}", v.len()),
        ));
    }
    v.iter()
        .map(|s| match s.parse::<u64>() {
            Ok(x) if x <= MAX_DECLARED => Ok(x),
            _ => Err(Error::format(n, format!("bad number {s:?}"))),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use whet_mesh::DVec3;

    fn tetra() -> Mesh {
        Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
        )
    }

    #[test]
    fn round_trip() {
        let m = tetra();
        let tags = SharpTags::from_vertex_flags(&m, &[true, true, false, true]);
        assert_eq!(tags.vertices, vec![VertexId(0), VertexId(1), VertexId(3)]);
        assert_eq!(
            tags.edges,
            vec![
                [VertexId(0), VertexId(1)],
                [VertexId(0), VertexId(3)],
                [VertexId(1), VertexId(3)]
            ]
        );
        let mut buf = Vec::new();
        tags.write(&mut buf, &m).unwrap();
        let text = String::from_utf8(buf.clone()).unwrap();
        assert!(text.starts_with("whet-sharp-tags 1\n"));
        assert!(text.contains("mesh 4 4\nvertices 3\n0\n1\n3\nedges 3\n0 1\n0 3\n1 3\n"));
        assert_eq!(SharpTags::read(&buf[..], &m).unwrap(), tags);
        assert!(tags.is_sharp(VertexId(3), VertexId(0)));
        assert!(!tags.is_sharp(VertexId(2), VertexId(0)));
    }

    #[test]
    fn rejects_bad_files() {
        let m = tetra();
        let bad = [
            ("", "end of file"),
            ("whet-sharp-tags 2\n", "version"),
            ("whet-sharp-tags 1\nmesh 5 4\n", "mesh of 5"),
            (
                "whet-sharp-tags 1\nmesh 4 4\nvertices 1\n9\n",
                "out of range",
            ),
            (
                "whet-sharp-tags 1\nmesh 4 4\nvertices 2\n1\n1\n",
                "increasing",
            ),
            (
                "whet-sharp-tags 1\nmesh 4 4\nvertices 0\nedges 1\n1 0\n",
                "a < b",
            ),
            (
                "whet-sharp-tags 1\nmesh 4 4\nvertices 0\nedges 1\n0 x\n",
                "bad number",
            ),
            (
                "whet-sharp-tags 1\nmesh 4 4\nvertices 0\nedges 99\n",
                "at most",
            ),
            (
                "whet-sharp-tags 1\nmesh 4 4\nvertices 0\nedges 0\nextra\n",
                "unexpected",
            ),
            (
                "whet-sharp-tags 1\nmesh 4 4\nvertices 18446744073709551615\n",
                "bad number",
            ),
        ];
        for (text, want) in bad {
            let e = SharpTags::read(text.as_bytes(), &m).unwrap_err();
            assert!(e.to_string().contains(want), "{text:?}: {e}");
        }
        // Not an edge: a square's diagonal that the triangulation does not use.
        let sq = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let e = SharpTags::read(
            "whet-sharp-tags 1\nmesh 4 2\nvertices 0\nedges 1\n1 3\n".as_bytes(),
            &sq,
        )
        .unwrap_err();
        assert!(e.to_string().contains("not an edge"), "{e}");
    }
}
