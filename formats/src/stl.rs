//! STL through `stl_io` (ASCII and binary). STL is a triangle soup in f32: the caller welds it.

use crate::error::Problem;
use delamesh_core::mesh::{PatchId, SurfaceMesh};
use glam::DVec3;
use std::borrow::Cow;
use std::io::{Cursor, Write};

const HEADER: usize = 84;
const FACET: usize = 50;

pub(crate) fn read(bytes: &[u8]) -> Result<SurfaceMesh, Problem> {
    // A byte-order mark before `solid` makes an ASCII file (a binary header just starting with
    // those bytes keeps them: its size says so).
    let text_start = crate::text::strip_bom(bytes).trim_ascii_start();
    let binary_size = bytes.get(80..84).map(|c| {
        HEADER as u64 + FACET as u64 * u64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
    });
    let looks_ascii = text_start.starts_with(b"solid") && binary_size != Some(bytes.len() as u64);
    if !looks_ascii {
        match binary_size {
            None => {
                return Err(Problem::at_byte(
                    bytes.len() as u64,
                    "truncated binary STL: shorter than its 84-byte header",
                ));
            }
            Some(size) if size > bytes.len() as u64 => {
                return Err(Problem::at_byte(
                    bytes.len() as u64,
                    format!(
                        "truncated binary STL: the header announces {} triangles ({size} bytes), the file has {} bytes",
                        (size - HEADER as u64) / FACET as u64,
                        bytes.len()
                    ),
                ));
            }
            Some(_) => {}
        }
    }
    // stl_io decides ASCII by a first line starting with "solid ": give it a first line it reads the
    // way we decided (binary headers may start with "solid"; ASCII files may say just "solid").
    let input: Cow<[u8]> = if looks_ascii {
        let body = text_start
            .iter()
            .position(|&b| b == b'\n')
            .map_or(&[][..], |i| &text_start[i..]);
        let body = String::from_utf8_lossy(body);
        Cow::Owned([b"solid surface".as_slice(), body.as_bytes()].concat())
    } else if bytes.starts_with(b"solid") {
        let mut owned = bytes.to_vec();
        owned[..5].copy_from_slice(b"SOLID");
        Cow::Owned(owned)
    } else {
        Cow::Borrowed(bytes)
    };
    let mut cursor = Cursor::new(input.as_ref());
    let reader = stl_io::create_stl_reader(&mut cursor)
        .map_err(|e| Problem::bad(format!("not an STL file: {e}")))?;
    let mut positions = Vec::new();
    for (i, facet) in reader.enumerate() {
        let facet = facet.map_err(|e| {
            if looks_ascii {
                Problem::bad(format!("facet {i}: {e}"))
            } else {
                Problem::at_byte((HEADER + FACET * i) as u64, format!("facet {i}: {e}"))
            }
        })?;
        for v in facet.vertices {
            let p = DVec3::new(v[0].into(), v[1].into(), v[2].into());
            if !p.is_finite() {
                let msg = format!(
                    "facet {i} has a non-finite vertex ({}, {}, {})",
                    p.x, p.y, p.z
                );
                return Err(if looks_ascii {
                    Problem::bad(msg)
                } else {
                    Problem::at_byte((HEADER + FACET * i) as u64, msg)
                });
            }
            positions.push(p);
        }
    }
    let n = positions.len() as u32 / 3;
    let triangles = (0..n).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    Ok(SurfaceMesh {
        positions,
        triangles,
        patches: vec![PatchId(0); n as usize],
        patch_names: vec!["surface".into()],
    })
}

/// Binary STL; coordinates are rounded to f32, as the format demands.
pub(crate) fn write(w: &mut dyn Write, mesh: &SurfaceMesh) -> Result<(), Problem> {
    let f32s = |p: DVec3| stl_io::Vector::new([p.x as f32, p.y as f32, p.z as f32]);
    let facets: Vec<stl_io::Triangle> = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            stl_io::Triangle {
                normal: f32s((b - a).cross(c - a).normalize_or_zero()),
                vertices: [f32s(a), f32s(b), f32s(c)],
            }
        })
        .collect();
    let mut w = w;
    stl_io::write_stl(&mut w, facets.iter())?;
    Ok(())
}
