//! PLY through `ply-rs-bw` (maintained fork of ply-rs): ASCII and binary of either endianness, any
//! scalar type for coordinates, faces as lists of any index type. Written as binary little endian
//! with double coordinates and an int `patch` per face.

use crate::error::Problem;
use crate::polygons::PolygonMesh;
use delamesh_core::mesh::{PatchId, SurfaceMesh, name_patch_labels};
use glam::DVec3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{
    Addable, DefaultElement, ElementDef, Encoding, Ply, Property, PropertyDef, PropertyType,
    ScalarType,
};
use ply_rs_bw::writer::Writer;
use std::io::{Cursor, Write};

/// The file with its header read as text (a Latin-1 byte in a comment would make the parser give
/// up), the body untouched (it may be binary).
fn text_header(bytes: &[u8]) -> std::borrow::Cow<'_, [u8]> {
    const END: &[u8] = b"end_header";
    let Some(end) = bytes.windows(END.len()).position(|w| w == END) else {
        return bytes.into();
    };
    let header = &bytes[..end];
    if std::str::from_utf8(header).is_ok() {
        return bytes.into();
    }
    let text = String::from_utf8_lossy(header);
    [text.as_bytes(), &bytes[end..]].concat().into()
}

fn number(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(x) => x.into(),
        Property::UChar(x) => x.into(),
        Property::Short(x) => x.into(),
        Property::UShort(x) => x.into(),
        Property::Int(x) => x.into(),
        Property::UInt(x) => x.into(),
        Property::Float(x) => x.into(),
        Property::Double(x) => x,
        _ => return None,
    })
}

fn index_list(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x.into()).collect(),
        _ => return None,
    })
}

pub(crate) fn read(bytes: &[u8]) -> Result<SurfaceMesh, Problem> {
    read_polygons(bytes).map(|m| m.triangulated())
}

/// The polygons as written (a subdivision control mesh), the `patch` property as groups.
pub(crate) fn read_polygons(bytes: &[u8]) -> Result<PolygonMesh, Problem> {
    let bytes = text_header(bytes);
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut Cursor::new(bytes.as_ref()))
        .map_err(|e| {
            // ply-rs-bw's messages run over several lines; the first says what and where.
            let msg = e.to_string();
            let first = msg.lines().next().unwrap_or("unknown error");
            match first.strip_prefix("Line ").and_then(|r| r.split_once(": ")) {
                Some((line, what)) if line.parse::<usize>().is_ok() => Problem::at_line(
                    line.parse().unwrap_or(0),
                    format!("not a readable PLY file: {what}"),
                ),
                _ => Problem::bad(format!("not a readable PLY file: {first}")),
            }
        })?;
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| Problem::bad("no vertex element"))?;
    let mut m = PolygonMesh::default();
    for (i, v) in vertices.iter().enumerate() {
        let coord = |name: &str| {
            v.get(name)
                .and_then(number)
                .ok_or_else(|| Problem::bad(format!("vertex {i} has no numeric property {name:?}")))
        };
        let p = DVec3::new(coord("x")?, coord("y")?, coord("z")?);
        if !p.is_finite() {
            return Err(Problem::bad(format!(
                "vertex {i} has a non-finite coordinate ({}, {}, {})",
                p.x, p.y, p.z
            )));
        }
        m.positions.push(p);
    }
    let n = m.positions.len() as i64;
    let faces = ply.payload.get("face").map_or(&[][..], Vec::as_slice);
    for (i, f) in faces.iter().enumerate() {
        let ids = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(index_list)
            .ok_or_else(|| Problem::bad(format!("face {i} has no vertex_indices list")))?;
        if ids.len() < 3 {
            return Err(Problem::bad(format!("face {i} has {} vertices", ids.len())));
        }
        if let Some(bad) = ids.iter().find(|&&v| v < 0 || v >= n) {
            return Err(Problem::bad(format!(
                "face {i} refers to vertex {bad}, there are {n} vertices"
            )));
        }
        let patch = f
            .get("patch")
            .and_then(number)
            .map_or(0, |x| x.max(0.0) as u32);
        m.faces.push(ids.iter().map(|&v| v as u32).collect());
        m.groups.push(PatchId(patch));
    }
    m.group_names = name_patch_labels(&mut m.groups);
    Ok(m)
}

pub(crate) fn write(w: &mut dyn Write, m: &SurfaceMesh) -> Result<(), Problem> {
    let mut ply = Ply::<DefaultElement>::new();
    ply.header.encoding = Encoding::BinaryLittleEndian;
    ply.header.comments.push("written by delamesh".into());
    let mut vertex = ElementDef::new("vertex".into());
    for c in ["x", "y", "z"] {
        vertex.properties.add(PropertyDef::new(
            c.into(),
            PropertyType::Scalar(ScalarType::Double),
        ));
    }
    ply.header.elements.add(vertex);
    let mut face = ElementDef::new("face".into());
    face.properties.add(PropertyDef::new(
        "vertex_indices".into(),
        PropertyType::List(ScalarType::UChar, ScalarType::Int),
    ));
    face.properties.add(PropertyDef::new(
        "patch".into(),
        PropertyType::Scalar(ScalarType::Int),
    ));
    ply.header.elements.add(face);
    let vertices = m
        .positions
        .iter()
        .map(|p| {
            let mut e = DefaultElement::new();
            e.insert("x".into(), Property::Double(p.x));
            e.insert("y".into(), Property::Double(p.y));
            e.insert("z".into(), Property::Double(p.z));
            e
        })
        .collect();
    ply.payload.insert("vertex".into(), vertices);
    let too_big =
        || Problem::Unsupported("more than 2^31 vertices or patches: too large for PLY int".into());
    let faces = m
        .triangles
        .iter()
        .zip(&m.patches)
        .map(|(t, p)| {
            let ids = t
                .iter()
                .map(|&v| i32::try_from(v).map_err(|_| too_big()))
                .collect::<Result<_, _>>()?;
            let mut e = DefaultElement::new();
            e.insert("vertex_indices".into(), Property::ListInt(ids));
            e.insert(
                "patch".into(),
                Property::Int(i32::try_from(p.0).map_err(|_| too_big())?),
            );
            Ok(e)
        })
        .collect::<Result<_, Problem>>()?;
    ply.payload.insert("face".into(), faces);
    let mut w = w;
    Writer::new()
        .write_ply(&mut w, &mut ply)
        .map_err(|e| Problem::bad(format!("PLY writer: {e}")))?;
    Ok(())
}
