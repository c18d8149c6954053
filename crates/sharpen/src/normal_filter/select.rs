//! `--select`: the vertex list that limits the normal filter to a region (docs/sharpen.md).
//!
//! Format: 0-based vertex indices separated by any whitespace; `#` starts a comment that runs
//! to the end of its line; order and repeats do not matter.

use std::path::Path;

use whet_mesh::Mesh;

use crate::Error;

/// A set of vertices of one mesh: the region the normal filter may change.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct VertexSelection {
    /// The selected vertices, strictly increasing.
    pub vertices: Vec<u32>,
}

impl VertexSelection {
    /// A selection from any list of indices (sorted and deduplicated here).
    pub fn new(mut vertices: Vec<u32>) -> VertexSelection {
        vertices.sort_unstable();
        vertices.dedup();
        VertexSelection { vertices }
    }

    /// Parses the text of a selection file for a mesh of `vertex_count` vertices. A word that
    /// is not a non-negative integer, or an index not below `vertex_count`, is an
    /// [`Error::Format`] naming its (1-based) line.
    pub fn parse(text: &str, vertex_count: usize) -> Result<VertexSelection, Error> {
        let mut vertices = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let body = line.split('#').next().unwrap_or("");
            for word in body.split_whitespace() {
                let v: u64 = word
                    .parse()
                    .map_err(|_| Error::format(i + 1, format!("{word:?} is not a vertex index")))?;
                if v >= vertex_count as u64 {
                    return Err(Error::format(
                        i + 1,
                        format!("vertex {v} is out of range: the mesh has {vertex_count} vertices"),
                    ));
                }
                vertices.push(v as u32);
            }
        }
        Ok(VertexSelection::new(vertices))
    }

    /// Reads a selection file for `mesh`.
    pub fn read_path(path: impl AsRef<Path>, mesh: &Mesh) -> Result<VertexSelection, Error> {
        let text = std::fs::read_to_string(path)?;
        VertexSelection::parse(&text, mesh.positions.len())
    }

    /// The selection as file text (one index per line, after a comment line).
    pub fn to_text(&self) -> String {
        let mut s = String::from("# whet vertex selection: 0-based vertex indices\n");
        for v in &self.vertices {
            s += &format!("{v}\n");
        }
        s
    }

    /// One flag per vertex of a mesh of `vertex_count` vertices; indices out of range are an
    /// [`Error::Parameter`].
    pub(crate) fn flags(&self, vertex_count: usize) -> Result<Vec<bool>, Error> {
        let mut f = vec![false; vertex_count];
        for &v in &self.vertices {
            match f.get_mut(v as usize) {
                Some(x) => *x = true,
                None => {
                    return Err(Error::Parameter(format!(
                        "selected vertex {v} is out of range: the mesh has {vertex_count} vertices"
                    )))
                }
            }
        }
        Ok(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_whitespace_comments_and_repeats() {
        let s = VertexSelection::parse("# region\n3 1\t2\n\n 1 # again\n0#x\n", 4).unwrap();
        assert_eq!(s.vertices, vec![0, 1, 2, 3]);
        assert_eq!(VertexSelection::parse(&s.to_text(), 4).unwrap(), s);
        assert!(VertexSelection::parse("", 4).unwrap().vertices.is_empty());
    }

    #[test]
    fn bad_words_and_ranges_name_their_line() {
        match VertexSelection::parse("1\n2 x\n", 4) {
            Err(Error::Format { line: 2, .. }) => {}
            other => panic!("{other:?}"),
        }
        match VertexSelection::parse("1\n# 9\n-1", 4) {
            Err(Error::Format { line: 3, .. }) => {}
            other => panic!("{other:?}"),
        }
        match VertexSelection::parse("4", 4) {
            Err(Error::Format { line: 1, message }) => assert!(message.contains("out of range")),
            other => panic!("{other:?}"),
        }
        assert!(VertexSelection::new(vec![7]).flags(4).is_err());
    }
}
