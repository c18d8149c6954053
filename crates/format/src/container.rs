//! Sections and the whole container, and the writer (docs/format.md §1, §4).

use std::fmt;
use std::io::Write;

use byteorder::{LittleEndian, WriteBytesExt};

use crate::error::Error;
use crate::header::{encode_header, Header};
use crate::varint::{varint_len, write_varint};

/// A section tag (docs/format.md §4). Odd tags are optional; 0 is the end marker.
///
/// Any tag can be represented, so a writer can emit optional sections this crate does not
/// know; readers drop unknown optional sections and refuse unknown required ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SectionKind(u64);

impl SectionKind {
    /// Optional: key/value metadata.
    pub const METADATA: SectionKind = SectionKind(1);
    /// Required: entropy-coded CLERS symbols and handle records.
    pub const CONNECTIVITY: SectionKind = SectionKind(2);
    /// Required: entropy-coded position residuals or swing angles.
    pub const GEOMETRY: SectionKind = SectionKind(4);
    /// Optional: per-vertex attributes.
    pub const ATTRIBUTES: SectionKind = SectionKind(5);
    /// Required (subdiv mode): the control mesh, a complete exact-mode stream.
    pub const CONTROL: SectionKind = SectionKind(6);
    /// Required (subdiv mode): the quantized sharpness of every control edge.
    pub const SHARPNESS: SectionKind = SectionKind(8);

    /// Every section kind of format 1.0, in tag order.
    pub const KNOWN: [SectionKind; 6] = [
        SectionKind::METADATA,
        SectionKind::CONNECTIVITY,
        SectionKind::GEOMETRY,
        SectionKind::ATTRIBUTES,
        SectionKind::CONTROL,
        SectionKind::SHARPNESS,
    ];

    /// The kind with wire tag `tag`, known or not.
    pub const fn new(tag: u64) -> Self {
        SectionKind(tag)
    }

    /// The wire tag.
    pub const fn tag(self) -> u64 {
        self.0
    }

    /// True for odd tags, which a reader that does not know them skips.
    pub const fn is_optional(self) -> bool {
        self.0 & 1 == 1
    }

    /// True for the kinds in [`SectionKind::KNOWN`].
    pub const fn is_known(self) -> bool {
        self.name().is_some()
    }

    /// Lower-case name of a known kind, as in docs/format.md.
    pub const fn name(self) -> Option<&'static str> {
        match self.0 {
            1 => Some("metadata"),
            2 => Some("connectivity"),
            4 => Some("geometry"),
            5 => Some("attributes"),
            6 => Some("control"),
            8 => Some("sharpness"),
            _ => None,
        }
    }
}

impl fmt::Display for SectionKind {
    /// The name, or `section <tag>` for an unknown kind.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.name() {
            Some(name) => f.write_str(name),
            None => write!(f, "section {}", self.0),
        }
    }
}

/// One section: its kind and its payload.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Section {
    /// Kind (tag).
    pub kind: SectionKind,
    /// Payload bytes, opaque to the container.
    pub payload: Vec<u8>,
}

impl Section {
    /// A section of `kind` holding `payload`.
    pub fn new(kind: SectionKind, payload: impl Into<Vec<u8>>) -> Self {
        Section {
            kind,
            payload: payload.into(),
        }
    }
}

/// A whole stream: header and sections, in increasing tag order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Container {
    /// The header.
    pub header: Header,
    /// The sections, in strictly increasing tag order (as [`Container::set_section`] keeps
    /// them); the writer refuses any other order.
    pub sections: Vec<Section>,
}

impl Container {
    /// A container without sections.
    pub fn new(header: Header) -> Self {
        Container {
            header,
            sections: Vec::new(),
        }
    }

    /// Adds or replaces a section (builder form of [`Container::set_section`]).
    pub fn with_section(mut self, kind: SectionKind, payload: impl Into<Vec<u8>>) -> Self {
        self.set_section(kind, payload);
        self
    }

    /// Adds the section, or replaces the payload of the section of the same kind, keeping the
    /// sections in tag order.
    pub fn set_section(&mut self, kind: SectionKind, payload: impl Into<Vec<u8>>) {
        let payload = payload.into();
        match self.sections.binary_search_by_key(&kind, |s| s.kind) {
            Ok(i) => {
                if let Some(s) = self.sections.get_mut(i) {
                    s.payload = payload;
                }
            }
            Err(i) => self.sections.insert(i, Section { kind, payload }),
        }
    }

    /// The payload of the section of `kind`.
    pub fn section(&self, kind: SectionKind) -> Option<&[u8]> {
        self.sections
            .iter()
            .find(|s| s.kind == kind)
            .map(|s| s.payload.as_slice())
    }

    /// Bytes after the header: every section's framing and payload plus the end marker.
    fn body_len(&self) -> u64 {
        let sections: u64 = self
            .sections
            .iter()
            .map(|s| section_len(s.kind.tag(), s.payload.len() as u64))
            .sum();
        sections + 1
    }

    /// Checks what the format requires of sections and that our own reader would accept them.
    fn check_sections(&self) -> Result<(), Error> {
        let mut previous = 0;
        for s in &self.sections {
            let tag = s.kind.tag();
            if tag <= previous {
                return Err(Error::Parameter(if tag == 0 {
                    "section tag 0 is the end marker".to_string()
                } else {
                    format!(
                        "section {tag} follows section {previous}: sections must be unique and \
                         in increasing tag order"
                    )
                }));
            }
            if !s.kind.is_known() && !s.kind.is_optional() {
                return Err(Error::Parameter(format!(
                    "unknown section {tag} must be optional (odd) to be written"
                )));
            }
            previous = tag;
        }
        Ok(())
    }

    /// Writes the stream to `out` without copying payloads.
    ///
    /// Errors: [`Error::Parameter`] when the header version is not 1.x, a header field or
    /// section is not writable (unknown required tag, wrong type for a known tag, sections out
    /// of order), or the header body exceeds 65 535 bytes; [`Error::Io`] from `out`.
    pub fn write_to<W: Write>(&self, mut out: W) -> Result<(), Error> {
        self.check_sections()?;
        out.write_all(&encode_header(&self.header, self.body_len())?)?;
        let mut frame = Vec::with_capacity(20);
        for s in &self.sections {
            frame.clear();
            write_varint(&mut frame, s.kind.tag());
            write_varint(&mut frame, s.payload.len() as u64);
            let mut crc = crc32fast::Hasher::new();
            crc.update(&frame);
            crc.update(&s.payload);
            out.write_all(&frame)?;
            out.write_all(&s.payload)?;
            out.write_u32::<LittleEndian>(crc.finalize())?;
        }
        out.write_all(&[END_MARKER])?;
        Ok(())
    }

    /// The stream as bytes; errors as [`Container::write_to`] (never `Io`).
    pub fn to_bytes(&self) -> Result<Vec<u8>, Error> {
        let mut out = Vec::with_capacity(64 + usize::try_from(self.body_len()).unwrap_or(0));
        self.write_to(&mut out)?;
        Ok(out)
    }
}

/// The end marker: a section tag of 0.
pub(crate) const END_MARKER: u8 = 0;

/// Framing plus payload bytes of one section.
pub(crate) fn section_len(tag: u64, payload_len: u64) -> u64 {
    varint_len(tag) as u64 + varint_len(payload_len) as u64 + payload_len + 4
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::header::Mode;

    fn header() -> Header {
        Header::new(Mode::Exact, 3, 1)
    }

    #[test]
    fn kinds() {
        assert!(SectionKind::METADATA.is_optional());
        assert!(!SectionKind::CONNECTIVITY.is_optional());
        assert_eq!(SectionKind::GEOMETRY.to_string(), "geometry");
        assert_eq!(SectionKind::new(9).to_string(), "section 9");
        assert!(!SectionKind::new(9).is_known());
        assert!(SectionKind::KNOWN.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn set_section_keeps_order() {
        let c = Container::new(header())
            .with_section(SectionKind::GEOMETRY, vec![2])
            .with_section(SectionKind::CONNECTIVITY, vec![1])
            .with_section(SectionKind::GEOMETRY, vec![3]);
        let kinds: Vec<_> = c.sections.iter().map(|s| s.kind).collect();
        assert_eq!(kinds, [SectionKind::CONNECTIVITY, SectionKind::GEOMETRY]);
        assert_eq!(c.section(SectionKind::GEOMETRY), Some(&[3][..]));
        assert_eq!(c.section(SectionKind::METADATA), None);
    }

    #[test]
    fn writer_refuses_bad_sections() {
        let mut c = Container::new(header());
        c.sections.push(Section::new(SectionKind::GEOMETRY, vec![]));
        c.sections
            .push(Section::new(SectionKind::CONNECTIVITY, vec![]));
        assert!(matches!(c.to_bytes(), Err(Error::Parameter(_))), "order");
        c.sections = vec![Section::new(SectionKind::new(0), vec![])];
        assert!(
            matches!(c.to_bytes(), Err(Error::Parameter(_))),
            "end marker"
        );
        c.sections = vec![Section::new(SectionKind::new(10), vec![])];
        assert!(
            matches!(c.to_bytes(), Err(Error::Parameter(_))),
            "unknown required"
        );
        c.sections = vec![Section::new(SectionKind::new(9), vec![])];
        assert!(c.to_bytes().is_ok(), "unknown optional is writable");
    }

    #[test]
    fn writer_refuses_bad_header() {
        let c = Container::new(header().with_version(crate::Version::new(2, 0)));
        let err = c.to_bytes().unwrap_err();
        assert!(
            err.to_string().contains("cannot write format version 2.0"),
            "{err}"
        );
        let c = Container::new(header().with(crate::tag::QUANT_BITS, 1.5));
        assert!(matches!(c.to_bytes(), Err(Error::Parameter(_))));
        let c = Container::new(header().with(14, 1u64));
        assert!(
            matches!(c.to_bytes(), Err(Error::Parameter(_))),
            "unknown required"
        );
        let c = Container::new(header().with(crate::tag::ENCODER, vec![b'x'; 70_000]));
        assert!(
            matches!(c.to_bytes(), Err(Error::Parameter(_))),
            "header too long"
        );
        let c = Container::new(header().with(u64::MAX, 1u64));
        assert!(
            matches!(c.to_bytes(), Err(Error::Parameter(_))),
            "tag too large"
        );
    }

    #[test]
    fn length_accounting() {
        let c = Container::new(header())
            .with_section(SectionKind::CONNECTIVITY, vec![7; 200])
            .with_section(SectionKind::new(1001), vec![]);
        let bytes = c.to_bytes().unwrap();
        let info = crate::peek_header(&bytes).unwrap();
        assert_eq!(info.total_len, bytes.len() as u64);
        assert_eq!(bytes.last(), Some(&END_MARKER));
    }
}
