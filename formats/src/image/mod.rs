//! 3D images (segmented label maps, gray-level scans): INR (`.inr`), NIfTI-1 (`.nii`), VTK image
//! data (`.vti`) and NRRD (`.nrrd`, `.nhdr`), each optionally gzipped (`.gz`).
//!
//! Every reader gives the same [`Image`]: the voxel values in x-fastest order and the affine map
//! from voxel indices to world coordinates (voxel size, origin and, for NIfTI and NRRD, the axis
//! directions). A header is checked before any voxel buffer is allocated: the voxel count times the
//! voxel size must fit in the bytes the file holds, so a corrupt header claiming huge dimensions is
//! a one-line error, not an allocation failure.

mod inr;
mod nifti;
mod nrrd;
mod vti;

use crate::error::{Error, Problem, Result};
use glam::{DAffine3, DMat3, DVec3};
use std::io::Read;
use std::path::Path;

/// The scalar type of the voxels as stored in a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScalarType {
    /// Unsigned 8-bit integer.
    U8,
    /// Signed 8-bit integer.
    I8,
    /// Unsigned 16-bit integer.
    U16,
    /// Signed 16-bit integer.
    I16,
    /// Unsigned 32-bit integer.
    U32,
    /// Signed 32-bit integer.
    I32,
    /// 32-bit float.
    F32,
    /// 64-bit float.
    F64,
}

impl ScalarType {
    /// Bytes per voxel.
    pub fn size(self) -> usize {
        match self {
            ScalarType::U8 | ScalarType::I8 => 1,
            ScalarType::U16 | ScalarType::I16 => 2,
            ScalarType::U32 | ScalarType::I32 | ScalarType::F32 => 4,
            ScalarType::F64 => 8,
        }
    }
}

/// Voxel values, x fastest, then y, then z, in the type the file stores them.
#[derive(Clone, Debug, PartialEq)]
pub enum Voxels {
    /// Unsigned 8-bit integers.
    U8(Vec<u8>),
    /// Signed 8-bit integers.
    I8(Vec<i8>),
    /// Unsigned 16-bit integers.
    U16(Vec<u16>),
    /// Signed 16-bit integers.
    I16(Vec<i16>),
    /// Unsigned 32-bit integers.
    U32(Vec<u32>),
    /// Signed 32-bit integers.
    I32(Vec<i32>),
    /// 32-bit floats.
    F32(Vec<f32>),
    /// 64-bit floats.
    F64(Vec<f64>),
}

/// `$body` with `$v` bound to the values of whichever type `$voxels` holds: the methods that do
/// the same for every type say it once.
macro_rules! each_type {
    ($voxels:expr, $v:ident => $body:expr) => {
        match $voxels {
            Voxels::U8($v) => $body,
            Voxels::I8($v) => $body,
            Voxels::U16($v) => $body,
            Voxels::I16($v) => $body,
            Voxels::U32($v) => $body,
            Voxels::I32($v) => $body,
            Voxels::F32($v) => $body,
            Voxels::F64($v) => $body,
        }
    };
}

impl Voxels {
    /// Number of voxels.
    pub fn len(&self) -> usize {
        each_type!(self, v => v.len())
    }

    /// No voxel at all.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The scalar type the values are stored in.
    pub fn scalar_type(&self) -> ScalarType {
        match self {
            Voxels::U8(_) => ScalarType::U8,
            Voxels::I8(_) => ScalarType::I8,
            Voxels::U16(_) => ScalarType::U16,
            Voxels::I16(_) => ScalarType::I16,
            Voxels::U32(_) => ScalarType::U32,
            Voxels::I32(_) => ScalarType::I32,
            Voxels::F32(_) => ScalarType::F32,
            Voxels::F64(_) => ScalarType::F64,
        }
    }

    /// Value of voxel `i` (x-fastest index) as a double; every stored type converts exactly.
    #[allow(clippy::useless_conversion, reason = "the f64 arm converts to itself")]
    pub fn value(&self, i: usize) -> f64 {
        each_type!(self, v => f64::from(v[i]))
    }

    /// Decodes `bytes` (exactly `count × ty.size()` of them) in the given byte order.
    pub(crate) fn from_bytes(ty: ScalarType, bytes: &[u8], big_endian: bool) -> Voxels {
        macro_rules! decode {
            ($t:ty, $n:literal) => {
                bytes
                    .chunks_exact($n)
                    .map(|c| {
                        let mut a = [0u8; $n];
                        a.copy_from_slice(c);
                        if big_endian {
                            <$t>::from_be_bytes(a)
                        } else {
                            <$t>::from_le_bytes(a)
                        }
                    })
                    .collect()
            };
        }
        match ty {
            ScalarType::U8 => Voxels::U8(bytes.to_vec()),
            ScalarType::I8 => Voxels::I8(bytes.iter().map(|&b| b as i8).collect()),
            ScalarType::U16 => Voxels::U16(decode!(u16, 2)),
            ScalarType::I16 => Voxels::I16(decode!(i16, 2)),
            ScalarType::U32 => Voxels::U32(decode!(u32, 4)),
            ScalarType::I32 => Voxels::I32(decode!(i32, 4)),
            ScalarType::F32 => Voxels::F32(decode!(f32, 4)),
            ScalarType::F64 => Voxels::F64(decode!(f64, 8)),
        }
    }
}

/// A 3D image: voxel `(i, j, k)` holds `voxels[i + nx (j + ny k)]` and its centre lies at
/// `index_to_world.transform_point3((i, j, k))`.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Voxels along x, y and z.
    pub dims: [usize; 3],
    /// Voxel indices to world coordinates: the columns of the matrix are the steps between
    /// neighbouring voxel centres, the translation is the centre of voxel (0, 0, 0).
    pub index_to_world: DAffine3,
    /// The values.
    pub voxels: Voxels,
}

impl Image {
    /// An axis-aligned image: voxel size `spacing`, first voxel centre at `origin`.
    pub fn axis_aligned(dims: [usize; 3], spacing: DVec3, origin: DVec3, voxels: Voxels) -> Image {
        Image {
            dims,
            index_to_world: DAffine3::from_mat3_translation(DMat3::from_diagonal(spacing), origin),
            voxels,
        }
    }

    /// The distances between neighbouring voxel centres along i, j and k.
    pub fn spacing(&self) -> DVec3 {
        let m = self.index_to_world.matrix3;
        DVec3::new(m.x_axis.length(), m.y_axis.length(), m.z_axis.length())
    }

    /// Checks what the readers promise: dimensions match the voxel count, the index map is
    /// finite and invertible.
    pub fn validate(&self) -> Result<(), Problem> {
        let count = voxel_count(self.dims)?;
        if count != self.voxels.len() {
            return Err(Problem::bad(format!(
                "{} voxels for dimensions {:?}",
                self.voxels.len(),
                self.dims
            )));
        }
        let m = self.index_to_world.matrix3;
        let t = self.index_to_world.translation;
        let finite = m.to_cols_array().iter().all(|v| v.is_finite()) && t.is_finite();
        let det = m.determinant();
        if !finite || !det.is_finite() || det == 0.0 {
            return Err(Problem::bad(
                "the voxel size or orientation is not finite and non-zero",
            ));
        }
        Ok(())
    }
}

/// The image file formats, told apart by extension (a trailing `.gz` is allowed on all).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// INRIA's INR (`.inr`), the format of CGAL's examples.
    Inr,
    /// NIfTI-1 single file (`.nii`).
    Nifti,
    /// VTK XML image data (`.vti`).
    Vti,
    /// NRRD with attached (`.nrrd`) or detached (`.nhdr`) data.
    Nrrd,
}

impl ImageFormat {
    /// The image format named by the path's extension (case-insensitive; `.gz` is looked through).
    pub fn from_path(path: &Path) -> Option<ImageFormat> {
        let name = path.file_name()?.to_str()?.to_ascii_lowercase();
        let name = name.strip_suffix(".gz").unwrap_or(&name);
        let ext = name.rsplit_once('.')?.1;
        match ext {
            "inr" => Some(ImageFormat::Inr),
            "nii" => Some(ImageFormat::Nifti),
            "vti" => Some(ImageFormat::Vti),
            "nrrd" | "nhdr" => Some(ImageFormat::Nrrd),
            _ => None,
        }
    }
}

/// Is `path` named like a 3D image this module reads?
pub fn is_image_path(path: &Path) -> bool {
    ImageFormat::from_path(path).is_some()
}

/// Reads a 3D image; the format comes from the extension.
pub fn read_image(path: &Path) -> Result<Image> {
    let run = || -> Result<Image, Problem> {
        let format = ImageFormat::from_path(path).ok_or_else(|| {
            Problem::Unsupported(
                "not an image file name (expected .inr, .nii, .vti, .nrrd or .nhdr, optionally .gz)"
                    .into(),
            )
        })?;
        if path.is_dir() {
            return Err(Problem::Unsupported(
                "is a directory, not an image file".into(),
            ));
        }
        let bytes = gunzip_if_needed(std::fs::read(path)?)?;
        let image = read_image_bytes(&bytes, format, path.parent())?;
        image.validate()?;
        Ok(image)
    };
    run().map_err(|p| Error::new(path, p))
}

/// Parses an image already in memory (decompressed). `dir` is where NRRD's detached data files
/// are looked up; `None` forbids them.
pub fn read_image_bytes(
    bytes: &[u8],
    format: ImageFormat,
    dir: Option<&Path>,
) -> Result<Image, Problem> {
    if bytes.is_empty() {
        return Err(Problem::bad("the file is empty"));
    }
    match format {
        ImageFormat::Inr => inr::read(bytes),
        ImageFormat::Nifti => nifti::read(bytes),
        ImageFormat::Vti => vti::read(bytes),
        ImageFormat::Nrrd => nrrd::read(bytes, dir),
    }
}

/// Decompresses gzip data (recognised by its magic), else returns the bytes unchanged. Deflate
/// expands at most about 1032:1, so the output is bounded by the file size.
fn gunzip_if_needed(bytes: Vec<u8>) -> Result<Vec<u8>, Problem> {
    if !bytes.starts_with(&[0x1f, 0x8b]) {
        return Ok(bytes);
    }
    gunzip(&bytes)
}

/// Decompresses a gzip stream (several members allowed, as `cat a.gz b.gz` makes).
fn gunzip(bytes: &[u8]) -> Result<Vec<u8>, Problem> {
    // The last member's size (mod 2³²) ends the stream: reserved once instead of doubling the
    // buffer all the way, within what deflate can expand to.
    let mut out = Vec::new();
    if let Some(tail) = bytes.len().checked_sub(4).map(|n| &bytes[n..]) {
        let size = u32::from_le_bytes([tail[0], tail[1], tail[2], tail[3]]) as usize;
        out.reserve(size.min(bytes.len().saturating_mul(1032)));
    }
    flate2::read::MultiGzDecoder::new(bytes)
        .read_to_end(&mut out)
        .map_err(|e| Problem::bad(format!("corrupt gzip data: {e}")))?;
    Ok(out)
}

/// `nx × ny × nz`, each at least 1, without overflow.
fn voxel_count(dims: [usize; 3]) -> Result<usize, Problem> {
    if dims.contains(&0) {
        return Err(Problem::bad(format!(
            "image dimensions {dims:?} include a zero"
        )));
    }
    dims.iter()
        .try_fold(1usize, |n, &d| n.checked_mul(d))
        .ok_or_else(|| Problem::bad(format!("image dimensions {dims:?} overflow")))
}

/// The voxels of a `dims` image of type `ty` from `data`, which must hold at least that many
/// bytes: the count is checked against the bytes present before anything is allocated.
fn decode_voxels(
    dims: [usize; 3],
    ty: ScalarType,
    data: &[u8],
    big_endian: bool,
) -> Result<Voxels, Problem> {
    let need = voxel_count(dims)?
        .checked_mul(ty.size())
        .ok_or_else(|| Problem::bad(format!("image dimensions {dims:?} overflow")))?;
    if data.len() < need {
        return Err(Problem::bad(format!(
            "truncated voxel data: dimensions {dims:?} of {}-byte voxels need {need} bytes, the file has {}",
            ty.size(),
            data.len()
        )));
    }
    Ok(Voxels::from_bytes(ty, &data[..need], big_endian))
}

/// A positive finite voxel size, or an error naming the header field.
fn positive(name: &str, v: f64) -> Result<f64, Problem> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Problem::bad(format!(
            "{name} must be a positive number, got {v}"
        )))
    }
}

/// A dimension parsed from a header field, at least 1.
fn dimension(name: &str, value: &str) -> Result<usize, Problem> {
    value
        .trim()
        .parse::<usize>()
        .ok()
        .filter(|&d| d > 0)
        .ok_or_else(|| Problem::bad(format!("{name} must be a positive integer, got {value:?}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_from_names() {
        let f = |s: &str| ImageFormat::from_path(Path::new(s));
        assert_eq!(f("liver.inr.gz"), Some(ImageFormat::Inr));
        assert_eq!(f("a/b/Brain.NII.GZ"), Some(ImageFormat::Nifti));
        assert_eq!(f("x.vti"), Some(ImageFormat::Vti));
        assert_eq!(f("x.nhdr"), Some(ImageFormat::Nrrd));
        assert_eq!(f("x.stl"), None);
        assert_eq!(f("gz"), None);
    }

    #[test]
    fn huge_dimensions_are_refused_before_allocating() {
        let e = decode_voxels([1 << 20, 1 << 20, 1 << 20], ScalarType::U8, &[0; 16], false);
        assert!(e.unwrap_err().to_string().contains("truncated"));
        let e = decode_voxels([usize::MAX, 2, 2], ScalarType::U8, &[0; 16], false);
        assert!(e.unwrap_err().to_string().contains("overflow"));
    }

    #[test]
    fn decoding_honours_the_byte_order() {
        let le = Voxels::from_bytes(ScalarType::I16, &[0x01, 0x80], false);
        let be = Voxels::from_bytes(ScalarType::I16, &[0x80, 0x01], true);
        assert_eq!(le, be);
        assert_eq!(le.value(0), f64::from(i16::from_le_bytes([0x01, 0x80])));
    }
}
