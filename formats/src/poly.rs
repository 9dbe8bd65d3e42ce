//! Reader of Shewchuk's Triangle `.poly` files (planar straight-line graphs): vertices, segments
//! with boundary markers, holes and regional attributes / area bounds. No maintained crate reads
//! this format, so it is hand-written. A `.poly` file with zero vertices takes them from the `.node`
//! file of the same name, as Triangle does.

use delamesh_core::mesh2d::{Point2, Pslg, Region};
use std::path::{Path, PathBuf};

/// Why a `.poly` file could not be read.
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum PolyError {
    #[error("cannot read {path}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}:{line}: {message}")]
    Syntax {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error("{path}: invalid planar straight-line graph")]
    Invalid {
        path: PathBuf,
        source: delamesh_core::mesh2d::PslgError,
    },
}

/// Reads and validates a `.poly` file.
pub fn read_poly(path: &Path) -> Result<Pslg, PolyError> {
    let text = read_text(path)?;
    let node = path.with_extension("node");
    let pslg = parse_poly(&text, path, || read_text(&node).map(|t| (t, node.clone())))?;
    pslg.validate().map_err(|source| PolyError::Invalid {
        path: path.to_owned(),
        source,
    })?;
    Ok(pslg)
}

fn read_text(path: &Path) -> Result<String, PolyError> {
    let bytes = std::fs::read(path).map_err(|source| PolyError::Io {
        path: path.to_owned(),
        source,
    })?;
    Ok(crate::text::as_text(&bytes)
        .map(std::borrow::Cow::into_owned)
        .unwrap_or_default())
}

/// The non-empty, comment-stripped lines of a file, with their line numbers.
struct Lines<'a> {
    path: &'a Path,
    inner: std::iter::Enumerate<std::str::Lines<'a>>,
    last: usize,
    /// Length of the text, which bounds how many items it can hold.
    len: usize,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str, path: &'a Path) -> Self {
        Self {
            path,
            inner: text.lines().enumerate(),
            last: 0,
            len: text.len(),
        }
    }

    fn error(&self, message: impl Into<String>) -> PolyError {
        PolyError::Syntax {
            path: self.path.to_owned(),
            line: self.last,
            message: message.into(),
        }
    }

    /// The numbers of the next meaningful line (`None` at the end of the file).
    fn next_numbers(&mut self) -> Result<Option<Vec<f64>>, PolyError> {
        for (i, line) in self.inner.by_ref() {
            self.last = i + 1;
            let content = line.split('#').next().unwrap_or("");
            let words: Vec<&str> = content.split_whitespace().collect();
            if words.is_empty() {
                continue;
            }
            let nums = words
                .iter()
                .map(|w| {
                    w.parse::<f64>()
                        .map_err(|_| format!("{} is not a number", crate::text::quote(w)))
                })
                .collect::<Result<Vec<f64>, String>>()
                .map_err(|m| self.error(m))?;
            return Ok(Some(nums));
        }
        Ok(None)
    }

    fn expect_numbers(&mut self, what: &str, at_least: usize) -> Result<Vec<f64>, PolyError> {
        match self.next_numbers()? {
            Some(n) if n.len() >= at_least => Ok(n),
            Some(n) => Err(self.error(format!(
                "{what}: expected {at_least} numbers, found {}",
                n.len()
            ))),
            None => Err(self.error(format!("file ends before {what}"))),
        }
    }

    /// Capacity to reserve for `n` announced items: never more than the text can hold.
    fn capacity(&self, n: usize) -> usize {
        crate::text::capped(n, self.len)
    }

    fn count(&self, v: f64, what: &str) -> Result<usize, PolyError> {
        if v >= 0.0 && v.fract() == 0.0 && v < 1e9 {
            Ok(v as usize)
        } else {
            Err(self.error(format!("{what} must be a non-negative integer, found {v}")))
        }
    }
}

/// Reads the vertex section (shared by `.poly` and `.node`); returns the points and the number of
/// the first vertex (0 or 1, as the file numbers them).
fn parse_vertices(lines: &mut Lines) -> Result<(Vec<Point2>, i64), PolyError> {
    let header = lines.expect_numbers("the vertex header", 1)?;
    let n = lines.count(header[0], "the number of vertices")?;
    if header.get(1).is_some_and(|&d| d != 2.0) {
        return Err(lines.error("only dimension 2 is supported"));
    }
    let attributes = lines.count(
        header.get(2).copied().unwrap_or(0.0),
        "the number of attributes",
    )?;
    let mut points = Vec::with_capacity(lines.capacity(n));
    let mut first = 0;
    for k in 0..n {
        let row = lines.expect_numbers("a vertex", 3)?;
        let id = row[0] as i64;
        if k == 0 {
            first = id;
            if first != 0 && first != 1 {
                return Err(lines.error("vertices must be numbered from 0 or 1"));
            }
        } else if id != first + k as i64 {
            return Err(lines.error(format!("vertex number {id}, expected {}", first + k as i64)));
        }
        if row.len() < 3 + attributes {
            return Err(lines.error("vertex line is missing attributes"));
        }
        let p = Point2::new(row[1], row[2]);
        if !p.is_finite() {
            return Err(lines.error("vertex has a non-finite coordinate"));
        }
        points.push(p);
    }
    Ok((points, first))
}

/// Parses `.poly` text; `node` supplies the `.node` file when the vertex count is zero.
pub fn parse_poly(
    text: &str,
    path: &Path,
    node: impl FnOnce() -> Result<(String, PathBuf), PolyError>,
) -> Result<Pslg, PolyError> {
    let mut lines = Lines::new(text, path);
    let (mut points, mut first) = parse_vertices(&mut lines)?;
    if points.is_empty() {
        let (node_text, node_path) = node()?;
        let mut node_lines = Lines::new(&node_text, &node_path);
        (points, first) = parse_vertices(&mut node_lines)?;
    }
    let header = lines.expect_numbers("the segment header", 1)?;
    let m = lines.count(header[0], "the number of segments")?;
    let markers = header.get(1).is_some_and(|&b| b != 0.0);
    let mut segments = Vec::with_capacity(lines.capacity(m));
    let mut segment_markers = Vec::with_capacity(lines.capacity(m));
    for _ in 0..m {
        let row = lines.expect_numbers("a segment", 3)?;
        let mut ends = [0u32; 2];
        for (e, &x) in ends.iter_mut().zip(&row[1..3]) {
            let k = lines.count(x, "a segment endpoint")? as i64 - first;
            if k < 0 || k as usize >= points.len() {
                return Err(lines.error(format!("segment endpoint {x} is not a vertex")));
            }
            *e = k as u32;
        }
        segments.push(ends);
        segment_markers.push(if markers {
            row.get(3).copied().unwrap_or(0.0) as i32
        } else {
            0
        });
    }
    let header = lines.expect_numbers("the hole header", 1)?;
    let h = lines.count(header[0], "the number of holes")?;
    let mut holes = Vec::with_capacity(lines.capacity(h));
    for _ in 0..h {
        let row = lines.expect_numbers("a hole", 3)?;
        holes.push(Point2::new(row[1], row[2]));
    }
    let mut regions = Vec::new();
    if let Some(header) = lines.next_numbers()? {
        let r = lines.count(header[0], "the number of regions")?;
        for _ in 0..r {
            let row = lines.expect_numbers("a region", 4)?;
            let max_area = row.get(4).copied().filter(|&a| a > 0.0);
            regions.push(Region {
                point: Point2::new(row[1], row[2]),
                attribute: row[3],
                max_area,
            });
        }
    }
    if holes
        .iter()
        .chain(regions.iter().map(|r| &r.point))
        .any(|p| !p.is_finite())
    {
        return Err(lines.error("hole or region point has a non-finite coordinate"));
    }
    Ok(Pslg {
        points,
        segments,
        segment_markers,
        holes,
        regions,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Pslg, PolyError> {
        parse_poly(text, Path::new("t.poly"), || {
            Ok((
                "3 2 0 0\n1 0 0\n2 1 0\n3 0 1\n".to_owned(),
                PathBuf::from("t.node"),
            ))
        })
    }

    #[test]
    fn reads_square_with_hole_and_region() {
        let text = "# square with a hole\n8 2 0 1\n1 0 0 1\n2 3 0 1\n3 3 3 1\n4 0 3 1\n\
                    5 1 1 0\n6 2 1 0\n7 2 2 0\n8 1 2 0\n8 1\n1 1 2 5\n2 2 3 5\n3 3 4 5\n4 4 1 5\n\
                    5 5 6 0\n6 6 7 0\n7 7 8 0\n8 8 5 0\n1\n1 1.5 1.5\n1\n1 0.5 0.5 7 0.25\n";
        let p = parse(text).expect("valid");
        assert_eq!(p.points.len(), 8);
        assert_eq!(p.segments[3], [3, 0]);
        assert_eq!(p.segment_markers[0], 5);
        assert_eq!(p.holes, vec![Point2::new(1.5, 1.5)]);
        assert_eq!(p.regions[0].attribute, 7.0);
        assert_eq!(p.regions[0].max_area, Some(0.25));
        assert!(p.validate().is_ok());
    }

    #[test]
    fn zero_vertices_reads_the_node_file() {
        let p = parse("0 2 0 0\n3 0\n0 1 2\n1 2 3\n2 3 1\n0\n").expect("valid");
        assert_eq!(p.points.len(), 3);
        assert_eq!(p.segments, vec![[0, 1], [1, 2], [2, 0]]);
    }

    #[test]
    fn errors_name_the_line() {
        let bad = [
            ("3 2 0 0\n1 0 0\n2 1 x\n", 3),
            ("2 2 0 0\n1 0 0\n2 1 0\n1 0\n1 1 7\n0\n", 5),
            ("2 3 0 0\n", 1),
            ("2 2 0 0\n1 0 0\n", 2),
        ];
        for (text, line) in bad {
            match parse(text) {
                Err(PolyError::Syntax { line: l, .. }) => assert_eq!(l, line, "{text}"),
                other => panic!("{text}: {other:?}"),
            }
        }
    }
}
