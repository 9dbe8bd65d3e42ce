//! A whitespace tokenizer with line numbers and `#` comments, shared by the hand-written text readers.

use crate::error::Problem;
use std::borrow::Cow;
use std::str::{FromStr, SplitWhitespace};

/// The UTF-8 byte-order mark some editors put at the start of text files.
const BOM: &[u8] = b"\xEF\xBB\xBF";

/// `bytes` without a leading UTF-8 byte-order mark.
pub(crate) fn strip_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(BOM).unwrap_or(bytes)
}

/// The file as text. The syntax of every text format is ASCII, so bytes that are not UTF-8 (a
/// Latin-1 `é` in a comment or a name) become U+FFFD instead of failing the whole file: where they
/// matter, the token holding them is refused with its line.
pub(crate) fn as_text(bytes: &[u8]) -> Result<Cow<'_, str>, Problem> {
    Ok(String::from_utf8_lossy(strip_bom(bytes)))
}

/// Longest piece of input quoted in a message, in characters.
const QUOTE_CHARS: usize = 40;

/// `s` quoted for a message (`Debug` escapes), cut to a few dozen characters so that a line of
/// binary junk cannot flood the terminal.
pub(crate) fn quote(s: &str) -> String {
    match s.char_indices().nth(QUOTE_CHARS) {
        Some((cut, _)) => format!("{:?}…", &s[..cut]),
        None => format!("{s:?}"),
    }
}

/// Capacity to reserve for `count` items announced by a file of `bytes` bytes: never more than the
/// file could possibly hold, so a lying header cannot make us allocate gigabytes.
pub(crate) fn capped(count: usize, bytes: usize) -> usize {
    count.min(bytes / 2 + 1)
}

pub(crate) struct Tokens<'a> {
    lines: std::str::Lines<'a>,
    words: SplitWhitespace<'a>,
    line: usize,
}

impl<'a> Tokens<'a> {
    pub(crate) fn new(text: &'a str) -> Tokens<'a> {
        Tokens {
            lines: text.lines(),
            words: "".split_whitespace(),
            line: 0,
        }
    }

    /// Line of the last token returned (1-based).
    pub(crate) fn line(&self) -> usize {
        self.line
    }

    pub(crate) fn next_token(&mut self) -> Option<&'a str> {
        loop {
            if let Some(w) = self.words.next() {
                return Some(w);
            }
            let l = self.lines.next()?;
            self.line += 1;
            let content = l.split('#').next().unwrap_or("");
            self.words = content.split_whitespace();
        }
    }

    /// Drops what is left of the current line (colours, normals and other extras we do not keep).
    pub(crate) fn skip_rest_of_line(&mut self) {
        self.words = "".split_whitespace();
    }

    pub(crate) fn expect(&mut self, what: &str) -> Result<&'a str, Problem> {
        self.next_token().ok_or_else(|| {
            Problem::at_line(
                self.line.max(1),
                format!("unexpected end of file, expected {what}"),
            )
        })
    }

    pub(crate) fn parse<T: FromStr>(&mut self, what: &str) -> Result<T, Problem> {
        let tok = self.expect(what)?;
        tok.parse().map_err(|_| {
            Problem::at_line(self.line, format!("expected {what}, found {}", quote(tok)))
        })
    }

    /// A finite coordinate: NaN and infinities are rejected where they are read.
    pub(crate) fn coordinate(&mut self) -> Result<f64, Problem> {
        let x: f64 = self.parse("a coordinate")?;
        if x.is_finite() {
            Ok(x)
        } else {
            Err(Problem::at_line(
                self.line,
                format!("non-finite coordinate {x}"),
            ))
        }
    }

    /// A vertex index in `1..=count` (1-based formats), returned 0-based.
    pub(crate) fn index_1based(&mut self, count: usize) -> Result<u32, Problem> {
        let i: i64 = self.parse("a vertex index")?;
        if i < 1 || i as u64 > count as u64 {
            return Err(Problem::at_line(
                self.line,
                format!("vertex index {i} out of range 1..={count}"),
            ));
        }
        Ok((i - 1) as u32)
    }

    /// A vertex index in `0..count` (0-based formats).
    pub(crate) fn index_0based(&mut self, count: usize) -> Result<u32, Problem> {
        let i: i64 = self.parse("a vertex index")?;
        if i < 0 || i as u64 >= count as u64 {
            return Err(Problem::at_line(
                self.line,
                format!("vertex index {i} out of range 0..{count}"),
            ));
        }
        Ok(i as u32)
    }
}

/// Shortest decimal that parses back to the same f64 (Rust's `Debug` float formatting), so text
/// formats round-trip positions bit-exactly.
pub(crate) struct Exact(pub f64);

impl std::fmt::Display for Exact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}", self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_and_line_numbers() {
        let mut t = Tokens::new("a b # c\n\n# only comment\n d 1.5 nan");
        assert_eq!(t.next_token(), Some("a"));
        assert_eq!(t.next_token(), Some("b"));
        assert_eq!(t.next_token(), Some("d"));
        assert_eq!(t.line(), 4);
        assert_eq!(t.coordinate().ok(), Some(1.5));
        assert!(t.coordinate().is_err());
        assert!(t.expect("more").is_err());
    }

    #[test]
    fn quotes_are_short_and_text_survives_latin1_and_a_bom() {
        let junk = "\0".repeat(1000);
        assert!(quote(&junk).chars().count() < 4 * QUOTE_CHARS);
        assert_eq!(quote("abc"), "\"abc\"");
        let text = as_text(b"\xEF\xBB\xBFOFF # caf\xE9\n1 2").map(Cow::into_owned);
        let text = text.unwrap_or_default();
        let mut t = Tokens::new(&text);
        assert_eq!(t.next_token(), Some("OFF"));
        assert_eq!(t.next_token(), Some("1"));
    }

    #[test]
    fn exact_formatting_round_trips() {
        for x in [0.1, 1.0 / 3.0, -2.5e-300, 1e300, 0.0, -0.0, 123456789.0] {
            assert_eq!(
                Exact(x).to_string().parse::<f64>().ok().map(f64::to_bits),
                Some(x.to_bits())
            );
        }
    }
}
