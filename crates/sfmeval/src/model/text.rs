//! Small helpers shared by the text readers: UTF-8 decoding with a typed error, whitespace
//! token streams that know their line number, and number parsing with a clear message.

use crate::error::{Error, Result};

/// Decodes bytes as text (lossy for invalid UTF-8 only in names would hide corruption, so
/// refuse instead), stripping a UTF-8 BOM.
pub(crate) fn utf8<'a>(format: &'static str, bytes: &'a [u8]) -> Result<&'a str> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    std::str::from_utf8(bytes)
        .map_err(|e| Error::malformed(format, format!("not UTF-8 text (byte {})", e.valid_up_to())))
}

/// Non-empty, non-comment lines with their 1-based line numbers.
pub(crate) fn data_lines(text: &str, comment: char) -> Vec<(usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with(comment))
        .collect()
}

/// Parses one token as `T` or reports `what` at `line`.
pub(crate) fn parse<T: std::str::FromStr>(
    format: &'static str,
    tok: Option<&str>,
    what: &str,
    line: usize,
) -> Result<T> {
    let tok =
        tok.ok_or_else(|| Error::truncated(format, format!("line {line}: missing {what}")))?;
    tok.parse::<T>().map_err(|_| {
        Error::malformed(
            format,
            format!("line {line}: {what} '{}' is not a valid number", clip(tok)),
        )
    })
}

/// Parses a finite f64.
pub(crate) fn parse_f64(
    format: &'static str,
    tok: Option<&str>,
    what: &str,
    line: usize,
) -> Result<f64> {
    let v: f64 = parse(format, tok, what, line)?;
    if !v.is_finite() {
        return Err(Error::NonFinite {
            format,
            what: "value at line",
            count: 1,
            first_index: line,
        });
    }
    Ok(v)
}

/// A token at most 40 characters long for messages.
pub(crate) fn clip(s: &str) -> String {
    if s.chars().count() > 40 {
        let mut c: String = s.chars().take(40).collect();
        c.push('…');
        c
    } else {
        s.to_string()
    }
}

/// A stream of whitespace-separated tokens over several lines, remembering the line number.
pub(crate) struct Tokens<'a> {
    format: &'static str,
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    current: std::str::SplitWhitespace<'a>,
    line: usize,
}

impl<'a> Tokens<'a> {
    /// Tokens of `text`.
    pub(crate) fn new(format: &'static str, text: &'a str) -> Tokens<'a> {
        Tokens {
            format,
            lines: text.lines().enumerate(),
            current: "".split_whitespace(),
            line: 0,
        }
    }

    /// The next token, or `None` at the end.
    pub(crate) fn next_token(&mut self) -> Option<&'a str> {
        loop {
            if let Some(t) = self.current.next() {
                return Some(t);
            }
            let (i, l) = self.lines.next()?;
            self.line = i + 1;
            self.current = l.split_whitespace();
        }
    }

    /// The next token parsed as `T`.
    pub(crate) fn parse<T: std::str::FromStr>(&mut self, what: &str) -> Result<T> {
        let t = self.next_token();
        parse(self.format, t, what, self.line)
    }

    /// The next token as a finite f64.
    pub(crate) fn f64(&mut self, what: &str) -> Result<f64> {
        let t = self.next_token();
        parse_f64(self.format, t, what, self.line)
    }
}
