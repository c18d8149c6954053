//! Helpers of the text formats: a line reader over any `BufRead` that counts lines and bounds
//! line length, whitespace tokens, number parsing and shortest round-trip float printing.

use std::io::{self, BufRead, Read, Write};

use whet_mesh::DVec3;

use crate::Error;

/// Longest line the text readers accept, in bytes (64 MiB): a file without line breaks is
/// refused instead of being buffered whole.
pub(crate) const MAX_LINE: usize = 1 << 26;

/// The UTF-8 byte order mark some Windows tools put at the start of text files.
pub(crate) const BOM: &[u8] = b"\xEF\xBB\xBF";

/// Reads a `BufRead` line by line into one reused buffer, counting 1-based line numbers.
///
/// Lines end at `\n`; a trailing `\r` is removed, and so is a byte order mark at the start of
/// the first line. Bytes need not be UTF-8: the formats' syntax is ASCII, and the callers check
/// each token they use.
pub(crate) struct LineReader<R> {
    reader: R,
    buf: Vec<u8>,
    start: usize,
    end: usize,
    line: usize,
    max_len: usize,
}

impl<R: BufRead> LineReader<R> {
    /// A reader whose lines may be up to [`MAX_LINE`] bytes long.
    pub(crate) fn new(reader: R) -> Self {
        Self::with_max_len(reader, MAX_LINE)
    }

    /// A reader that refuses lines longer than `max_len` bytes with a parse error.
    pub(crate) fn with_max_len(reader: R, max_len: usize) -> Self {
        LineReader {
            reader,
            buf: Vec::new(),
            start: 0,
            end: 0,
            line: 0,
            max_len,
        }
    }

    /// Changes the longest accepted line.
    pub(crate) fn set_max_len(&mut self, max_len: usize) {
        self.max_len = max_len;
    }

    /// Number of the line last read (1-based; 0 before the first).
    pub(crate) fn line(&self) -> usize {
        self.line
    }

    /// Reads the next line; false at the end of the input.
    pub(crate) fn advance(&mut self) -> Result<bool, Error> {
        self.buf.clear();
        self.start = 0;
        self.end = 0;
        let limit = u64::try_from(self.max_len)
            .unwrap_or(u64::MAX)
            .saturating_add(1);
        let n = (&mut self.reader)
            .take(limit)
            .read_until(b'\n', &mut self.buf)?;
        if n == 0 {
            return Ok(false);
        }
        self.line += 1;
        let mut end = self.buf.len();
        if self.buf.last() == Some(&b'\n') {
            end -= 1;
        } else if end > self.max_len {
            return Err(Error::parse(
                self.line,
                format!("line is longer than {} bytes", self.max_len),
            ));
        }
        if end > 0 && self.buf[end - 1] == b'\r' {
            end -= 1;
        }
        // A BOM is made of bytes other than '\r' and '\n', so it lies within 0..end.
        if self.line == 1 && self.buf[..end].starts_with(BOM) {
            self.start = BOM.len();
        }
        self.end = end;
        Ok(true)
    }

    /// The line last read, without its line break (empty before the first line).
    pub(crate) fn current(&self) -> &[u8] {
        &self.buf[self.start..self.end]
    }

    /// Reads and returns the next line, or `None` at the end of the input.
    #[cfg(test)]
    pub(crate) fn next_line(&mut self) -> Result<Option<&[u8]>, Error> {
        if self.advance()? {
            Ok(Some(self.current()))
        } else {
            Ok(None)
        }
    }

    /// The underlying reader, positioned just after the last line read.
    pub(crate) fn into_inner(self) -> R {
        self.reader
    }
}

/// The first read of a [`LineBlocks`], before its buffer grows to a block.
const FIRST_READ: usize = 1 << 16;

/// How [`LineBlocks`] cuts its input into blocks and its readers cut a block into pieces.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Chunking {
    /// Bytes a block holds before it ends at a line break.
    pub block: usize,
    /// Longest line accepted, in bytes.
    pub max_line: usize,
    /// Bytes of a block one task takes (more, to end at a line break).
    pub piece: usize,
}

impl Chunking {
    /// Blocks of 4 MiB (large enough to split among threads, small enough that reading
    /// stays streaming), lines up to [`MAX_LINE`], pieces of 256 KiB.
    pub const DEFAULT: Chunking = Chunking {
        block: 1 << 22,
        max_line: MAX_LINE,
        piece: 1 << 18,
    };
}

/// Reads a `BufRead` in blocks of whole lines (about [`Chunking::block`] bytes; more when
/// one line is longer), so that the pieces of a block can be parsed in parallel, each line
/// where it lies in the block, without the copy per line [`LineReader`] makes. The caller
/// numbers the lines: it counts them as it parses.
///
/// A line longer than [`Chunking::max_line`] that a block would have to hold whole is refused
/// with the error [`LineReader`] gives it; one that a block holds (when blocks are larger than
/// that) is for the caller to refuse if it reads so far ([`line_spans`]).
pub(crate) struct LineBlocks<R> {
    reader: R,
    buf: Vec<u8>,
    /// `buf[..filled]` is read; `buf[consumed..filled]` is not yet handed out.
    filled: usize,
    consumed: usize,
    eof: bool,
    block: usize,
    max_line: usize,
    /// Whether a line ending in `\\` continues on the next ([`ends_statement`]): blocks then
    /// end only where a statement does.
    continued: bool,
    /// A read that failed after whole statements were read: those are handed out first,
    /// and the next call returns the error.
    failed: Option<Error>,
}

impl<R: BufRead> LineBlocks<R> {
    /// Blocks of `reader`'s lines; with `continued`, blocks end only at the end of a
    /// statement (OBJ's lines ending in `\\` continue on the next).
    pub(crate) fn new(reader: R, chunking: &Chunking, continued: bool) -> Self {
        LineBlocks {
            reader,
            buf: Vec::new(),
            filled: 0,
            consumed: 0,
            eof: false,
            // At least one byte, so that every read makes progress.
            block: chunking.block.max(1),
            max_line: chunking.max_line,
            continued,
            failed: None,
        }
    }

    /// The next block of whole lines (the last may lack its line break at the end of the
    /// input), or `None` at the end of the input; `first_line`, the number of its first
    /// line, names a line too long to hold.
    pub(crate) fn next_block(&mut self, first_line: usize) -> Result<Option<&[u8]>, Error> {
        if let Some(e) = self.failed.take() {
            return Err(e);
        }
        // Keep what follows the last line handed out.
        self.buf.copy_within(self.consumed..self.filled, 0);
        self.filled -= self.consumed;
        self.consumed = 0;
        // Read until the block holds `block` bytes and the end of a statement (a line break
        // unless lines continue), or the input ends.
        let mut last_end: Option<usize> = None;
        let mut searched = 0;
        // The search for lines too long: line breaks before `scanned` are found, and the
        // line in progress there starts at `line_start` (both only grow: each byte is
        // searched once however long the lines).
        let (mut scanned, mut line_start) = (0, 0);
        let end = loop {
            // Only the bytes read since the last search can hold later statement ends.
            let fresh = &self.buf[searched..self.filled];
            let ends = memchr::memrchr_iter(b'\n', fresh)
                .map(|i| searched + i)
                .find(|&i| !self.continued || ends_statement(&self.buf, i));
            last_end = ends.or(last_end);
            searched = self.filled;
            if self.eof {
                break self.filled;
            }
            if let (Some(i), true) = (last_end, self.filled >= self.block) {
                break i + 1;
            }
            // What follows the last statement end is more than a line's limit: if a line
            // there is too long, what comes before that statement is read first (it may hold
            // an error of its own), then the line is refused, at its number.
            let open = last_end.map_or(0, |i| i + 1);
            if self.filled - open > self.max_line {
                line_start = line_start.max(open);
                match self.first_long_line(scanned.max(open), line_start) {
                    Ok(start) => (scanned, line_start) = (self.filled, start),
                    Err(long) => {
                        if let Some(i) = last_end {
                            break i + 1;
                        }
                        let before = memchr::memchr_iter(b'\n', &self.buf[..long]).count();
                        return Err(Error::parse(
                            first_line + before,
                            format!("line is longer than {} bytes", self.max_line),
                        ));
                    }
                }
            }
            // Grow the buffer as the data comes, up to a block (a small file does not
            // take a block's memory).
            if self.filled == self.buf.len() {
                let grown = if self.filled < self.block {
                    (2 * self.filled).max(FIRST_READ).min(self.block)
                } else {
                    self.filled + self.block / 4
                };
                self.buf.resize(grown.max(self.filled + 1), 0);
            }
            let n = match read_some(&mut self.reader, &mut self.buf[self.filled..]) {
                Ok(n) => n,
                // What is read is handed out first (it may end the reading, or hold an
                // error of its own); the next block is the error.
                Err(e) => match last_end {
                    Some(i) => {
                        self.failed = Some(e);
                        break i + 1;
                    }
                    None => return Err(e),
                },
            };
            self.eof = n == 0;
            self.filled += n;
        };
        if end == 0 {
            return Ok(None);
        }
        self.consumed = end;
        Ok(Some(&self.buf[..end]))
    }

    /// The start of the first line longer than the limit, the unfinished last line included,
    /// as `Err`, searching the line breaks from `from` on, the line in progress there
    /// starting at `start`; or `Ok` with the start of the last line when none is.
    fn first_long_line(&self, from: usize, mut start: usize) -> Result<usize, usize> {
        for i in memchr::memchr_iter(b'\n', &self.buf[from..self.filled]) {
            if from + i - start > self.max_line {
                return Err(start);
            }
            start = from + i + 1;
        }
        if self.filled - start > self.max_line {
            return Err(start);
        }
        Ok(start)
    }
}

/// The pieces of `block` (whole lines, as [`LineBlocks`] gives them): ranges of about
/// `piece` bytes, each ending after a line break (one that ends a statement, with
/// `continued`) or at the block's end.
pub(crate) fn pieces(block: &[u8], piece: usize, continued: bool) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    while start < block.len() {
        let cut = (start + piece.max(1)).min(block.len());
        let stop = memchr::memchr_iter(b'\n', &block[cut..])
            .map(|i| cut + i)
            .find(|&i| !continued || ends_statement(block, i))
            .map_or(block.len(), |i| i + 1);
        out.push(start..stop);
        start = stop;
    }
    out
}

/// Whether the line break at `text[i]` ends a statement: the line it ends, without a
/// trailing `\r`, does not end in `\\` (OBJ's continuation, as [`LineReader`]'s lines are read).
pub(crate) fn ends_statement(text: &[u8], i: usize) -> bool {
    let line = &text[..i];
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    // A `\\` of the line itself: the line break before the line is not one.
    line.last() != Some(&b'\\')
}

/// The lines of `text` (whole lines: it ends after a line break or at the end of the
/// input) as byte ranges without their line break, in one search for the breaks (a search
/// per line costs a call and a set-up each, and most lines are some 30 bytes).
pub(crate) fn line_spans(text: &[u8]) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
    let last = (text.last().is_some_and(|&b| b != b'\n')).then_some(text.len());
    let mut start = 0;
    memchr::memchr_iter(b'\n', text)
        .chain(last)
        .map(move |stop| {
            let line = start..stop;
            start = stop + 1;
            line
        })
}

/// Whether `line` holds data: something before any `#` comment.
pub(crate) fn holds_data(line: &[u8]) -> bool {
    line.iter()
        .find(|b| !b.is_ascii_whitespace())
        .is_some_and(|&b| b != b'#')
}

/// One `read` of `reader` into `buf`, retried when interrupted.
fn read_some<R: Read>(reader: &mut R, buf: &mut [u8]) -> Result<usize, Error> {
    loop {
        match reader.read(buf) {
            Ok(n) => return Ok(n),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e.into()),
        }
    }
}

/// A stream of whitespace-separated tokens that may span lines (the PLY ascii body).
pub(crate) struct TokenReader<R> {
    lines: LineReader<R>,
    pos: usize,
}

impl<R: BufRead> TokenReader<R> {
    /// Tokens of the lines after the one `lines` read last.
    pub(crate) fn new(lines: LineReader<R>) -> Self {
        let pos = lines.current().len();
        TokenReader { lines, pos }
    }

    /// Line number of the token last returned.
    pub(crate) fn line(&self) -> usize {
        self.lines.line()
    }

    /// The next token, or `None` at the end of the input.
    pub(crate) fn next_token(&mut self) -> Result<Option<&[u8]>, Error> {
        loop {
            let line = self.lines.current();
            let rest = line.get(self.pos..).unwrap_or_default();
            if let Some(skip) = rest.iter().position(|b| !b.is_ascii_whitespace()) {
                let start = self.pos + skip;
                let len = line[start..]
                    .iter()
                    .position(u8::is_ascii_whitespace)
                    .unwrap_or(line.len() - start);
                self.pos = start + len;
                return Ok(Some(&self.lines.current()[start..start + len]));
            }
            if !self.lines.advance()? {
                return Ok(None);
            }
            self.pos = 0;
        }
    }
}

/// The part of a line before a `#` comment.
pub(crate) fn strip_comment(line: &[u8]) -> &[u8] {
    match line.iter().position(|&b| b == b'#') {
        Some(i) => &line[..i],
        None => line,
    }
}

/// The whitespace-separated tokens of a line.
pub(crate) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(u8::is_ascii_whitespace)
        .filter(|t| !t.is_empty())
}

/// Parses a decimal float (Rust syntax: `1`, `-2.5`, `1e-7`, `.5`, `inf`, `NaN`).
pub(crate) fn parse_f64(token: &[u8]) -> Option<f64> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

/// Parses a decimal integer with an optional sign; `None` on anything else or overflow.
pub(crate) fn parse_i64(token: &[u8]) -> Option<i64> {
    let (negative, digits) = match token.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, token),
    };
    if digits.is_empty() {
        return None;
    }
    let mut value: i64 = 0;
    for &b in digits {
        if !b.is_ascii_digit() {
            return None;
        }
        let digit = i64::from(b - b'0');
        value = value.checked_mul(10)?;
        value = if negative {
            value.checked_sub(digit)?
        } else {
            value.checked_add(digit)?
        };
    }
    Some(value)
}

/// The next three tokens of `toks` as a point, when all three are there and parse as
/// floats (finite or not): the quick path of the readers' vertex lines, which leave any
/// other line to their token-by-token path.
pub(crate) fn plain_point(toks: &mut std::str::SplitAsciiWhitespace<'_>) -> Option<DVec3> {
    let (x, y, z) = (toks.next()?, toks.next()?, toks.next()?);
    Some(DVec3::new(
        x.parse().ok()?,
        y.parse().ok()?,
        z.parse().ok()?,
    ))
}

/// A token as it appears in the file, cut to a readable length, for error messages.
pub(crate) fn show(token: &[u8]) -> String {
    const MAX: usize = 40;
    let text = String::from_utf8_lossy(&token[..token.len().min(MAX)]).into_owned();
    if token.len() > MAX {
        format!("{text}...")
    } else {
        text
    }
}

/// Writes `x` in the shortest form that parses back to the same f64, byte for byte as `{}`
/// prints it, switching to exponent form (`{:e}`, also shortest) for magnitudes where plain
/// digits would be long.
///
/// Plain numbers come from `zmij` (in the build already through serde_json): `write!` spent
/// about 1 000 instructions per coordinate, most of a plain `whet decode` (a 3 MB OFF: 70 %
/// of its instructions). Both give the shortest digits that round-trip, the nearest of them
/// to the value, and both lay out magnitudes from 1e-5 to 1e16 in plain digits; `zmij` ends
/// an integer with `.0`, which is dropped. Ties are left to the standard library
/// ([`may_tie`]), and so are the rare magnitudes printed with an exponent. The tests
/// compare the two on a million values and around every power of ten.
pub(crate) fn write_f64<W: Write>(w: &mut W, x: f64) -> io::Result<()> {
    let a = x.abs();
    let plain = (1e-5..1e16).contains(&a);
    if !plain || may_tie(a) {
        return if plain || a == 0.0 {
            write!(w, "{x}")
        } else {
            write!(w, "{x:e}")
        };
    }
    let mut digits = zmij::Buffer::new();
    let text = digits.format_finite(x).as_bytes();
    w.write_all(text.strip_suffix(b".0").unwrap_or(text))
}

/// Writes `lead` (if any) and the three coordinates of `p`, separated by spaces, as one line
/// (`v x y z` in OBJ, `x y z` in OFF).
pub(crate) fn write_point_line<W: Write>(w: &mut W, lead: &[u8], p: DVec3) -> io::Result<()> {
    if !lead.is_empty() {
        w.write_all(lead)?;
        w.write_all(b" ")?;
    }
    write_f64(w, p.x)?;
    w.write_all(b" ")?;
    write_f64(w, p.y)?;
    w.write_all(b" ")?;
    write_f64(w, p.z)?;
    w.write_all(b"\n")
}

/// Writes a face line: `lead`, then the three indices each after a space, then a line break
/// (`3 a b c` in OFF and PLY, `f a b c` in OBJ), as `writeln!` would, without its
/// formatting machinery.
pub(crate) fn write_face_line<W: Write>(w: &mut W, lead: &[u8], ids: [u64; 3]) -> io::Result<()> {
    w.write_all(lead)?;
    let mut digits = itoa::Buffer::new();
    for id in ids {
        w.write_all(b" ")?;
        w.write_all(digits.format(id).as_bytes())?;
    }
    w.write_all(b"\n")
}

/// Whether two shortest digit strings of finite nonzero `a` can lie equally close to it,
/// where the standard library and `zmij` pick different ones (seen: 1.69e15,
/// whose spacing is 0.25). A tie needs the value's exact decimal expansion to be one digit
/// longer than the shortest, so at most 18 digits: `m 2^e` with `m` odd has `-e` decimals
/// when `e < 0` (over 25 of them make it longer), and is an integer otherwise, printed
/// exactly under 2^53. Values with so few significant bits (0.5, 1.25, a coarse grid's
/// coordinates) are cheap to leave to the standard library.
fn may_tie(a: f64) -> bool {
    let bits = a.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let fraction = bits & ((1u64 << 52) - 1);
    let (m, e) = if biased == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1u64 << 52), biased - 1075)
    };
    let e = e + m.trailing_zeros() as i32;
    if e < 0 {
        e >= -25
    } else {
        a >= 9007199254740992.0
    }
}

/// Small blocks and pieces for the block readers' tests: boundaries inside lines, inside
/// continued statements, between vertices and faces, and every block split among tasks.
#[cfg(test)]
pub(crate) const SMALL_CHUNKINGS: [Chunking; 5] = [
    Chunking {
        block: 1,
        max_line: MAX_LINE,
        piece: 1,
    },
    Chunking {
        block: 2,
        max_line: MAX_LINE,
        piece: 5,
    },
    Chunking {
        block: 7,
        max_line: MAX_LINE,
        piece: 3,
    },
    Chunking {
        block: 31,
        max_line: MAX_LINE,
        piece: 40,
    },
    Chunking {
        block: 200,
        max_line: MAX_LINE,
        piece: 8,
    },
];

/// Asserts that `read` gives `text` the result the line-by-line `oracle` gives it (both in
/// their Debug form, errors included) with every chunking of [`SMALL_CHUNKINGS`] and the
/// default, lines limited to `max_line` bytes.
#[cfg(test)]
pub(crate) fn assert_chunkings_agree<T: std::fmt::Debug, U: std::fmt::Debug>(
    text: &[u8],
    max_line: usize,
    oracle: impl Fn(&[u8], usize) -> T,
    read: impl Fn(&[u8], &Chunking) -> U,
) {
    let expect = format!("{:?}", oracle(text, max_line));
    let default = Chunking {
        max_line,
        ..Chunking::DEFAULT
    };
    let small = SMALL_CHUNKINGS.iter().map(|c| Chunking { max_line, ..*c });
    for chunking in small.chain([default]) {
        let got = format!("{:?}", read(text, &chunking));
        assert_eq!(
            got,
            expect,
            "{chunking:?} on {:?}",
            String::from_utf8_lossy(text)
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn written(x: f64) -> String {
        let mut out = Vec::new();
        write_f64(&mut out, x).unwrap();
        String::from_utf8(out).unwrap()
    }

    fn standard(x: f64) -> String {
        let a = x.abs();
        if a == 0.0 || (1e-5..1e16).contains(&a) {
            format!("{x}")
        } else {
            format!("{x:e}")
        }
    }

    #[test]
    fn floats_print_as_the_standard_library_prints_them() {
        let mut cases = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.5,
            1.5,
            10.0,
            123456.789,
            0.99999e-5,
            1.00001e-5,
            9.999999999999998e15,
            1.0000000000000002,
            0.30000000000000004,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            f64::EPSILON,
            std::f64::consts::PI,
            // A tie of two shortest strings: 1690060720831323.25 (spacing 0.25) prints as
            // ...23.3 here and ...23.2 by zmij. Then a large integer (exponent layout), and
            // values of few significant bits (may_tie's path).
            f64::from_bits(0x4318_0467_b3a7_ed6d),
            1152921504606847232.0,
            0.1234375,
            -1.25e-3,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        // Every power of ten, beside it and at the two switches of layout (1e-5 and 1e16).
        for k in -324..=308 {
            let p = 10f64.powi(k);
            cases.extend([p, -p, 1.5 * p, 7.0 * p, p.next_up(), p.next_down()]);
        }
        for x in cases {
            assert_eq!(written(x), standard(x), "{x:?}");
        }
    }

    #[test]
    fn random_floats_print_as_the_standard_library_prints_them() {
        // Bit patterns with equal weight (every exponent), then coordinates of the magnitudes
        // meshes have (xorshift64, a fixed seed).
        const ROUNDS: usize = 200_000;
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for _ in 0..ROUNDS {
            let x = f64::from_bits(next());
            assert_eq!(written(x), standard(x), "{:#x}", x.to_bits());
            let y = (next() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
            for s in [1e-3, 1.0, 250.0, 1e6] {
                assert_eq!(written(y * s), standard(y * s), "{:#x}", (y * s).to_bits());
            }
        }
    }

    #[test]
    fn face_lines_read_as_writeln_writes_them() {
        for ids in [
            [0, 1, 2],
            [9, 10, 99],
            [u64::from(u32::MAX), 123_456_789, 7],
        ] {
            for lead in [&b"3"[..], b"f"] {
                let mut out = Vec::new();
                write_face_line(&mut out, lead, ids).unwrap();
                let [a, b, c] = ids;
                let lead = std::str::from_utf8(lead).unwrap();
                assert_eq!(
                    String::from_utf8(out).unwrap(),
                    format!("{lead} {a} {b} {c}\n")
                );
            }
        }
    }

    #[test]
    fn lines_strip_breaks_and_bom() {
        let data = b"\xEF\xBB\xBFfirst\r\nsecond\n\nlast";
        let mut r = LineReader::new(&data[..]);
        assert_eq!(r.next_line().unwrap(), Some(&b"first"[..]));
        assert_eq!(r.line(), 1);
        assert_eq!(r.next_line().unwrap(), Some(&b"second"[..]));
        assert_eq!(r.next_line().unwrap(), Some(&b""[..]));
        assert_eq!(r.next_line().unwrap(), Some(&b"last"[..]));
        assert_eq!(r.line(), 4);
        assert_eq!(r.next_line().unwrap(), None);
    }

    #[test]
    fn long_lines_are_refused() {
        let data = [b'x'; 100];
        let mut r = LineReader::with_max_len(&data[..], 10);
        assert!(matches!(r.next_line(), Err(Error::Parse { line: 1, .. })));
        let mut r = LineReader::with_max_len(&b"0123456789\nab"[..], 10);
        assert_eq!(r.next_line().unwrap(), Some(&b"0123456789"[..]));
        assert_eq!(r.next_line().unwrap(), Some(&b"ab"[..]));
    }

    #[test]
    fn tokens_span_lines() {
        let data = b"  a bb\n\n   \nccc\td  \n";
        let mut t = TokenReader::new(LineReader::new(&data[..]));
        let mut seen = Vec::new();
        while let Some(tok) = t.next_token().unwrap() {
            seen.push((String::from_utf8(tok.to_vec()).unwrap(), t.line()));
        }
        let expect = [("a", 1), ("bb", 1), ("ccc", 4), ("d", 4)];
        let expect: Vec<_> = expect.iter().map(|(s, l)| (s.to_string(), *l)).collect();
        assert_eq!(seen, expect);
    }

    #[test]
    fn integers() {
        assert_eq!(parse_i64(b"0"), Some(0));
        assert_eq!(parse_i64(b"+17"), Some(17));
        assert_eq!(parse_i64(b"-9223372036854775808"), Some(i64::MIN));
        assert_eq!(parse_i64(b"9223372036854775807"), Some(i64::MAX));
        assert_eq!(parse_i64(b"9223372036854775808"), None);
        assert_eq!(parse_i64(b"-"), None);
        assert_eq!(parse_i64(b""), None);
        assert_eq!(parse_i64(b"1.0"), None);
    }

    #[test]
    fn floats_round_trip() {
        let values = [
            0.0,
            -0.0,
            1.0,
            0.1,
            1e-6,
            -1.5e-300,
            f64::MIN_POSITIVE,
            5e-324,
            1e16,
            123_456_789.123_456_79,
            f64::MAX,
            -f64::MAX,
            2.97683e-21,
        ];
        for x in values {
            let s = written(x);
            assert!(s.len() <= 24, "{s}");
            let y = parse_f64(s.as_bytes()).unwrap();
            assert_eq!(x.to_bits(), y.to_bits(), "{x}");
        }
    }
}
