//! User feature polylines in CGAL's `.polylines.txt` format: one polyline per line,
//! `n x1 y1 z1 ... xn yn zn`.

use glam::DVec3;
use std::path::{Path, PathBuf};

/// A polyline given by the user, with the line of the file it came from (for error messages).
#[derive(Clone, Debug, PartialEq)]
pub struct Polyline {
    /// 1-based line number in the file.
    pub line: usize,
    /// The polyline's points in order.
    pub points: Vec<DVec3>,
}

/// Why a polylines file cannot be used.
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum PolylineError {
    #[error("{path}: cannot read: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}:{line}: {problem}")]
    Syntax {
        path: PathBuf,
        line: usize,
        problem: String,
    },
}

/// Reads a `.polylines.txt` file. Blank lines and lines starting with `#` are skipped.
pub fn read_polylines(path: &Path) -> Result<Vec<Polyline>, PolylineError> {
    let bytes = std::fs::read(path).map_err(|source| PolylineError::Io {
        path: path.to_owned(),
        source,
    })?;
    // Text with a byte-order mark or a Latin-1 comment is still text.
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
    let text = String::from_utf8_lossy(bytes);
    parse_polylines(&text).map_err(|(line, problem)| PolylineError::Syntax {
        path: path.to_owned(),
        line,
        problem,
    })
}

/// A word of the file quoted for a message, cut to a few dozen characters.
fn quote(word: &str) -> String {
    match word.char_indices().nth(40) {
        Some((cut, _)) => format!("{:?}…", &word[..cut]),
        None => format!("{word:?}"),
    }
}

/// Parses the text of a `.polylines.txt` file; an error is `(line, problem)`.
pub fn parse_polylines(text: &str) -> Result<Vec<Polyline>, (usize, String)> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = raw.trim();
        if content.is_empty() || content.starts_with('#') {
            continue;
        }
        let mut words = content.split_whitespace();
        let count_word = words.next().unwrap_or_default();
        let count: usize = count_word.parse().map_err(|_| {
            (
                line,
                format!("expected the number of points, found {}", quote(count_word)),
            )
        })?;
        if count < 2 {
            return Err((
                line,
                format!("a polyline needs at least 2 points, this one has {count}"),
            ));
        }
        let numbers = words
            .map(|w| {
                w.parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| (line, format!("{} is not a finite number", quote(w))))
            })
            .collect::<Result<Vec<f64>, _>>()?;
        // Compared as `numbers / 3` so that a huge announced count cannot wrap `3 * count`.
        if numbers.len() % 3 != 0 || numbers.len() / 3 != count {
            return Err((
                line,
                format!(
                    "{count} points need {} coordinates, found {}",
                    count.saturating_mul(3),
                    numbers.len()
                ),
            ));
        }
        let points = numbers
            .chunks_exact(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect();
        out.push(Polyline { line, points });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_count_whose_triple_wraps_is_refused() {
        // 3 · 6148914691236517206 wraps to 2 on 64 bits.
        let text = "6148914691236517206 0 0\n";
        assert!(parse_polylines(text).is_err());
    }

    #[test]
    fn parses_polylines_and_skips_blank_lines() {
        let text = "2 0 0 0 1 0 0\n\n# a comment\n3 0 0 0  0 1 0\t0 1 1\n";
        let p = parse_polylines(text).expect("valid");
        assert_eq!(p.len(), 2);
        assert_eq!(p[0].line, 1);
        assert_eq!(p[0].points, vec![DVec3::ZERO, DVec3::X]);
        assert_eq!(p[1].line, 4);
        assert_eq!(p[1].points[2], DVec3::new(0.0, 1.0, 1.0));
    }

    #[test]
    fn malformed_lines_are_errors_naming_the_line() {
        let cases = [
            ("2 0 0 0 1 0 0\nx 0 0 0\n", 2, "number of points"),
            ("3 0 0 0 1 0 0\n", 1, "9 coordinates, found 6"),
            ("2 0 0 0 1 0 NaN\n", 1, "not a finite number"),
            ("2 0 0 0 1 0 inf\n", 1, "not a finite number"),
            ("1 0 0 0\n", 1, "at least 2 points"),
            ("2 0 0 0 1 0 0 7\n", 1, "found 7"),
        ];
        for (text, line, problem) in cases {
            let (l, p) = parse_polylines(text).expect_err(text);
            assert_eq!(l, line, "{text}");
            assert!(p.contains(problem), "{text}: {p}");
        }
    }
}
