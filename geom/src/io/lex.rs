//! A byte cursor for the text formats (OBJ, OFF): whitespace and `#` comments, tokens,
//! fast float parsing (`fast-float2`), integers, and line numbers for error messages.

use crate::error::{Error, parse_err};

pub(crate) struct Lex<'a> {
    pub b: &'a [u8],
    pub pos: usize,
    pub line: usize,
    pub format: &'static str,
}

impl<'a> Lex<'a> {
    pub fn new(b: &'a [u8], format: &'static str) -> Self {
        Self { b, pos: 0, line: 1, format }
    }

    pub fn err(&self, msg: impl Into<String>) -> Error {
        parse_err(self.format, format!("line {}", self.line), msg)
    }

    pub fn remaining(&self) -> usize {
        self.b.len() - self.pos
    }

    /// Skips spaces, tabs, newlines and comments.
    pub fn skip_ws(&mut self) {
        while self.pos < self.b.len() {
            match self.b[self.pos] {
                b'\n' => {
                    self.line += 1;
                    self.pos += 1;
                }
                b' ' | b'\t' | b'\r' | 0x0c => self.pos += 1,
                b'#' => self.skip_line(),
                _ => break,
            }
        }
    }

    /// Skips spaces and tabs (not newlines); stops at a comment.
    pub fn skip_inline_ws(&mut self) {
        while self.pos < self.b.len() {
            match self.b[self.pos] {
                b' ' | b'\t' | b'\r' | 0x0c => self.pos += 1,
                b'#' => {
                    while self.pos < self.b.len() && self.b[self.pos] != b'\n' {
                        self.pos += 1;
                    }
                }
                _ => break,
            }
        }
    }

    /// True when the current line holds no more tokens.
    pub fn at_line_end(&mut self) -> bool {
        self.skip_inline_ws();
        self.pos >= self.b.len() || self.b[self.pos] == b'\n'
    }

    /// Moves past the next newline.
    pub fn skip_line(&mut self) {
        match self.b[self.pos..].iter().position(|&c| c == b'\n') {
            Some(i) => {
                self.pos += i + 1;
                self.line += 1;
            }
            None => self.pos = self.b.len(),
        }
    }

    /// Next whitespace-delimited token (possibly across lines).
    pub fn token(&mut self) -> Option<&'a [u8]> {
        self.skip_ws();
        self.raw_token()
    }

    /// Next token on the current line.
    pub fn inline_token(&mut self) -> Option<&'a [u8]> {
        self.skip_inline_ws();
        self.raw_token()
    }

    fn raw_token(&mut self) -> Option<&'a [u8]> {
        let start = self.pos;
        while self.pos < self.b.len() && !matches!(self.b[self.pos], b' ' | b'\t' | b'\r' | b'\n' | 0x0c | b'#') {
            self.pos += 1;
        }
        (self.pos > start).then(|| &self.b[start..self.pos])
    }

    pub fn f64(&mut self, what: &str) -> Result<f64, Error> {
        let t = self.token().ok_or_else(|| self.err(format!("unexpected end of file, expected {what}")))?;
        parse_f64(t).ok_or_else(|| self.err(format!("invalid number {:?} for {what}", show(t))))
    }

    pub fn inline_f64(&mut self, what: &str) -> Result<f64, Error> {
        let t = self.inline_token().ok_or_else(|| self.err(format!("expected {what} on this line")))?;
        parse_f64(t).ok_or_else(|| self.err(format!("invalid number {:?} for {what}", show(t))))
    }

    pub fn u64(&mut self, what: &str) -> Result<u64, Error> {
        let t = self.token().ok_or_else(|| self.err(format!("unexpected end of file, expected {what}")))?;
        parse_u64(t).ok_or_else(|| self.err(format!("invalid integer {:?} for {what}", show(t))))
    }
}

/// Parses a whole token as f64 (accepts `nan`/`inf`; validation rejects them later by vertex).
pub(crate) fn parse_f64(t: &[u8]) -> Option<f64> {
    fast_float2::parse::<f64, _>(t).ok()
}

/// Parses a whole token as an unsigned integer, refusing overflow.
pub(crate) fn parse_u64(t: &[u8]) -> Option<u64> {
    if t.is_empty() || t.len() > 19 {
        return None;
    }
    let mut v: u64 = 0;
    for &c in t {
        if !c.is_ascii_digit() {
            return None;
        }
        v = v * 10 + u64::from(c - b'0');
    }
    Some(v)
}

/// Parses a signed integer (OBJ indices may be negative).
pub(crate) fn parse_i64(t: &[u8]) -> Option<i64> {
    match t.first() {
        Some(b'-') => parse_u64(&t[1..]).map(|v| -(v as i64)),
        Some(b'+') => parse_u64(&t[1..]).map(|v| v as i64),
        _ => parse_u64(t).map(|v| v as i64),
    }
}

/// A token for an error message, truncated.
pub(crate) fn show(t: &[u8]) -> String {
    let s = String::from_utf8_lossy(&t[..t.len().min(32)]).into_owned();
    if t.len() > 32 { format!("{s}...") } else { s }
}
