//! What a reader skipped: the data a file held that a [`whet_mesh::Mesh`] has no place for.

use std::fmt;

/// What a reader found in a file besides vertex positions and polygons, and did not keep.
///
/// whet codes positions and triangles only, so texture coordinates, normals, colours and the
/// other attributes a file may carry are read past; [`read_with_report`](crate::read_with_report)
/// and [`read_path_with_report`](crate::read_path_with_report) say which, and how many, so an
/// application can tell its user. Only data a user could miss is listed: comments, OBJ group,
/// object, smoothing and material names, STL facet normals (they follow from the triangles)
/// and all-zero STL attribute bytes are not. Counting costs no memory beyond a counter per kind.
///
/// ```
/// use whet_io::{read_with_report, Format};
///
/// let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\n";
/// let (mesh, report) = read_with_report(obj.as_bytes(), Format::Obj)?;
/// assert_eq!(mesh.triangles.len(), 1);
/// assert_eq!(report.to_string(), "3 texture coordinates and 1 vertex normal");
/// assert_eq!(report.skipped[0].what, "texture coordinates");
/// assert_eq!(report.skipped[0].count, 3);
/// # Ok::<(), whet_io::Error>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct ReadReport {
    /// One entry per kind of data skipped, none with a zero count. PLY lists them in header
    /// order; the other formats in a fixed order (see their readers' documentation).
    pub skipped: Vec<Skipped>,
}

impl ReadReport {
    /// True when the file held nothing but positions and polygons (and names and comments).
    pub fn is_empty(&self) -> bool {
        self.skipped.is_empty()
    }

    /// The entries as (what, count) pairs, for tests.
    #[cfg(test)]
    pub(crate) fn pairs(&self) -> Vec<(&str, u64)> {
        self.skipped
            .iter()
            .map(|s| (s.what.as_str(), s.count))
            .collect()
    }

    /// Adds `entry` unless its count is zero.
    pub(crate) fn push(&mut self, entry: Skipped) {
        if entry.count > 0 {
            self.skipped.push(entry);
        }
    }
}

/// The entries as one English list, e.g. "1200 texture coordinates, 1200 vertex normals and
/// element `edge` (30 entries)"; "nothing" when empty.
impl fmt::Display for ReadReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.skipped.len();
        if n == 0 {
            return f.write_str("nothing");
        }
        for (i, entry) in self.skipped.iter().enumerate() {
            if i > 0 {
                f.write_str(if i + 1 == n { " and " } else { ", " })?;
            }
            write!(f, "{entry}")?;
        }
        Ok(())
    }
}

/// One kind of data a reader skipped, and how many.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct Skipped {
    /// What was skipped, in plain words: "texture coordinates", "vertex normals",
    /// "vertex colours", "face colours", "lines (`l`)", "vertex property `confidence`",
    /// "element `edge`", "STL attribute bytes"...
    pub what: String,
    /// How many: items of `what` when it is a plural noun (`vt` lines, vertices carrying a
    /// colour, faces carrying one); for a PLY property, the values of it (one per element);
    /// for a PLY element, its entries; for STL attribute bytes, the facets whose two bytes are
    /// not zero; for values OFF does not name, the vertices that carry them.
    pub count: u64,
    /// How [`fmt::Display`] puts `count` into words.
    unit: Unit,
}

/// How a count reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Unit {
    /// "{count} {what}", with `one` for a count of 1: "1200 texture coordinates".
    Items { one: &'static str },
    /// "{what} ({prefix}{count} {one or many})": "element `edge` (30 entries)".
    Of {
        prefix: &'static str,
        one: &'static str,
        many: &'static str,
    },
}

impl Skipped {
    /// `count` items of `many` (a plural noun whose singular is `one`).
    pub(crate) fn items(many: &'static str, one: &'static str, count: u64) -> Skipped {
        Skipped {
            what: many.to_owned(),
            count,
            unit: Unit::Items { one },
        }
    }

    /// `what`, counted in `one`/`many` after `prefix`: "STL attribute bytes (non-zero on 3
    /// facets)".
    pub(crate) fn of(
        what: String,
        count: u64,
        prefix: &'static str,
        one: &'static str,
        many: &'static str,
    ) -> Skipped {
        Skipped {
            what,
            count,
            unit: Unit::Of { prefix, one, many },
        }
    }
}

/// "1200 texture coordinates", "vertex property `confidence` (1200 values)", "STL attribute
/// bytes (non-zero on 3 facets)".
impl fmt::Display for Skipped {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let count = self.count;
        match self.unit {
            Unit::Items { one } => {
                let noun = if count == 1 { one } else { &self.what };
                write!(f, "{count} {noun}")
            }
            Unit::Of { prefix, one, many } => {
                let unit = if count == 1 { one } else { many };
                write!(f, "{} ({prefix}{count} {unit})", self.what)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_read_as_english() {
        let mut r = ReadReport::default();
        assert!(r.is_empty());
        assert_eq!(r.to_string(), "nothing");
        r.push(Skipped::items("vertex normals", "vertex normal", 0));
        assert!(r.is_empty());
        r.push(Skipped::items("vertex normals", "vertex normal", 1));
        assert_eq!(r.to_string(), "1 vertex normal");
        r.push(Skipped::of(
            "STL attribute bytes".into(),
            3,
            "non-zero on ",
            "facet",
            "facets",
        ));
        assert_eq!(
            r.to_string(),
            "1 vertex normal and STL attribute bytes (non-zero on 3 facets)"
        );
        r.push(Skipped::of(
            "element `edge`".into(),
            1,
            "",
            "entry",
            "entries",
        ));
        assert_eq!(
            r.to_string(),
            "1 vertex normal, STL attribute bytes (non-zero on 3 facets) and element `edge` \
             (1 entry)"
        );
    }
}
