//! INRIA's INR image format (CGAL's `Image_3` native format): a text header of `KEY=value` lines
//! padded with newlines to a multiple of 256 bytes, starting `#INRIMAGE-4#{` and ending `##}`,
//! then the raw voxels.
//!
//! Keys: `XDIM YDIM ZDIM` (dimensions), `VDIM` (components, must be 1), `TYPE` (`unsigned fixed`,
//! `signed fixed`, `float`), `PIXSIZE` (`8 bits` … `64 bits`), `CPU` (byte order: `decm`, `alpha`,
//! `pc` little-endian; `sun`, `sgi` big-endian), `VX VY VZ` (voxel size), `TX TY TZ` (origin).
//! Others (`SCALE`, `#GEOMETRY`, comments) are ignored.

use super::{Image, ScalarType, decode_voxels, dimension, positive};
use crate::error::Problem;
use glam::DVec3;

const MAGIC: &[u8] = b"#INRIMAGE-4#{";
const END: &[u8] = b"##}";
/// Headers longer than this are corrupt (real ones are 256 bytes, rarely 512 or 1024).
const MAX_HEADER: usize = 64 * 1024;

/// Parses an INR image.
pub(crate) fn read(bytes: &[u8]) -> Result<Image, Problem> {
    if !bytes.starts_with(MAGIC) {
        return Err(Problem::at_byte(
            0,
            "wrong magic: an INR file starts with \"#INRIMAGE-4#{\"",
        ));
    }
    let search = &bytes[..bytes.len().min(MAX_HEADER)];
    let end = search
        .windows(END.len())
        .position(|w| w == END)
        .ok_or_else(|| Problem::bad("truncated INR header: no closing \"##}\""))?;
    // The header (with its closing line) fills a multiple of 256 bytes.
    let header_len = (end + END.len() + 1).div_ceil(256) * 256;
    let text = std::str::from_utf8(&bytes[MAGIC.len()..end])
        .map_err(|_| Problem::bad("the INR header is not text"))?;

    let mut dims = [0usize; 3];
    let mut vdim = 1usize;
    let mut kind = None;
    let mut bits = None;
    let mut big_endian = false;
    let mut spacing = DVec3::ONE;
    let mut origin = DVec3::ZERO;
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let Some((key, value)) = line.split_once('=') else {
            return Err(Problem::at_line(
                n + 1,
                format!("INR header line {line:?} is not KEY=value"),
            ));
        };
        let value = value.trim();
        let number = |name: &str| -> Result<f64, Problem> {
            value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| Problem::bad(format!("{name} must be a number, got {value:?}")))
        };
        match key.trim() {
            "XDIM" => dims[0] = dimension("XDIM", value)?,
            "YDIM" => dims[1] = dimension("YDIM", value)?,
            "ZDIM" => dims[2] = dimension("ZDIM", value)?,
            "VDIM" => vdim = dimension("VDIM", value)?,
            "TYPE" => kind = Some(value.to_ascii_lowercase()),
            "PIXSIZE" => {
                bits = Some(
                    value
                        .split_whitespace()
                        .next()
                        .and_then(|b| b.parse::<u32>().ok())
                        .ok_or_else(|| {
                            Problem::bad(format!("PIXSIZE must be \"N bits\", got {value:?}"))
                        })?,
                );
            }
            "CPU" => {
                big_endian = match value.to_ascii_lowercase().as_str() {
                    "decm" | "alpha" | "pc" => false,
                    "sun" | "sgi" => true,
                    other => {
                        return Err(Problem::bad(format!(
                            "unknown CPU {other:?} (expected decm, alpha, pc, sun or sgi)"
                        )));
                    }
                };
            }
            "VX" => spacing.x = positive("VX", number("VX")?)?,
            "VY" => spacing.y = positive("VY", number("VY")?)?,
            "VZ" => spacing.z = positive("VZ", number("VZ")?)?,
            "TX" => origin.x = number("TX")?,
            "TY" => origin.y = number("TY")?,
            "TZ" => origin.z = number("TZ")?,
            _ => {}
        }
    }
    for (d, name) in dims.iter().zip(["XDIM", "YDIM", "ZDIM"]) {
        if *d == 0 {
            return Err(Problem::bad(format!("the INR header has no {name}")));
        }
    }
    if vdim != 1 {
        return Err(Problem::Unsupported(format!(
            "vector images (VDIM={vdim}) are not supported: give one value per voxel"
        )));
    }
    let kind = kind.ok_or_else(|| Problem::bad("the INR header has no TYPE"))?;
    let ty = scalar_type(&kind, bits)?;
    let data = bytes.get(header_len..).unwrap_or_default();
    let voxels = decode_voxels(dims, ty, data, big_endian)?;
    Ok(Image::axis_aligned(dims, spacing, origin, voxels))
}

/// The voxel type of `TYPE` and `PIXSIZE` (floats default to 32 bits, integers to 8).
fn scalar_type(kind: &str, bits: Option<u32>) -> Result<ScalarType, Problem> {
    Ok(match (kind, bits) {
        ("unsigned fixed", None | Some(8)) => ScalarType::U8,
        ("unsigned fixed", Some(16)) => ScalarType::U16,
        ("unsigned fixed", Some(32)) => ScalarType::U32,
        ("signed fixed", None | Some(8)) => ScalarType::I8,
        ("signed fixed", Some(16)) => ScalarType::I16,
        ("signed fixed", Some(32)) => ScalarType::I32,
        ("float", None | Some(32)) => ScalarType::F32,
        ("float", Some(64)) => ScalarType::F64,
        _ => {
            return Err(Problem::Unsupported(format!(
                "INR TYPE={kind} with PIXSIZE={} bits is not supported (8/16/32-bit integers, 32/64-bit floats)",
                bits.map_or("?".to_string(), |b| b.to_string())
            )));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Voxels;

    fn header(lines: &str) -> Vec<u8> {
        let mut h = format!("#INRIMAGE-4#{{\n{lines}\n").into_bytes();
        h.resize(252, b'\n');
        h.extend_from_slice(b"##}\n");
        h
    }

    #[test]
    fn reads_big_endian_signed_shorts_with_voxel_size_and_origin() {
        let mut bytes = header(
            "XDIM=2\nYDIM=1\nZDIM=1\nVDIM=1\nTYPE=signed fixed\nPIXSIZE=16 bits\nCPU=sun\nVX=0.5\nVY=2\nVZ=3\nTX=1\nTY=2\nTZ=3",
        );
        bytes.extend_from_slice(&[0xff, 0xfe, 0x00, 0x07]);
        let image = read(&bytes).expect("valid");
        assert_eq!(image.dims, [2, 1, 1]);
        assert_eq!(image.voxels, Voxels::I16(vec![-2, 7]));
        assert_eq!(image.spacing(), DVec3::new(0.5, 2.0, 3.0));
        assert_eq!(image.index_to_world.translation, DVec3::new(1.0, 2.0, 3.0));
    }

    #[test]
    fn bad_headers_and_truncated_data_are_errors() {
        let e = |b: &[u8]| read(b).unwrap_err().to_string();
        assert!(e(b"P3 not an image").contains("magic"));
        assert!(e(b"#INRIMAGE-4#{\nXDIM=2\n").contains("##}"));
        let mut b = header("XDIM=4\nYDIM=4\nZDIM=4\nTYPE=unsigned fixed\nPIXSIZE=8 bits");
        b.extend_from_slice(&[1, 2, 3]);
        assert!(e(&b).contains("truncated"));
        let b = header("XDIM=4\nYDIM=0\nZDIM=4\nTYPE=unsigned fixed");
        assert!(e(&b).contains("YDIM"));
        let b = header("XDIM=1\nYDIM=1\nZDIM=1\nTYPE=float\nPIXSIZE=16 bits");
        assert!(e(&b).contains("not supported"));
        let b = header("XDIM=1\nYDIM=1\nZDIM=1\nTYPE=unsigned fixed\nVX=-1");
        assert!(e(&b).contains("VX"));
    }
}
