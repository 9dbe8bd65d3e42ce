//! NRRD images (`.nrrd` with the data after the header, `.nhdr` with `data file:` naming it):
//! a small hand-written reader, as no maintained Rust crate reads NRRD.
//!
//! Fields read: `type`, `dimension` (3), `sizes`, `endian`, `encoding` (`raw`, `gzip`/`gz`),
//! `spacings` or `space directions` (the voxel steps, which may be oblique), `space origin`,
//! `data file` (one file, relative to the header's directory), `byte skip` (≥ 0). `key:=value`
//! pairs and comments are ignored.

use super::{Image, ScalarType, decode_voxels, dimension, gunzip, positive};
use crate::error::Problem;
use glam::{DAffine3, DMat3, DVec3};
use std::path::Path;

/// Parses a NRRD image; `dir` is where a detached data file is looked up.
pub(crate) fn read(bytes: &[u8], dir: Option<&Path>) -> Result<Image, Problem> {
    if !bytes.starts_with(b"NRRD000") {
        return Err(Problem::at_byte(
            0,
            "wrong magic: a NRRD file starts with \"NRRD000\"",
        ));
    }
    // The header ends at the first empty line (or at the end of a detached header).
    let (header, data) = match find(bytes, b"\n\n") {
        Some(i) => (&bytes[..i], &bytes[i + 2..]),
        None => match find(bytes, b"\r\n\r\n") {
            Some(i) => (&bytes[..i], &bytes[i + 4..]),
            None => (bytes, &[][..]),
        },
    };
    let header =
        std::str::from_utf8(header).map_err(|_| Problem::bad("the NRRD header is not text"))?;
    let header = Header::parse(header)?;
    let ty = header
        .ty
        .ok_or_else(|| Problem::bad("the NRRD header has no type"))?;
    if header.rank != Some(3) {
        return Err(Problem::Unsupported(format!(
            "only 3D NRRD images are supported (dimension: {})",
            header.rank.map_or("missing".to_string(), |r| r.to_string())
        )));
    }
    let dims: [usize; 3] = header
        .sizes
        .as_deref()
        .and_then(|s| s.try_into().ok())
        .ok_or_else(|| Problem::bad("NRRD sizes must give three dimensions"))?;
    let matrix = header.voxel_steps()?;

    let detached;
    let data = match &header.data_file {
        Some(name) => {
            let dir = dir.ok_or_else(|| {
                Problem::Unsupported("a detached NRRD data file cannot be read here".into())
            })?;
            let path = dir.join(name);
            detached = std::fs::read(&path).map_err(|e| {
                Problem::bad(format!("cannot read the data file {}: {e}", path.display()))
            })?;
            &detached[..]
        }
        None => data,
    };
    let inflated;
    let data = if header.gzip {
        inflated = gunzip(data)?;
        &inflated[..]
    } else {
        data
    };
    let data = data.get(header.byte_skip..).unwrap_or_default();
    let voxels = decode_voxels(dims, ty, data, header.big_endian)?;
    Ok(Image {
        dims,
        index_to_world: DAffine3::from_mat3_translation(matrix, header.origin),
        voxels,
    })
}

/// The header fields the reader uses, as given (checked by [`read`]).
#[derive(Default)]
struct Header {
    ty: Option<ScalarType>,
    rank: Option<usize>,
    sizes: Option<Vec<usize>>,
    big_endian: bool,
    gzip: bool,
    spacings: Option<Vec<f64>>,
    directions: Option<Vec<Option<DVec3>>>,
    origin: DVec3,
    data_file: Option<String>,
    byte_skip: usize,
}

impl Header {
    /// Reads the `field: value` lines after the magic line.
    fn parse(text: &str) -> Result<Header, Problem> {
        let mut h = Header::default();
        for (n, line) in text.lines().enumerate().skip(1) {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') || line.contains(":=") {
                continue;
            }
            let at = |m: String| Problem::at_line(n + 1, m);
            let Some((key, value)) = line.split_once(':') else {
                return Err(at(format!(
                    "NRRD header line {line:?} is not \"field: value\""
                )));
            };
            let value = value.trim();
            match key.trim().to_ascii_lowercase().as_str() {
                "type" => h.ty = Some(scalar_type(value).map_err(at)?),
                "dimension" => h.rank = Some(dimension("dimension", value)?),
                "sizes" => {
                    h.sizes = Some(
                        value
                            .split_whitespace()
                            .map(|s| dimension("sizes", s))
                            .collect::<Result<Vec<_>, _>>()?,
                    );
                }
                "endian" => h.big_endian = value.eq_ignore_ascii_case("big"),
                "encoding" => {
                    h.gzip = match value.to_ascii_lowercase().as_str() {
                        "raw" => false,
                        "gzip" | "gz" => true,
                        other => {
                            return Err(at(format!(
                                "NRRD encoding {other:?} is not supported (raw or gzip)"
                            )));
                        }
                    };
                }
                "spacings" => {
                    h.spacings = Some(
                        value
                            .split_whitespace()
                            .map(|s| positive("spacings", s.parse().unwrap_or(f64::NAN)))
                            .collect::<Result<Vec<_>, _>>()?,
                    );
                }
                "space directions" => h.directions = Some(vectors(value).map_err(at)?),
                "space origin" => {
                    h.origin = vectors(value)
                        .map_err(at)?
                        .first()
                        .copied()
                        .flatten()
                        .ok_or_else(|| at("space origin must be a vector (x,y,z)".into()))?;
                }
                "data file" | "datafile" => h.data_file = Some(value.to_string()),
                "byte skip" | "byteskip" => {
                    h.byte_skip = value.parse().map_err(|_| {
                        at(format!(
                            "byte skip must be a non-negative integer, got {value:?}"
                        ))
                    })?;
                }
                _ => {}
            }
        }
        Ok(h)
    }

    /// The voxel steps as matrix columns: the space directions, else the spacings along the axes.
    fn voxel_steps(&self) -> Result<DMat3, Problem> {
        Ok(match (&self.directions, &self.spacings) {
            (Some(d), _) => {
                let cols: Vec<DVec3> = d.iter().flatten().copied().collect();
                let cols: [DVec3; 3] = cols
                    .try_into()
                    .map_err(|_| Problem::bad("NRRD space directions must give three vectors"))?;
                DMat3::from_cols(cols[0], cols[1], cols[2])
            }
            (None, Some(s)) => {
                let s: [f64; 3] = s
                    .as_slice()
                    .try_into()
                    .map_err(|_| Problem::bad("NRRD spacings must give three numbers"))?;
                DMat3::from_diagonal(DVec3::from_array(s))
            }
            (None, None) => DMat3::IDENTITY,
        })
    }
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// NRRD's type names (with their synonyms) for the types we read.
fn scalar_type(name: &str) -> Result<ScalarType, String> {
    Ok(match name.to_ascii_lowercase().as_str() {
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => ScalarType::U8,
        "signed char" | "int8" | "int8_t" => ScalarType::I8,
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => {
            ScalarType::U16
        }
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
            ScalarType::I16
        }
        "uint" | "unsigned int" | "uint32" | "uint32_t" => ScalarType::U32,
        "int" | "signed int" | "int32" | "int32_t" => ScalarType::I32,
        "float" => ScalarType::F32,
        "double" => ScalarType::F64,
        other => {
            return Err(format!(
                "NRRD type {other:?} is not supported (8/16/32-bit integers, float, double)"
            ));
        }
    })
}

/// A list of `(x,y,z)` vectors, `none` standing for a non-spatial axis.
fn vectors(value: &str) -> Result<Vec<Option<DVec3>>, String> {
    let mut out = Vec::new();
    let mut rest = value.trim();
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix("none") {
            out.push(None);
            rest = r.trim_start();
            continue;
        }
        let inner = rest
            .strip_prefix('(')
            .and_then(|r| r.split_once(')'))
            .ok_or_else(|| format!("expected a vector (x,y,z) in {value:?}"))?;
        let c: Vec<f64> = inner
            .0
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("expected numbers in the vector ({})", inner.0))?;
        let v: [f64; 3] = c
            .try_into()
            .map_err(|_| format!("expected three coordinates in ({})", inner.0))?;
        let v = DVec3::from_array(v);
        if !v.is_finite() {
            return Err(format!("the vector ({}) is not finite", inner.0));
        }
        out.push(Some(v));
        rest = inner.1.trim_start();
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Voxels;

    #[test]
    fn reads_attached_raw_and_gzip_data_with_directions() {
        let head = "NRRD0004\n# comment\ntype: short\ndimension: 3\nsizes: 2 1 1\nendian: big\n\
                    space directions: (0,2,0) (1,0,0) (0,0,3)\nspace origin: (1,2,3)\n";
        let mut raw = format!("{head}encoding: raw\n\n").into_bytes();
        raw.extend_from_slice(&[0xff, 0xfe, 0x00, 0x07]);
        let image = read(&raw, None).expect("valid");
        assert_eq!(image.voxels, Voxels::I16(vec![-2, 7]));
        assert_eq!(
            image.index_to_world.matrix3.x_axis,
            DVec3::new(0.0, 2.0, 0.0)
        );
        assert_eq!(image.index_to_world.translation, DVec3::new(1.0, 2.0, 3.0));

        use std::io::Write;
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        gz.write_all(&[0xff, 0xfe, 0x00, 0x07]).expect("in memory");
        let mut zipped = format!("{head}encoding: gzip\n\n").into_bytes();
        zipped.extend(gz.finish().expect("in memory"));
        assert_eq!(read(&zipped, None).expect("valid"), image);
    }

    #[test]
    fn bad_headers_are_errors() {
        let e = |s: &str| read(s.as_bytes(), None).unwrap_err().to_string();
        assert!(e("P5").contains("magic"));
        assert!(e("NRRD0004\ntype: short\ndimension: 2\nsizes: 2 2\n\n").contains("3D"));
        assert!(e("NRRD0004\ntype: quad\n\n").contains("not supported"));
        assert!(
            e("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 9 9 9\nencoding: raw\n\n\x01")
                .contains("truncated")
        );
        assert!(
            e("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\ndata file: x.raw\n")
                .contains("detached")
        );
    }
}
