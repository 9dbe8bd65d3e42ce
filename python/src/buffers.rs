//! Meshes as flat native-endian buffers, the form they cross the language boundary in: float64
//! points, int64 vertex indices, int32 labels (saturated, as the VTK writers store them).

use crate::Error;
use delamesh::core::mesh::{CurveId, PatchId, SubdomainId};
use delamesh::formats::image::{Image, Voxels};
use delamesh::{Point3, SurfaceMesh, TetMesh};
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes, PyDict, PyList};

/// A mesh by blocks: tetrahedra, triangles, lines, each with its labels; per-tet float fields.
#[derive(Default)]
pub struct Raw {
    points: Vec<f64>,
    tetra: Vec<i64>,
    subdomain: Vec<i32>,
    triangle: Vec<i64>,
    patch: Vec<i32>,
    line: Vec<i64>,
    curve: Vec<i32>,
    fields: Vec<(String, Vec<f64>)>,
}

/// Labels are u32 in the model and int32 in files; the rare label above `i32::MAX` saturates.
fn label(x: u32) -> i32 {
    i32::try_from(x).unwrap_or(i32::MAX)
}

fn indices<const N: usize>(cells: &[[u32; N]]) -> Vec<i64> {
    cells.iter().flatten().map(|&v| i64::from(v)).collect()
}

fn xyz(points: &[Point3]) -> Vec<f64> {
    points.iter().flat_map(|p| p.to_array()).collect()
}

/// A tet mesh (the mesher's result, or a volume file) by blocks.
pub fn raw_of_tet_mesh(m: &TetMesh) -> Raw {
    Raw {
        points: xyz(&m.positions),
        tetra: indices(&m.tets),
        subdomain: m.subdomains.iter().map(|s| label(s.0)).collect(),
        triangle: indices(&m.boundary),
        patch: m.boundary_patches.iter().map(|p| label(p.0)).collect(),
        line: indices(&m.feature_edges),
        curve: m.feature_curves.iter().map(|c| label(c.0)).collect(),
        fields: m
            .cell_fields
            .iter()
            .map(|f| (f.name.clone(), f.values.clone()))
            .collect(),
    }
}

/// A surface file: triangles with their patches.
pub fn raw_of_surface(s: &SurfaceMesh) -> Raw {
    Raw {
        points: xyz(&s.positions),
        triangle: indices(&s.triangles),
        patch: s.patches.iter().map(|p| label(p.0)).collect(),
        ..Raw::default()
    }
}

fn bytearray<'py, T: Copy, const N: usize>(
    py: Python<'py>,
    values: &[T],
    to_bytes: fn(T) -> [u8; N],
) -> Bound<'py, PyByteArray> {
    let bytes: Vec<u8> = values.iter().flat_map(|&v| to_bytes(v)).collect();
    PyByteArray::new(py, &bytes)
}

/// int64 values as a `bytearray` (writable, so numpy's view of it is too).
pub fn bytes_of_i64<'py>(py: Python<'py>, values: &[i64]) -> Bound<'py, PyByteArray> {
    bytearray(py, values, i64::to_ne_bytes)
}

impl Raw {
    /// The buffers as a dict of `bytearray`s (`fields`: a list of `(name, bytearray)`).
    pub fn into_dict(self, py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("points", bytearray(py, &self.points, f64::to_ne_bytes))?;
        for (key, cells) in [
            ("tetra", &self.tetra),
            ("triangle", &self.triangle),
            ("line", &self.line),
        ] {
            d.set_item(key, bytes_of_i64(py, cells))?;
        }
        for (key, labels) in [
            ("subdomain", &self.subdomain),
            ("patch", &self.patch),
            ("curve", &self.curve),
        ] {
            d.set_item(key, bytearray(py, labels, i32::to_ne_bytes))?;
        }
        let fields = PyList::empty(py);
        for (name, values) in &self.fields {
            fields.append((name, bytearray(py, values, f64::to_ne_bytes)))?;
        }
        d.set_item("fields", fields)?;
        Ok(d)
    }

    /// The buffers of a dict with the keys of [`into_dict`](Self::into_dict) (`bytes` values;
    /// a missing key is an empty block).
    pub fn from_dict(d: &Bound<'_, PyDict>) -> PyResult<Raw> {
        let bytes = |key: &str| -> PyResult<Vec<u8>> {
            match d.get_item(key)? {
                Some(v) => Ok(v.cast::<PyBytes>()?.as_bytes().to_vec()),
                None => Ok(Vec::new()),
            }
        };
        let i64s = |key: &str| -> PyResult<Vec<i64>> {
            Ok(chunks(&bytes(key)?, key)?.map(i64::from_ne_bytes).collect())
        };
        let i32s = |key: &str| -> PyResult<Vec<i32>> {
            Ok(chunks(&bytes(key)?, key)?.map(i32::from_ne_bytes).collect())
        };
        Ok(Raw {
            points: chunks(&bytes("points")?, "points")?
                .map(f64::from_ne_bytes)
                .collect(),
            tetra: i64s("tetra")?,
            subdomain: i32s("subdomain")?,
            triangle: i64s("triangle")?,
            patch: i32s("patch")?,
            line: i64s("line")?,
            curve: i32s("curve")?,
            fields: Vec::new(),
        })
    }
}

/// `bytes` cut into values of `N` bytes, or an error naming `what` when they do not divide.
fn chunks<'a, const N: usize>(
    bytes: &'a [u8],
    what: &str,
) -> PyResult<impl Iterator<Item = [u8; N]> + 'a> {
    if bytes.len() % N != 0 {
        return Err(Error::new_err(format!(
            "{what}: {} bytes is not a whole number of {N}-byte values",
            bytes.len()
        )));
    }
    Ok(bytes
        .chunks_exact(N)
        .map(|c| <[u8; N]>::try_from(c).unwrap_or([0; N])))
}

/// float64 values, `per` to a row, all finite.
pub fn read_f64(bytes: &[u8], per: usize, what: &str) -> PyResult<Vec<f64>> {
    let values: Vec<f64> = chunks(bytes, what)?.map(f64::from_ne_bytes).collect();
    if values.len() % per != 0 {
        return Err(Error::new_err(format!("{what}: expected {per} columns")));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(Error::new_err(format!(
            "{what}: row {} has a coordinate that is not a finite number",
            i / per
        )));
    }
    Ok(values)
}

/// float64 values as given, NaN and infinities kept: the sizing fields' own checks name the node
/// holding a bad one.
pub fn read_sizes(bytes: &[u8], what: &str) -> PyResult<Vec<f64>> {
    Ok(chunks(bytes, what)?.map(f64::from_ne_bytes).collect())
}

/// int64 vertex indices, `per` to a row, each in `0..vertices`.
pub fn read_index(bytes: &[u8], per: usize, vertices: usize, what: &str) -> PyResult<Vec<u32>> {
    let values: Vec<i64> = chunks(bytes, what)?.map(i64::from_ne_bytes).collect();
    to_indices(&values, per, vertices, what)
}

fn to_indices(values: &[i64], per: usize, vertices: usize, what: &str) -> PyResult<Vec<u32>> {
    if values.len() % per != 0 {
        return Err(Error::new_err(format!("{what}: expected {per} columns")));
    }
    values
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            usize::try_from(v)
                .ok()
                .filter(|&u| u < vertices)
                .and_then(|u| u32::try_from(u).ok())
                .ok_or_else(|| {
                    Error::new_err(format!(
                        "{what}: row {} has the index {v}, not a vertex (there are {vertices})",
                        i / per
                    ))
                })
        })
        .collect()
}

/// Labels of one block: one per cell (none given: 0 each), none negative.
fn labels(values: &[i32], cells: usize, what: &str) -> PyResult<Vec<u32>> {
    if values.is_empty() {
        return Ok(vec![0; cells]);
    }
    if values.len() != cells {
        return Err(Error::new_err(format!(
            "{what}: {} labels for {cells} cells",
            values.len()
        )));
    }
    values
        .iter()
        .map(|&v| {
            u32::try_from(v)
                .map_err(|_| Error::new_err(format!("{what}: the label {v} is negative")))
        })
        .collect()
}

/// The tet mesh of the buffers, every index and label checked.
pub fn tet_mesh_of_raw(raw: &Raw) -> PyResult<TetMesh> {
    if raw.points.len() % 3 != 0 {
        return Err(Error::new_err("points: expected 3 columns"));
    }
    let n = raw.points.len() / 3;
    let rows = |values: &[i64], per: usize, what: &str| to_indices(values, per, n, what);
    let tets: Vec<[u32; 4]> = rows(&raw.tetra, 4, "tetra")?
        .chunks_exact(4)
        .map(|t| [t[0], t[1], t[2], t[3]])
        .collect();
    let boundary: Vec<[u32; 3]> = rows(&raw.triangle, 3, "triangle")?
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let feature_edges: Vec<[u32; 2]> = rows(&raw.line, 2, "line")?
        .chunks_exact(2)
        .map(|e| [e[0], e[1]])
        .collect();
    Ok(TetMesh {
        positions: raw
            .points
            .chunks_exact(3)
            .map(|p| Point3::new(p[0], p[1], p[2]))
            .collect(),
        subdomains: labels(&raw.subdomain, tets.len(), "subdomain")?
            .into_iter()
            .map(SubdomainId)
            .collect(),
        boundary_patches: labels(&raw.patch, boundary.len(), "patch")?
            .into_iter()
            .map(PatchId)
            .collect(),
        feature_curves: labels(&raw.curve, feature_edges.len(), "curve")?
            .into_iter()
            .map(CurveId)
            .collect(),
        tets,
        boundary,
        feature_edges,
        cell_fields: Vec::new(),
    })
}

/// The image of `dims` voxels of numpy type `dtype` in `bytes` (x fastest), every size checked.
pub fn image(
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    dtype: &str,
    bytes: &[u8],
) -> PyResult<Image> {
    let count = dims
        .iter()
        .try_fold(1usize, |n, &d| n.checked_mul(d))
        .filter(|&n| n > 0)
        .ok_or_else(|| Error::new_err(format!("image: {dims:?} voxels is no image")))?;
    if let Some(s) = spacing.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return Err(Error::new_err(format!(
            "voxel_size: must be positive numbers, got {s}"
        )));
    }
    if origin.iter().any(|o| !o.is_finite()) {
        return Err(Error::new_err("origin: must be finite numbers"));
    }
    macro_rules! voxels {
        ($variant:ident, $t:ty) => {
            Voxels::$variant(chunks(bytes, "image")?.map(<$t>::from_ne_bytes).collect())
        };
    }
    let voxels = match dtype {
        "u1" => voxels!(U8, u8),
        "i1" => voxels!(I8, i8),
        "u2" => voxels!(U16, u16),
        "i2" => voxels!(I16, i16),
        "u4" => voxels!(U32, u32),
        "i4" => voxels!(I32, i32),
        "f4" => voxels!(F32, f32),
        "f8" => voxels!(F64, f64),
        _ => {
            return Err(Error::new_err(format!(
                "image: voxels of type {dtype} are not read (integers of 8 to 32 bits, floats)"
            )));
        }
    };
    if voxels.len() != count {
        return Err(Error::new_err(format!(
            "image: {} voxels for dims {dims:?}",
            voxels.len()
        )));
    }
    Ok(Image::axis_aligned(
        dims,
        Point3::from_array(spacing),
        Point3::from_array(origin),
        voxels,
    ))
}
