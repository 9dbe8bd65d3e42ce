//! NIfTI-1 single-file images (`.nii`): the header is parsed by the `nifti` crate (byte order,
//! field layout, magic), the voxels are decoded here so that their count is checked against the
//! bytes present before anything is allocated.
//!
//! The voxel-to-world map is the sform when `sform_code > 0`, else the qform (quaternion, voxel
//! size, offset and the `pixdim[0]` handedness) when `qform_code > 0`, else the voxel size alone,
//! as the NIfTI-1 standard orders them. `scl_slope`/`scl_inter` scale gray values (labels are
//! normally stored unscaled, slope 0 or 1).

use super::{Image, ScalarType, Voxels, decode_voxels, dimension, positive};
use crate::error::Problem;
use glam::{DAffine3, DMat3, DQuat, DVec3};
use nifti::{Endianness, NiftiHeader, NiftiType};

/// Size of the NIfTI-1 header; the voxels follow at `vox_offset` (≥ 352 in a `.nii`).
const HEADER_BYTES: usize = 348;

/// Parses a NIfTI-1 image.
pub(crate) fn read(bytes: &[u8]) -> Result<Image, Problem> {
    if bytes.len() < HEADER_BYTES {
        return Err(Problem::bad(format!(
            "truncated NIfTI header: {} of {HEADER_BYTES} bytes",
            bytes.len()
        )));
    }
    let header = NiftiHeader::from_reader(bytes)
        .map_err(|e| Problem::bad(format!("not a NIfTI-1 header: {e}")))?;
    if &header.magic != b"n+1\0" {
        return Err(Problem::Unsupported(
            "a NIfTI header/image pair (.hdr/.img) is not supported: give a single .nii file"
                .into(),
        ));
    }
    let rank = usize::from(header.dim[0]);
    if !(1..=7).contains(&rank) {
        return Err(Problem::bad(format!(
            "NIfTI dim[0] = {rank} is not between 1 and 7"
        )));
    }
    let dim = |i: usize| -> Result<usize, Problem> {
        if i > rank {
            return Ok(1);
        }
        dimension(&format!("dim[{i}]"), &header.dim[i].to_string())
    };
    let dims = [dim(1)?, dim(2)?, dim(3)?];
    for i in 4..=rank {
        if dim(i)? != 1 {
            return Err(Problem::Unsupported(format!(
                "4D NIfTI images (dim[{i}] = {}) are not supported: give one 3D volume",
                header.dim[i]
            )));
        }
    }
    let ty = match header.data_type() {
        Ok(NiftiType::Uint8) => ScalarType::U8,
        Ok(NiftiType::Int8) => ScalarType::I8,
        Ok(NiftiType::Uint16) => ScalarType::U16,
        Ok(NiftiType::Int16) => ScalarType::I16,
        Ok(NiftiType::Uint32) => ScalarType::U32,
        Ok(NiftiType::Int32) => ScalarType::I32,
        Ok(NiftiType::Float32) => ScalarType::F32,
        Ok(NiftiType::Float64) => ScalarType::F64,
        _ => {
            return Err(Problem::Unsupported(format!(
                "NIfTI datatype {} is not supported (8/16/32-bit integers, 32/64-bit floats)",
                header.datatype
            )));
        }
    };
    let offset = header.vox_offset;
    if !(offset.is_finite() && offset >= HEADER_BYTES as f32) {
        return Err(Problem::bad(format!(
            "NIfTI vox_offset {offset} lies inside the header"
        )));
    }
    let data = bytes.get(offset as usize..).unwrap_or_default();
    let big_endian = header.endianness == Endianness::Big;
    let voxels = scaled(
        decode_voxels(dims, ty, data, big_endian)?,
        header.scl_slope,
        header.scl_inter,
    );
    Ok(Image {
        dims,
        index_to_world: index_to_world(&header)?,
        voxels,
    })
}

/// Applies the intensity scaling when the header asks for one.
fn scaled(voxels: Voxels, slope: f32, inter: f32) -> Voxels {
    let identity = slope == 0.0 || !slope.is_finite() || (slope == 1.0 && inter == 0.0);
    if identity || !inter.is_finite() {
        return voxels;
    }
    let (slope, inter) = (f64::from(slope), f64::from(inter));
    Voxels::F64(
        (0..voxels.len())
            .map(|i| voxels.value(i) * slope + inter)
            .collect(),
    )
}

/// The voxel-to-world map of the header (sform, else qform, else voxel size).
fn index_to_world(h: &NiftiHeader) -> Result<DAffine3, Problem> {
    let f = |v: f32| f64::from(v);
    if h.sform_code > 0 {
        let row = |r: [f32; 4]| DVec3::new(f(r[0]), f(r[1]), f(r[2]));
        let m = DMat3::from_cols_array_2d(&[
            row(h.srow_x).to_array(),
            row(h.srow_y).to_array(),
            row(h.srow_z).to_array(),
        ])
        .transpose();
        let t = DVec3::new(f(h.srow_x[3]), f(h.srow_y[3]), f(h.srow_z[3]));
        return Ok(DAffine3::from_mat3_translation(m, t));
    }
    let spacing = DVec3::new(
        positive("pixdim[1]", f(h.pixdim[1]).abs())?,
        positive("pixdim[2]", f(h.pixdim[2]).abs())?,
        positive("pixdim[3]", f(h.pixdim[3]).abs())?,
    );
    if h.qform_code > 0 {
        let (b, c, d) = (f(h.quatern_b), f(h.quatern_c), f(h.quatern_d));
        let a = (1.0 - (b * b + c * c + d * d)).max(0.0).sqrt();
        let rotation = DMat3::from_quat(DQuat::from_xyzw(b, c, d, a).normalize());
        // pixdim[0] = -1 flips the third axis (left-handed voxel grids).
        let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let scale = DMat3::from_diagonal(DVec3::new(spacing.x, spacing.y, qfac * spacing.z));
        let t = DVec3::new(f(h.quatern_x), f(h.quatern_y), f(h.quatern_z));
        return Ok(DAffine3::from_mat3_translation(rotation * scale, t));
    }
    Ok(DAffine3::from_mat3_translation(
        DMat3::from_diagonal(spacing),
        DVec3::ZERO,
    ))
}
