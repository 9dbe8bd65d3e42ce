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
    let text = as_text(bytes)?;
    let mut points = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("");
        let mut words = content.split_whitespace();
        let Some(first) = words.next() else { continue };
        let mut xyz = [0.0; 3];
        for (k, word) in std::iter::once(first).chain(words).take(3).enumerate() {
            xyz[k] = word.parse::<f64>().map_err(|_| {
                Problem::at_line(
                    i + 1,
                    format!("{} is not a number", crate::text::quote(word)),
                )
            })?;
            if !xyz[k].is_finite() {
                return Err(Problem::at_line(
                    i + 1,
                    format!("non-finite coordinate {word}"),
                ));
            }
        }
        if content.split_whitespace().count() < 3 {
            return Err(Problem::at_line(
                i + 1,
                "expected three coordinates `x y z`",
            ));
        }
        points.push(DVec3::from_array(xyz));
    }
    if points.is_empty() {
        return Err(Problem::bad("the file holds no points"));
    }
    Ok(points)
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
}
