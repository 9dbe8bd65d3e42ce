//! Point sets: `x y z` text files (`.xyz`, `.pts`, `.txt`), or the vertices of any mesh file.

use crate::error::{Error, Problem, Result};
use crate::format::Format;
use crate::text::as_text;
use glam::DVec3;
use std::path::Path;

/// True for the extensions read as `x y z` lines.
fn is_xyz(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| ["xyz", "pts", "txt"].contains(&e.to_ascii_lowercase().as_str()))
}

/// Reads a point set: one point per line as `x y z` (further columns, e.g. normals, are ignored;
/// `#` starts a comment) for `.xyz` / `.pts` / `.txt`, otherwise the vertices of a mesh file read
/// with [`crate::read`]. Every coordinate must be finite.
pub fn read_points(path: &Path, format: Option<Format>) -> Result<Vec<DVec3>> {
    if format.is_some() || !is_xyz(path) {
        return Ok(match crate::read(path, format)?.mesh {
            crate::AnyMesh::Surface(s) => s.positions,
            crate::AnyMesh::Volume(v) => v.positions,
        });
    }
    let run = || -> Result<Vec<DVec3>, Problem> {
        if path.is_dir() {
            return Err(Problem::Unsupported(
                "is a directory, not a point file".into(),
            ));
        }
        parse_xyz(&std::fs::read(path)?)
    };
    run().map_err(|p| Error::new(path, p))
}

/// Parses `x y z` lines.
pub fn parse_xyz(bytes: &[u8]) -> Result<Vec<DVec3>, Problem> {
    let rows = parse_rows::<3>(bytes, "three coordinates `x y z`")?;
    Ok(rows
        .into_iter()
        .map(|(_, r)| DVec3::from_array(r))
        .collect())
}

/// Parses `x y z h` lines: a size `h` at each point (a sizing field's samples); every size must
/// be a positive number.
pub fn parse_point_sizes(bytes: &[u8]) -> Result<(Vec<DVec3>, Vec<f64>), Problem> {
    let rows = parse_rows::<4>(bytes, "a point and its size `x y z h`")?;
    let mut points = Vec::with_capacity(rows.len());
    let mut sizes = Vec::with_capacity(rows.len());
    for (line, [x, y, z, h]) in rows {
        if h <= 0.0 {
            return Err(Problem::at_line(line, format!("size {h} is not positive")));
        }
        points.push(DVec3::new(x, y, z));
        sizes.push(h);
    }
    Ok((points, sizes))
}

/// Reads `x y z h` lines from a file (see [`parse_point_sizes`]).
pub fn read_point_sizes(path: &Path) -> Result<(Vec<DVec3>, Vec<f64>)> {
    let run = || -> Result<_, Problem> {
        if path.is_dir() {
            return Err(Problem::Unsupported(
                "is a directory, not a point file".into(),
            ));
        }
        parse_point_sizes(&std::fs::read(path)?)
    };
    run().map_err(|p| Error::new(path, p))
}

/// Lines of at least `N` finite numbers (further columns ignored, `#` starts a comment), with
/// their line numbers; `expected` says what a line holds.
fn parse_rows<const N: usize>(
    bytes: &[u8],
    expected: &str,
) -> Result<Vec<(usize, [f64; N])>, Problem> {
    let text = as_text(bytes)?;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("");
        let mut words = content.split_whitespace();
        let Some(first) = words.next() else { continue };
        let mut row = [0.0; N];
        for (k, word) in std::iter::once(first).chain(words).take(N).enumerate() {
            row[k] = word.parse::<f64>().map_err(|_| {
                Problem::at_line(
                    i + 1,
                    format!("{} is not a number", crate::text::quote(word)),
                )
            })?;
            if !row[k].is_finite() {
                return Err(Problem::at_line(i + 1, format!("non-finite value {word}")));
            }
        }
        if content.split_whitespace().count() < N {
            return Err(Problem::at_line(i + 1, format!("expected {expected}")));
        }
        rows.push((i + 1, row));
    }
    if rows.is_empty() {
        return Err(Problem::bad("the file holds no points"));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_points_with_comments_and_extra_columns() {
        let pts = parse_xyz(b"# header\n1 2 3\n\n4.5 -6 7e2 0 0 1 # normal\n").expect("valid");
        assert_eq!(
            pts,
            vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.5, -6.0, 700.0)]
        );
    }

    #[test]
    fn rejects_short_lines_bad_numbers_nan_and_empty_files() {
        let short = parse_xyz(b"1 2 3\n1 2\n").expect_err("two coordinates");
        assert!(short.to_string().contains("line 2"), "{short}");
        assert!(parse_xyz(b"1 2 x\n").is_err());
        assert!(parse_xyz(b"1 NaN 3\n").is_err());
        assert!(parse_xyz(b"1 2 inf\n").is_err());
        assert!(parse_xyz(b"# only a comment\n").is_err());
    }

    #[test]
    fn point_sizes_need_four_columns_and_positive_sizes() {
        let (p, h) = parse_point_sizes(b"0 0 0 0.5\n1 2 3 0.25 extra\n").expect("valid");
        assert_eq!(p, vec![DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)]);
        assert_eq!(h, vec![0.5, 0.25]);
        let e = parse_point_sizes(b"0 0 0 1\n0 0 1 -1\n").expect_err("negative");
        assert!(
            e.to_string().contains("line 2") && e.to_string().contains("-1"),
            "{e}"
        );
        assert!(parse_point_sizes(b"0 0 0\n").is_err());
        assert!(parse_point_sizes(b"0 0 0 nan\n").is_err());
        assert!(parse_point_sizes(b"0 0 0 0\n").is_err());
    }
}
