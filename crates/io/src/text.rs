//! Helpers of the text formats: a line reader over any `BufRead` that counts lines and bounds
//! line length, whitespace tokens, number parsing and shortest round-trip float printing.

use std::io::{self, BufRead, Read, Write};

use crate::Error;

/// Longest line the text readers accept, in bytes (64 MiB): a file without line breaks is
/// refused instead of being buffered whole.
pub(crate) const MAX_LINE: usize = 1 << 26;

/// The UTF-8 byte order mark some Windows tools put at the start of text files.
const BOM: &[u8] = b"\xEF\xBB\xBF";

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

/// Writes `x` in the shortest form that parses back to the same f64 (`{}`), switching to
/// exponent form (`{:e}`, also shortest) for magnitudes where plain digits would be long.
pub(crate) fn write_f64<W: Write>(w: &mut W, x: f64) -> io::Result<()> {
    let a = x.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) {
        write!(w, "{x}")
    } else {
        write!(w, "{x:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
            let mut s = Vec::new();
            write_f64(&mut s, x).unwrap();
            assert!(s.len() < 30, "{}", String::from_utf8_lossy(&s));
            let y = parse_f64(&s).unwrap();
            assert_eq!(x.to_bits(), y.to_bits(), "{x}");
        }
    }
}
