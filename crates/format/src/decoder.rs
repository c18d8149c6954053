//! The reader: a sans-IO [`StreamingDecoder`] fed chunk by chunk, and [`parse`] (a slice) and
//! [`read_from`] (any `Read`) built on it, so all three accept and refuse the same streams
//! (docs/format.md §1–§5, §7).
//!
//! Invariants: every byte is consumed exactly once through one state machine, so results do
//! not depend on chunking; nothing is reserved from a declared length alone (buffers grow with
//! the bytes actually received, after the length passed [`Limits`]); no recursion.

use std::io::{ErrorKind, Read};
use std::mem;

use byteorder::{ByteOrder, LittleEndian};

use crate::container::{Container, Section, SectionKind};
use crate::error::{Error, FormatError};
use crate::header::{check_preamble, decode_body, Header, Version, MAX_HEADER_LEN, PREAMBLE_LEN};
use crate::limits::Limits;
use crate::varint::VarintAcc;

/// What a call to [`StreamingDecoder::update`] reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    /// The chunk was consumed; feed more bytes.
    NeedMore,
    /// The header was read and checked; see [`StreamingDecoder::header`].
    HeaderReady,
    /// A section was read and its CRC checked; it is the last of
    /// [`StreamingDecoder::sections`]. Unknown optional sections are dropped without an event.
    SectionReady(SectionKind),
    /// The end marker was read; the stream is complete.
    Done,
}

#[derive(Debug)]
enum State {
    Preamble {
        bytes: [u8; PREAMBLE_LEN],
        got: usize,
    },
    HeaderLen(VarintAcc),
    /// Collecting the header body and its CRC (`len + 4` bytes) in `buf`.
    HeaderBody {
        len: usize,
    },
    /// Start of a section or the end marker.
    Tag(VarintAcc),
    Len {
        kind: SectionKind,
        acc: VarintAcc,
    },
    Payload {
        kind: SectionKind,
        left: u64,
        keep: bool,
    },
    Crc {
        kind: SectionKind,
        bytes: [u8; 4],
        got: usize,
        keep: bool,
    },
    Done,
    Failed,
}

/// A sans-IO decoder: feed it chunks as they arrive, in any sizes; results do not depend on
/// how the stream is split.
///
/// ```
/// use whet_format::{Container, Header, Limits, Mode, Progress, SectionKind, StreamingDecoder};
///
/// let bytes = Container::new(Header::new(Mode::Exact, 3, 1))
///     .with_section(SectionKind::CONNECTIVITY, vec![1, 2, 3])
///     .to_bytes()?;
/// let mut decoder = StreamingDecoder::new(Limits::DEFAULT);
/// let mut events = Vec::new();
/// for chunk in bytes.chunks(5) {
///     let mut rest = chunk;
///     while !rest.is_empty() {
///         let (used, progress) = decoder.update(rest)?;
///         rest = &rest[used..];
///         events.push(progress);
///     }
/// }
/// assert!(events.contains(&Progress::SectionReady(SectionKind::CONNECTIVITY)));
/// assert_eq!(events.last(), Some(&Progress::Done));
/// let container = decoder.finish()?;
/// assert_eq!(container.section(SectionKind::CONNECTIVITY), Some(&[1, 2, 3][..]));
/// # Ok::<(), whet_format::Error>(())
/// ```
#[derive(Debug)]
pub struct StreamingDecoder {
    limits: Limits,
    state: State,
    /// Bytes consumed so far.
    offset: u64,
    crc: crc32fast::Hasher,
    /// Header body while in `HeaderBody`, then the payload of the section being read.
    buf: Vec<u8>,
    version: Version,
    header: Option<Header>,
    header_taken: bool,
    sections: Vec<Section>,
    last_tag: u64,
    /// Declared stream length; meaningful once the header is read.
    declared_len: u64,
    /// Bytes kept so far (header body plus kept payloads), held against `max_alloc_bytes`.
    kept: u64,
}

impl Default for StreamingDecoder {
    fn default() -> Self {
        StreamingDecoder::new(Limits::DEFAULT)
    }
}

impl StreamingDecoder {
    /// A decoder at the start of a stream.
    pub fn new(limits: Limits) -> Self {
        StreamingDecoder {
            limits,
            state: State::Preamble {
                bytes: [0; PREAMBLE_LEN],
                got: 0,
            },
            offset: 0,
            crc: crc32fast::Hasher::new(),
            buf: Vec::new(),
            version: Version::CURRENT,
            header: None,
            header_taken: false,
            sections: Vec::new(),
            last_tag: 0,
            declared_len: 0,
            kept: 0,
        }
    }

    /// Consumes bytes from `chunk` up to the next event and returns how many it consumed and
    /// the event. Call again with the rest of the chunk after an event; [`Progress::NeedMore`]
    /// means the whole chunk was consumed.
    ///
    /// After [`Progress::Done`], any further byte is [`FormatError::TrailingBytes`]. After an
    /// error the decoder is spent and every call fails with [`Error::Parameter`].
    pub fn update(&mut self, chunk: &[u8]) -> Result<(usize, Progress), Error> {
        let mut used = 0;
        match self.run(chunk, &mut used) {
            Ok(progress) => Ok((used, progress)),
            Err(e) => {
                self.state = State::Failed;
                Err(e)
            }
        }
    }

    /// The header, once [`Progress::HeaderReady`] was returned (and until taken).
    pub fn header(&self) -> Option<&Header> {
        self.header.as_ref()
    }

    /// Takes the header out of the decoder; [`StreamingDecoder::finish`] then fails.
    pub fn take_header(&mut self) -> Option<Header> {
        let h = self.header.take();
        self.header_taken |= h.is_some();
        h
    }

    /// The sections read so far and not taken.
    pub fn sections(&self) -> &[Section] {
        &self.sections
    }

    /// Takes the sections read so far (to process them before the stream ends); they are then
    /// missing from [`StreamingDecoder::finish`]'s container. Their bytes stay counted
    /// against `max_alloc_bytes`.
    pub fn take_sections(&mut self) -> Vec<Section> {
        mem::take(&mut self.sections)
    }

    /// True once the end marker was read.
    pub fn is_done(&self) -> bool {
        matches!(self.state, State::Done)
    }

    /// Bytes consumed so far.
    pub fn bytes_consumed(&self) -> u64 {
        self.offset
    }

    /// The stream length the header declares, once it is read.
    pub fn declared_len(&self) -> Option<u64> {
        (self.header.is_some() || self.header_taken).then_some(self.declared_len)
    }

    /// The header and the sections not taken.
    ///
    /// Errors: [`Error::Truncated`] before [`Progress::Done`], naming where the input ended;
    /// [`Error::Parameter`] after an earlier error or when the header was taken.
    pub fn finish(self) -> Result<Container, Error> {
        let what = match &self.state {
            State::Done => {
                return match self.header {
                    Some(header) => Ok(Container {
                        header,
                        sections: self.sections,
                    }),
                    None => Err(Error::Parameter(
                        "finish() after take_header(): the header is gone".to_string(),
                    )),
                };
            }
            State::Failed => {
                return Err(Error::Parameter(
                    "finish() after the decoder returned an error".to_string(),
                ))
            }
            State::Preamble { .. } => "inside the magic and version".to_string(),
            State::HeaderLen(_) => "inside the header length".to_string(),
            State::HeaderBody { .. } => "inside the header".to_string(),
            State::Tag(acc) if acc.is_empty() => "before the end marker".to_string(),
            State::Tag(_) => "inside a section tag".to_string(),
            State::Len { kind, .. } => format!("inside the length of {kind}"),
            State::Payload { kind, .. } => format!("inside the payload of {kind}"),
            State::Crc { kind, .. } => format!("inside the checksum of {kind}"),
        };
        Err(Error::Truncated {
            offset: self.offset,
            what,
        })
    }

    fn run(&mut self, chunk: &[u8], used: &mut usize) -> Result<Progress, Error> {
        loop {
            let rest = chunk.get(*used..).unwrap_or_default();
            match self.state {
                State::Done if rest.is_empty() => return Ok(Progress::Done),
                State::Done => {
                    return Err(FormatError::TrailingBytes {
                        offset: self.offset,
                    }
                    .into())
                }
                State::Failed => {
                    return Err(Error::Parameter(
                        "update() after the decoder returned an error".to_string(),
                    ))
                }
                _ if rest.is_empty() => return Ok(Progress::NeedMore),
                _ => {}
            }
            let (n, progress) = self.step(rest)?;
            *used += n;
            self.offset += n as u64;
            if let Some(progress) = progress {
                return Ok(progress);
            }
        }
    }

    /// Advances through non-empty `rest`; returns the bytes consumed and any event.
    fn step(&mut self, rest: &[u8]) -> Result<(usize, Option<Progress>), Error> {
        let Some(&byte) = rest.first() else {
            return Ok((0, None));
        };
        // Offset just after `byte`, for the states that consume one byte.
        let after = self.offset + 1;
        match &mut self.state {
            State::Preamble { bytes, got } => {
                if let Some(slot) = bytes.get_mut(*got) {
                    *slot = byte;
                }
                *got += 1;
                self.crc.update(&[byte]);
                check_preamble(bytes.get(..*got).unwrap_or_default())?;
                if *got == PREAMBLE_LEN {
                    self.version = Version::new(bytes[4], bytes[5]);
                    self.state = State::HeaderLen(VarintAcc::default());
                }
            }
            State::HeaderLen(acc) => {
                self.crc.update(&[byte]);
                if let Some(len) = acc.push(byte)? {
                    if len > MAX_HEADER_LEN {
                        return Err(FormatError::HeaderTooLong(len).into());
                    }
                    self.limits.check_section(len)?;
                    self.limits.check_alloc(len)?;
                    self.kept = len;
                    // `len` ≤ 65 535 (checked above), so it fits usize.
                    self.state = State::HeaderBody { len: len as usize };
                }
            }
            State::HeaderBody { len } => {
                let len = *len;
                let take = (len + 4).saturating_sub(self.buf.len()).min(rest.len());
                self.buf
                    .extend_from_slice(rest.get(..take).unwrap_or_default());
                if self.buf.len() == len + 4 {
                    self.finish_header(len, self.offset + take as u64)?;
                    return Ok((take, Some(Progress::HeaderReady)));
                }
                return Ok((take, None));
            }
            State::Tag(acc) => {
                if acc.is_empty() {
                    if self.offset >= self.declared_len {
                        return Err(FormatError::MissingEndMarker {
                            offset: self.offset,
                        }
                        .into());
                    }
                    self.crc = crc32fast::Hasher::new();
                }
                self.crc.update(&[byte]);
                if let Some(tag) = acc.push(byte)? {
                    return self.start_section(tag, after).map(|p| (1, p));
                }
            }
            State::Len { kind, acc } => {
                self.crc.update(&[byte]);
                if let Some(len) = acc.push(byte)? {
                    let kind = *kind;
                    self.start_payload(kind, len, after)?;
                }
            }
            State::Payload { kind, left, keep } => {
                // `take` ≤ rest.len(), so it fits usize.
                let take = (*left).min(rest.len() as u64) as usize;
                let data = rest.get(..take).unwrap_or_default();
                self.crc.update(data);
                if *keep {
                    self.buf.extend_from_slice(data);
                }
                *left -= take as u64;
                if *left == 0 {
                    let (kind, keep) = (*kind, *keep);
                    self.state = State::Crc {
                        kind,
                        bytes: [0; 4],
                        got: 0,
                        keep,
                    };
                }
                return Ok((take, None));
            }
            State::Crc {
                kind,
                bytes,
                got,
                keep,
            } => {
                if let Some(slot) = bytes.get_mut(*got) {
                    *slot = byte;
                }
                *got += 1;
                if *got == 4 {
                    let (kind, keep) = (*kind, *keep);
                    let stored = LittleEndian::read_u32(bytes);
                    let computed = mem::take(&mut self.crc).finalize();
                    if stored != computed {
                        return Err(Error::ChecksumMismatch {
                            section: kind.to_string(),
                            stored,
                            computed,
                        });
                    }
                    self.state = State::Tag(VarintAcc::default());
                    if keep {
                        let payload = mem::take(&mut self.buf);
                        self.sections.push(Section { kind, payload });
                        return Ok((1, Some(Progress::SectionReady(kind))));
                    }
                }
            }
            State::Done | State::Failed => return Ok((0, None)),
        }
        Ok((1, None))
    }

    /// Checks the header CRC, decodes the body and frees the buffer; `end` is the offset just
    /// after the header CRC.
    fn finish_header(&mut self, len: usize, end: u64) -> Result<(), Error> {
        let buf = mem::take(&mut self.buf);
        // Called once `buf` holds exactly `len + 4` bytes, so `crc` is 4 bytes long.
        let (body, crc) = buf.split_at(len.min(buf.len()));
        self.crc.update(body);
        let computed = mem::take(&mut self.crc).finalize();
        let stored = LittleEndian::read_u32(crc);
        if stored != computed {
            return Err(Error::ChecksumMismatch {
                section: "header".to_string(),
                stored,
                computed,
            });
        }
        let (header, body_len) = decode_body(body, self.version, &self.limits)?;
        self.declared_len = end
            .checked_add(body_len)
            .ok_or(FormatError::LengthOverflow)?;
        self.header = Some(header);
        self.state = State::Tag(VarintAcc::default());
        Ok(())
    }

    /// Handles a complete tag; `after` is the offset just after it.
    fn start_section(&mut self, tag: u64, after: u64) -> Result<Option<Progress>, Error> {
        if tag == 0 {
            if after != self.declared_len {
                return Err(FormatError::MisplacedEndMarker {
                    offset: after,
                    declared: self.declared_len,
                }
                .into());
            }
            self.state = State::Done;
            return Ok(Some(Progress::Done));
        }
        if tag <= self.last_tag {
            let previous = self.last_tag;
            return Err(if tag == previous {
                FormatError::DuplicateSection { tag }
            } else {
                FormatError::SectionOrder {
                    previous,
                    found: tag,
                }
            }
            .into());
        }
        self.last_tag = tag;
        let kind = SectionKind::new(tag);
        if !kind.is_known() && !kind.is_optional() {
            return Err(FormatError::UnknownRequiredSection { tag }.into());
        }
        self.state = State::Len {
            kind,
            acc: VarintAcc::default(),
        };
        Ok(None)
    }

    /// Checks a declared payload length before anything is read; `after` is the offset just
    /// after the length varint.
    fn start_payload(&mut self, kind: SectionKind, len: u64, after: u64) -> Result<(), Error> {
        self.limits.check_section(len)?;
        // The payload and its CRC must leave room for the end marker before the declared end.
        let end = after.checked_add(len).and_then(|e| e.checked_add(4));
        if end.is_none_or(|end| end >= self.declared_len) {
            return Err(FormatError::SectionOverrun {
                tag: kind.tag(),
                len,
            }
            .into());
        }
        let keep = kind.is_known();
        if keep {
            // Cannot overflow: both terms are below declared_len.
            self.kept += len;
            self.limits.check_alloc(self.kept)?;
        }
        self.buf = Vec::new();
        self.state = if len == 0 {
            State::Crc {
                kind,
                bytes: [0; 4],
                got: 0,
                keep,
            }
        } else {
            State::Payload {
                kind,
                left: len,
                keep,
            }
        };
        Ok(())
    }
}

/// Decodes a whole stream held in memory.
///
/// After the header, the length it declares is held against `data.len()`, so a stream that
/// claims more than it has is [`Error::Truncated`] (and one with more bytes is
/// [`FormatError::TrailingBytes`]) before any section is read. Errors: see docs/format.md §7.
pub fn parse(data: &[u8], limits: &Limits) -> Result<Container, Error> {
    let mut decoder = StreamingDecoder::new(*limits);
    let mut rest = data;
    loop {
        let (used, progress) = decoder.update(rest)?;
        rest = rest.get(used..).unwrap_or_default();
        match progress {
            Progress::HeaderReady => {
                let declared = decoder.declared_len;
                let have = data.len() as u64;
                if have < declared {
                    return Err(Error::Truncated {
                        offset: have,
                        what: format!("before the end of the {declared} bytes the header declares"),
                    });
                }
                if have > declared {
                    return Err(FormatError::TrailingBytes { offset: declared }.into());
                }
            }
            Progress::SectionReady(_) => {}
            Progress::NeedMore | Progress::Done => {
                if !rest.is_empty() {
                    decoder.update(rest)?;
                }
                return decoder.finish();
            }
        }
    }
}

/// Decodes a stream from `reader`, reading it to the end.
///
/// Reads in chunks and keeps only what [`Limits`] allow; bytes after the end marker are
/// [`FormatError::TrailingBytes`], so the reader must end with the stream. Accepts and refuses
/// the same streams as [`parse`]; `Interrupted` reads are retried.
pub fn read_from<R: Read>(mut reader: R, limits: &Limits) -> Result<Container, Error> {
    let mut decoder = StreamingDecoder::new(*limits);
    let mut buf = [0; 8192];
    loop {
        let n = match reader.read(&mut buf) {
            Ok(n) => n,
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            Err(e) => return Err(e.into()),
        };
        if n == 0 {
            return decoder.finish();
        }
        let mut rest = buf.get(..n).unwrap_or_default();
        while !rest.is_empty() {
            let (used, _) = decoder.update(rest)?;
            rest = rest.get(used..).unwrap_or_default();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::header::{tag, Mode};
    use crate::varint::write_varint;

    /// docs/format.md §8, byte for byte.
    const SPEC_EXAMPLE: [u8; 26] = [
        0x57, 0x48, 0x45, 0x54, 0x01, 0x00, 0x06, 0x00, 0x04, 0x04, 0x09, 0x10, 0x0C, 0x21, 0x50,
        0xEE, 0x18, 0x02, 0x02, 0xAA, 0xBB, 0x9E, 0xFD, 0x92, 0x80, 0x00,
    ];

    fn example() -> Container {
        Container::new(Header::new(Mode::Exact, 4, 4).with(tag::QUANT_BITS, 12u64))
            .with_section(SectionKind::CONNECTIVITY, vec![0xAA, 0xBB])
    }

    /// A stream with the given header body and raw bytes after the header, CRCs computed.
    fn raw(body: &[u8], after: &[u8]) -> Vec<u8> {
        let mut out = b"WHET\x01\x00".to_vec();
        write_varint(&mut out, body.len() as u64);
        out.extend_from_slice(body);
        let crc = crc32fast::hash(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        out.extend_from_slice(after);
        out
    }

    fn section(tag: u8, payload: &[u8]) -> Vec<u8> {
        let mut s = vec![tag, payload.len() as u8];
        s.extend_from_slice(payload);
        let crc = crc32fast::hash(&s);
        s.extend_from_slice(&crc.to_le_bytes());
        s
    }

    #[test]
    fn example_stream_matches_spec() {
        assert_eq!(example().to_bytes().unwrap(), SPEC_EXAMPLE);
        assert_eq!(parse(&SPEC_EXAMPLE, &Limits::DEFAULT).unwrap(), example());
        assert_eq!(
            crc32fast::hash(b"123456789"),
            0xCBF4_3926,
            "docs/format.md §2"
        );
    }

    #[test]
    fn events_in_order() {
        let bytes = example()
            .with_section(SectionKind::new(3), vec![9; 3])
            .with_section(SectionKind::GEOMETRY, vec![])
            .to_bytes()
            .unwrap();
        let mut d = StreamingDecoder::default();
        let mut rest = &bytes[..];
        let mut events = Vec::new();
        while !rest.is_empty() {
            let (used, p) = d.update(rest).unwrap();
            rest = &rest[used..];
            events.push(p);
            if p == Progress::HeaderReady {
                assert_eq!(d.declared_len(), Some(bytes.len() as u64));
            }
        }
        assert_eq!(
            events,
            [
                Progress::HeaderReady,
                Progress::SectionReady(SectionKind::CONNECTIVITY),
                // the unknown optional section 3 is dropped without an event
                Progress::SectionReady(SectionKind::GEOMETRY),
                Progress::Done,
            ]
        );
        assert!(d.is_done());
        assert_eq!(d.update(&[]).unwrap(), (0, Progress::Done));
        assert_eq!(d.bytes_consumed(), bytes.len() as u64);
        let c = d.finish().unwrap();
        assert_eq!(c.sections.len(), 2);
    }

    #[test]
    fn bytes_after_done_are_trailing() {
        let mut d = StreamingDecoder::default();
        let mut bytes = SPEC_EXAMPLE.to_vec();
        bytes.push(0);
        let mut rest = &bytes[..];
        loop {
            match d.update(rest) {
                Ok((used, _)) => rest = &rest[used..],
                Err(e) => {
                    assert!(
                        matches!(e, Error::Format(FormatError::TrailingBytes { offset: 26 })),
                        "{e}"
                    );
                    break;
                }
            }
        }
        assert!(matches!(d.update(&[]), Err(Error::Parameter(_))), "spent");
        assert!(matches!(d.finish(), Err(Error::Parameter(_))));
    }

    #[test]
    fn take_accessors() {
        let mut d = StreamingDecoder::default();
        let (used, p) = d.update(&SPEC_EXAMPLE).unwrap();
        assert_eq!(p, Progress::HeaderReady);
        assert_eq!(d.take_header(), Some(example().header));
        assert!(d.header().is_none());
        let (used2, p) = d.update(&SPEC_EXAMPLE[used..]).unwrap();
        assert_eq!(p, Progress::SectionReady(SectionKind::CONNECTIVITY));
        assert_eq!(d.take_sections(), example().sections);
        assert!(d.sections().is_empty());
        let (_, p) = d.update(&SPEC_EXAMPLE[used + used2..]).unwrap();
        assert_eq!(p, Progress::Done);
        assert!(
            matches!(d.finish(), Err(Error::Parameter(_))),
            "header was taken"
        );
    }

    #[test]
    fn zero_body_len_has_no_end_marker() {
        let bytes = raw(&[0, 0, 0, 0], &[0]);
        let err = parse(&bytes, &Limits::DEFAULT).unwrap_err();
        assert!(
            matches!(err, Error::Format(FormatError::TrailingBytes { .. })),
            "{err}"
        );
        let err = crate::fuzz::parse_chunked(&bytes, 1, &Limits::DEFAULT).unwrap_err();
        assert!(
            matches!(err, Error::Format(FormatError::MissingEndMarker { .. })),
            "{err}"
        );
    }

    #[test]
    fn misplaced_end_marker_and_overrun() {
        // body_len 2 but the end marker comes first.
        let err = parse(&raw(&[0, 0, 0, 2], &[0, 0]), &Limits::DEFAULT).unwrap_err();
        assert!(
            matches!(err, Error::Format(FormatError::MisplacedEndMarker { .. })),
            "{err}"
        );
        // A section that leaves no room for the end marker.
        let s = section(2, &[1]);
        let err = parse(&raw(&[0, 0, 0, s.len() as u8], &s), &Limits::DEFAULT).unwrap_err();
        assert!(
            matches!(
                err,
                Error::Format(FormatError::SectionOverrun { tag: 2, len: 1 })
            ),
            "{err}"
        );
    }

    #[test]
    fn skipped_sections_are_checksummed() {
        let mut s = section(7, &[1, 2]);
        s[2] ^= 1;
        s.push(0);
        let err = parse(&raw(&[0, 0, 0, s.len() as u8], &s), &Limits::DEFAULT).unwrap_err();
        assert!(
            matches!(&err, Error::ChecksumMismatch { section, .. } if section == "section 7"),
            "{err}"
        );
    }

    #[test]
    fn kept_bytes_are_limited() {
        let bytes = example()
            .with_section(SectionKind::GEOMETRY, vec![0; 100])
            .to_bytes()
            .unwrap();
        let limits = Limits::DEFAULT.with_max_alloc_bytes(100);
        let err = parse(&bytes, &limits).unwrap_err();
        assert!(
            matches!(
                err,
                Error::LimitExceeded {
                    what: "allocation (bytes)",
                    limit: 100,
                    value: 108
                }
            ),
            "{err}"
        );
        let limits = Limits::DEFAULT.with_max_section_bytes(99);
        let err = parse(&bytes, &limits).unwrap_err();
        assert!(
            matches!(err, Error::LimitExceeded { value: 100, .. }),
            "{err}"
        );
        let limits = Limits::DEFAULT.with_max_faces(3);
        let err = parse(&bytes, &limits).unwrap_err();
        assert!(
            matches!(
                err,
                Error::LimitExceeded {
                    what: "triangle count",
                    ..
                }
            ),
            "{err}"
        );
    }

    #[test]
    fn header_too_long() {
        let mut bytes = b"WHET\x01\x00".to_vec();
        write_varint(&mut bytes, MAX_HEADER_LEN + 1);
        for err in [
            parse(&bytes, &Limits::DEFAULT).unwrap_err(),
            crate::peek_header(&bytes).unwrap_err(),
        ] {
            assert!(
                matches!(err, Error::Format(FormatError::HeaderTooLong(65_536))),
                "{err}"
            );
        }
    }

    #[test]
    fn truncation_messages() {
        for (len, what) in [
            (3, "inside the magic and version"),
            (6, "inside the header length"),
            (10, "inside the header"),
            (17, "before the end"),
        ] {
            let mut d = StreamingDecoder::default();
            let mut rest = &SPEC_EXAMPLE[..len];
            while !rest.is_empty() {
                let (used, _) = d.update(rest).unwrap();
                rest = &rest[used..];
            }
            let err = d.finish().unwrap_err();
            assert!(err.to_string().contains(what), "{len}: {err}");
        }
        let mut d = StreamingDecoder::default();
        let (used, _) = d.update(&SPEC_EXAMPLE[..20]).unwrap();
        d.update(&SPEC_EXAMPLE[used..20]).unwrap();
        let err = d.finish().unwrap_err();
        assert_eq!(
            err.to_string(),
            "stream is truncated: it ends at byte 20, inside the payload of connectivity"
        );
    }
}
