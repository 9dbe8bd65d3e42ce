//! VTK XML image data (`.vti`) through vtkio: the first one-component point-data array holds the
//! voxel values (VTK places image points at the voxel centres); without point data, the first
//! cell-data array, the voxels then being the cells between the points.
//!
//! `Origin`, `Spacing` and `Direction` are read from the `ImageData` tag itself, in double
//! precision (vtkio keeps them as `f32`).

use super::{Image, Voxels, positive};
use crate::error::{Problem, contain_panics};
use crate::vtk::raw_appended_to_base64;
use glam::{DAffine3, DMat3, DVec3};
use vtkio::model::{Attribute, DataSet, IOBuffer, Piece};

/// Parses a VTK image data file.
pub(crate) fn read(bytes: &[u8]) -> Result<Image, Problem> {
    if !bytes.trim_ascii_start().starts_with(b"<") {
        return Err(Problem::at_byte(
            0,
            "wrong magic: a .vti file starts with an XML tag",
        ));
    }
    let tag = image_data_tag(bytes)?;
    let numbers = |name: &str, n: usize| -> Result<Option<Vec<f64>>, Problem> {
        let Some(v) = attribute(&tag, name) else {
            return Ok(None);
        };
        let values: Vec<f64> = v
            .split_whitespace()
            .map(|s| s.parse::<f64>().ok().filter(|x| x.is_finite()))
            .collect::<Option<_>>()
            .filter(|v: &Vec<f64>| v.len() == n)
            .ok_or_else(|| Problem::bad(format!("{name}=\"{v}\" is not {n} numbers")))?;
        Ok(Some(values))
    };
    let origin = numbers("Origin", 3)?.map_or(DVec3::ZERO, |v| DVec3::new(v[0], v[1], v[2]));
    let spacing = numbers("Spacing", 3)?.map_or(Ok(DVec3::ONE), |v| {
        Ok::<_, Problem>(DVec3::new(
            positive("Spacing", v[0])?,
            positive("Spacing", v[1])?,
            positive("Spacing", v[2])?,
        ))
    })?;
    // VTK's direction matrix is row-major; its columns are the axis directions.
    let direction = numbers("Direction", 9)?.map_or(DMat3::IDENTITY, |d| {
        DMat3::from_cols_array(&[d[0], d[3], d[6], d[1], d[4], d[7], d[2], d[5], d[8]])
    });

    let reencoded = raw_appended_to_base64(bytes)?;
    let bytes = reencoded.as_deref().unwrap_or(bytes);
    let vtk = contain_panics(|| vtkio::Vtk::parse_xml(bytes))
        .map_err(|why| Problem::bad(format!("malformed VTK file (vtkio gave up: {why})")))?
        .map_err(|e| Problem::bad(format!("not a readable VTK file: {e}")))?;
    let DataSet::ImageData { extent, pieces, .. } = vtk.data else {
        return Err(Problem::Unsupported(
            "the VTK file holds no ImageData".into(),
        ));
    };
    let [p0, p1, p2] = extent.clone().into_ranges();
    let point_dims = [p0, p1, p2].map(|r| (i64::from(*r.end()) - i64::from(*r.start()) + 1).max(0));
    let start = extent.into_ranges().map(|r| f64::from(*r.start()));
    let mut pieces = pieces.into_iter();
    let (Some(piece), None) = (pieces.next(), pieces.next()) else {
        return Err(Problem::Unsupported(
            "only image data in one piece is supported".into(),
        ));
    };
    let Piece::Inline(piece) = piece else {
        return Err(Problem::Unsupported(
            "image data pieces in other files are not supported".into(),
        ));
    };
    let first_scalar = |attributes: &[Attribute]| {
        attributes.iter().find_map(|a| match a {
            Attribute::DataArray(d) if d.num_comp() == 1 => Some(d.data.clone()),
            _ => None,
        })
    };
    let to_usize = |d: i64| usize::try_from(d).unwrap_or(0);
    let (dims, shift, data) = match first_scalar(&piece.data.point) {
        Some(d) => (point_dims.map(to_usize), 0.0, d),
        None => {
            let d = first_scalar(&piece.data.cell).ok_or_else(|| {
                Problem::bad("the image data has no one-component point or cell array")
            })?;
            ((point_dims.map(|n| to_usize(n - 1).max(1))), 0.5, d)
        }
    };
    let voxels = voxels_of(dims, data)?;
    let steps = direction * DMat3::from_diagonal(spacing);
    let first = origin + steps * (DVec3::from_array(start) + DVec3::splat(shift));
    Ok(Image {
        dims,
        index_to_world: DAffine3::from_mat3_translation(steps, first),
        voxels,
    })
}

/// The attributes of the `<ImageData ...>` tag.
fn image_data_tag(bytes: &[u8]) -> Result<String, Problem> {
    let at = bytes
        .windows(b"<ImageData".len())
        .position(|w| w == b"<ImageData")
        .ok_or_else(|| Problem::Unsupported("the VTK file holds no ImageData".into()))?;
    let len = bytes[at..]
        .iter()
        .position(|&b| b == b'>')
        .ok_or_else(|| Problem::at_byte(at as u64, "unterminated ImageData tag"))?;
    Ok(String::from_utf8_lossy(&bytes[at..at + len]).into_owned())
}

/// The value of `name="..."` in a tag.
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let len = tag[start..].find('"')?;
    Some(&tag[start..start + len])
}

/// The voxel values of a vtkio buffer, checked against the dimensions.
fn voxels_of(dims: [usize; 3], data: IOBuffer) -> Result<Voxels, Problem> {
    let voxels = match data {
        IOBuffer::U8(v) => Voxels::U8(v),
        IOBuffer::I8(v) => Voxels::I8(v),
        IOBuffer::U16(v) => Voxels::U16(v),
        IOBuffer::I16(v) => Voxels::I16(v),
        IOBuffer::U32(v) => Voxels::U32(v),
        IOBuffer::I32(v) => Voxels::I32(v),
        IOBuffer::F32(v) => Voxels::F32(v),
        IOBuffer::F64(v) => Voxels::F64(v),
        _ => {
            return Err(Problem::Unsupported(
                "image values must be 8/16/32-bit integers or floats".into(),
            ));
        }
    };
    let count = super::voxel_count(dims)?;
    if voxels.len() != count {
        return Err(Problem::bad(format!(
            "{} voxel values for an extent of {dims:?}",
            voxels.len()
        )));
    }
    Ok(voxels)
}
