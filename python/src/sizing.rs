//! The values `sizing=` takes besides a path: a Python callable of (x, y, z), or arrays in the
//! tagged tuples python/delamesh/__init__.py builds from numpy (native-endian bytes):
//! `("background", points, tets, values)` for a background tet mesh and `("points", points,
//! values)` for sizes at scattered points. The facade checks the values (naming the node or the
//! point), as it does for a file.

use crate::buffers::{read_f64, read_index, read_sizes};
use delamesh::core::refine::sizing::PointSizes;
use delamesh::{Point3, SizeSource};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};
use std::sync::Arc;

/// The size source of a `sizing=` value that is not a path, `None` for a path.
pub fn source(v: &Bound<'_, PyAny>) -> Result<Option<SizeSource>, String> {
    if v.is_callable() {
        let f: Py<PyAny> = v.clone().unbind();
        // Called with the GIL taken back: a value that is not a number, or an exception, is a
        // bad value (NaN) that the facade reports with its point; the Python layer keeps the
        // exception to raise it instead.
        return Ok(Some(SizeSource::function(move |p: Point3| {
            Python::attach(|py| {
                f.call1(py, (p.x, p.y, p.z))
                    .and_then(|r| r.extract::<f64>(py))
                    .unwrap_or(f64::NAN)
            })
        })));
    }
    let Ok(tuple) = v.cast::<PyTuple>() else {
        return Ok(None);
    };
    let py = v.py();
    let message = |e: PyErr| e.value(py).to_string();
    let part = |k: usize| -> Result<Vec<u8>, String> {
        let item = tuple.get_item(k).map_err(message)?;
        let bytes = item
            .cast::<PyBytes>()
            .map_err(|_| "expected arrays as bytes".to_string())?;
        Ok(bytes.as_bytes().to_vec())
    };
    let tag: String = tuple
        .get_item(0)
        .and_then(|t| t.extract())
        .map_err(|_| "expected a path, a callable or arrays".to_string())?;
    let positions = |bytes: &[u8]| -> Result<Vec<Point3>, String> {
        let flat = read_f64(bytes, 3, "sizing points").map_err(message)?;
        Ok(flat
            .chunks_exact(3)
            .map(|c| Point3::new(c[0], c[1], c[2]))
            .collect())
    };
    match (tag.as_str(), tuple.len()) {
        ("background", 4) => {
            let points = positions(&part(1)?)?;
            let flat = read_index(&part(2)?, 4, points.len(), "sizing tets").map_err(message)?;
            let tets = flat
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect();
            let values = read_sizes(&part(3)?, "sizing values").map_err(message)?;
            SizeSource::background(points, tets, values)
                .map(Some)
                .map_err(|e| format!("the background mesh: {e}"))
        }
        ("points", 3) => {
            let points = positions(&part(1)?)?;
            let values = read_sizes(&part(2)?, "sizing values").map_err(message)?;
            let cloud =
                PointSizes::new(&points, &values).map_err(|e| format!("the sized points: {e}"))?;
            Ok(Some(SizeSource::Field(Arc::new(cloud))))
        }
        _ => Err("expected a path, a callable or arrays".into()),
    }
}
