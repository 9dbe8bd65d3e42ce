//! `delamesh._delamesh`: the extension module under the Python package `delamesh`
//! (python/delamesh/__init__.py). It calls the library facade (`Mesher`, `MeshSettings`,
//! `info::describe`, `delaunay`, the formats crate) and exchanges flat native-endian buffers
//! (`bytes` in, `bytearray` out) that the Python layer views as numpy arrays and wraps in a
//! `meshio.Mesh`, so that this module needs neither numpy nor meshio at build time.

mod buffers;
mod options;
mod sizing;

use buffers::{Raw, raw_of_surface, raw_of_tet_mesh, read_f64, read_index, tet_mesh_of_raw};
use delamesh::formats::image::Image;
use delamesh::formats::{AnyMesh, WriteOptions};
use delamesh::{Cancel, MeshSettings, Mesher, Point3, Progress, SurfaceMesh};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

pyo3::create_exception!(
    delamesh,
    Error,
    PyValueError,
    "Bad input, option or file: the message is the command line's."
);

/// The facade's error as `delamesh.Error`, its causes joined as the command line prints them.
fn error(e: &(dyn std::error::Error + 'static)) -> PyErr {
    let mut message = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        message.push_str(": ");
        message.push_str(&s.to_string());
        source = s.source();
    }
    Error::new_err(message)
}

/// How often, at most, a run takes the GIL back to call `progress`.
const CHECK_EVERY: Duration = Duration::from_millis(100);

/// How often the calling thread looks for a pending signal (Ctrl-C) while a run meshes.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Stack of the thread a run meshes on: a main thread's usual size.
const WORKER_STACK: usize = 8 << 20;

/// Where a mesh comes from.
enum Source {
    File(PathBuf),
    Surface(SurfaceMesh),
    Image(Image),
}

/// What a run gives back: the mesh, its warnings, why it stopped early if it did.
type Outcome = (Raw, Vec<String>, Option<String>);

/// Meshes `source` with `options` on a worker thread, with the GIL released. The calling
/// thread waits, and every [`SIGNAL_POLL`] takes the GIL to run pending signal handlers, in
/// every phase of the run (signals reach the main thread only); the worker calls `progress`
/// every [`CHECK_EVERY`] during refinement. An exception from either raises the cancel flag
/// and is what the call raises.
fn run(
    py: Python<'_>,
    source: Source,
    settings: MeshSettings,
    progress: Option<Py<PyAny>>,
) -> PyResult<Py<PyDict>> {
    let warnings: Vec<String> = settings.warnings();
    let cancel = Cancel::new();
    let raised: Mutex<Option<PyErr>> = Mutex::new(None);
    let stop = |e: PyErr| {
        let mut first = raised.lock().unwrap_or_else(PoisonError::into_inner);
        first.get_or_insert(e);
        cancel.cancel();
    };
    let outcome = py.detach(|| {
        std::thread::scope(|scope| {
            let (done, finished) = mpsc::channel::<()>();
            let worker = std::thread::Builder::new()
                .stack_size(WORKER_STACK)
                .spawn_scoped(scope, || {
                    let _done = done;
                    let mut last = Instant::now();
                    let hook = |p: &Progress| {
                        let Some(f) = &progress else { return };
                        if last.elapsed() < CHECK_EVERY || cancel.is_cancelled() {
                            return;
                        }
                        last = Instant::now();
                        Python::attach(|py| {
                            if let Err(e) = progress_dict(py, p).and_then(|d| f.call1(py, (d,))) {
                                stop(e);
                            }
                        });
                    };
                    mesh_source(source, settings, warnings, hook, &cancel)
                })
                .map_err(|e| Error::new_err(format!("cannot start the meshing thread: {e}")))?;
            while let Err(RecvTimeoutError::Timeout) = finished.recv_timeout(SIGNAL_POLL) {
                Python::attach(|py| {
                    if let Err(e) = py.check_signals() {
                        stop(e);
                    }
                });
            }
            match worker.join() {
                Ok(outcome) => Ok::<_, PyErr>(outcome),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        })
    })?;
    if let Some(e) = raised.into_inner().unwrap_or_else(PoisonError::into_inner) {
        return Err(e);
    }
    let (raw, notes, stopped) = outcome.map_err(|e| error(&e))?;
    let dict = raw.into_dict(py)?;
    dict.set_item("warnings", PyList::new(py, notes)?)?;
    dict.set_item("stopped", stopped)?;
    Ok(dict.unbind())
}

/// Meshes `source` through the facade, with `progress` as its hook and `cancel` as its flag.
fn mesh_source(
    source: Source,
    settings: MeshSettings,
    warnings: Vec<String>,
    progress: impl FnMut(&Progress),
    cancel: &Cancel,
) -> Result<Outcome, delamesh::Error> {
    let mut mesher = Mesher::new(settings)
        .on_progress(progress)
        .cancel_on(cancel.clone());
    let meshed = match source {
        Source::File(path) => mesher.mesh_file(&path),
        Source::Surface(surface) => mesher.mesh_surface(SURFACE, surface),
        Source::Image(image) => mesher.mesh_image(IMAGE, image),
    }?;
    let mut notes = warnings;
    let repairs = meshed.domain().repairs();
    if !repairs.is_empty() {
        notes.push(format!(
            "{}: repaired: {}",
            meshed.name(),
            repairs.join("; ")
        ));
    }
    notes.extend(
        meshed
            .warnings
            .iter()
            .map(|w| format!("{}: {w}", meshed.name())),
    );
    let stopped = meshed
        .stopped
        .as_ref()
        .map(|e| format!("{}: stopped early: {e}", meshed.name()));
    Ok((raw_of_tet_mesh(&meshed.tet_mesh()), notes, stopped))
}

/// The name of an in-memory surface in messages.
const SURFACE: &str = "the input surface";
/// The name of an in-memory image in messages.
const IMAGE: &str = "the input image";

fn progress_dict<'py>(py: Python<'py>, p: &Progress) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("vertices", p.vertices)?;
    d.set_item("insertions", p.insertions)?;
    let pending = PyDict::new(py);
    for (name, n) in &p.pending {
        pending.set_item(*name, *n)?;
    }
    d.set_item("pending", pending)?;
    Ok(d)
}

/// Meshes the surface or image in the file `path`.
#[pyfunction]
#[pyo3(signature = (path, options=None, progress=None))]
fn mesh_file(
    py: Python<'_>,
    path: PathBuf,
    options: Option<&Bound<'_, PyDict>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Py<PyDict>> {
    run(
        py,
        Source::File(path),
        options::settings(options)?,
        progress,
    )
}

/// Meshes the closed surface of `vertices` (float64, 3 per vertex) and `faces` (int64, 3 per
/// triangle), given as native-endian bytes.
#[pyfunction]
#[pyo3(signature = (vertices, faces, options=None, progress=None))]
fn mesh_surface(
    py: Python<'_>,
    vertices: &[u8],
    faces: &[u8],
    options: Option<&Bound<'_, PyDict>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Py<PyDict>> {
    let positions = read_f64(vertices, 3, "vertices")?;
    let triangles = read_index(faces, 3, positions.len() / 3, "faces")?;
    let surface = SurfaceMesh::from_triangles(
        positions
            .chunks_exact(3)
            .map(|p| Point3::new(p[0], p[1], p[2]))
            .collect(),
        triangles
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
    );
    run(
        py,
        Source::Surface(surface),
        options::settings(options)?,
        progress,
    )
}

/// Meshes the labels of a 3D image: `dims` voxels (x, y, z) of numpy type `dtype` (`u1`, `i1`,
/// `u2`, `i2`, `u4`, `i4`, `f4`, `f8`) in native-endian bytes, x fastest; voxel centres at
/// `origin + index * spacing`.
#[pyfunction]
#[pyo3(signature = (dims, spacing, origin, dtype, voxels, options=None, progress=None))]
#[allow(clippy::too_many_arguments)] // the image's own description, then the call's
fn mesh_image(
    py: Python<'_>,
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    dtype: &str,
    voxels: &[u8],
    options: Option<&Bound<'_, PyDict>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Py<PyDict>> {
    let image = buffers::image(dims, spacing, origin, dtype, voxels)?;
    run(
        py,
        Source::Image(image),
        options::settings(options)?,
        progress,
    )
}

/// The Delaunay tetrahedra of `points` (float64 bytes, 3 per point), as int64 bytes, 4 indices
/// into `points` per tetrahedron (a duplicate point's first occurrence).
#[pyfunction]
fn delaunay(py: Python<'_>, points: &[u8]) -> PyResult<Py<PyAny>> {
    let xyz = read_f64(points, 3, "points")?;
    let points: Vec<Point3> = xyz
        .chunks_exact(3)
        .map(|p| Point3::new(p[0], p[1], p[2]))
        .collect();
    let t = py
        .detach(|| delamesh::delaunay("points", &points))
        .map_err(|e| error(&e))?;
    // The first input point of each vertex.
    let mut first = vec![u32::MAX; t.mesh.positions.len()];
    for (i, &v) in t.vertex_of_point.iter().enumerate().rev() {
        if let Some(slot) = first.get_mut(v as usize) {
            *slot = i as u32;
        }
    }
    let cells: Vec<i64> = t
        .mesh
        .tets
        .iter()
        .flatten()
        .map(|&v| i64::from(first[v as usize]))
        .collect();
    Ok(buffers::bytes_of_i64(py, &cells).into_any().unbind())
}

/// The JSON object of `delamesh info --json` for the mesh file `path`, as a string.
#[pyfunction]
fn info(py: Python<'_>, path: PathBuf) -> PyResult<String> {
    let described = py
        .detach(|| delamesh::info::describe(&path, None))
        .map_err(|e| error(&e))?;
    Ok(described.json.to_string())
}

/// The mesh in the file `path` (a surface or a volume mesh), as flat buffers.
#[pyfunction]
fn read(py: Python<'_>, path: PathBuf) -> PyResult<Py<PyDict>> {
    let read = py
        .detach(|| delamesh::formats::read(&path, None))
        .map_err(|e| error(&e))?;
    let raw = match &read.mesh {
        AnyMesh::Surface(s) => raw_of_surface(s),
        AnyMesh::Volume(v) => raw_of_tet_mesh(v),
    };
    let dict = raw.into_dict(py)?;
    dict.set_item("warnings", PyList::new(py, &read.warnings)?)?;
    Ok(dict.unbind())
}

/// Writes the mesh of flat buffers `raw` to `path`, the format from the extension (a volume
/// format, or a surface format for the triangles only).
#[pyfunction]
#[pyo3(signature = (path, raw, ascii=false))]
fn write(py: Python<'_>, path: PathBuf, raw: &Bound<'_, PyDict>, ascii: bool) -> PyResult<()> {
    let mesh = tet_mesh_of_raw(&Raw::from_dict(raw)?)?;
    let options = WriteOptions {
        ascii,
        ..WriteOptions::default()
    };
    py.detach(|| {
        if mesh.tets.is_empty() {
            delamesh::formats::write_surface(&path, &mesh.boundary_surface(), &options)
        } else {
            delamesh::formats::write_tet_mesh(&path, &mesh, &options)
        }
    })
    .map_err(|e| error(&e))
}

/// The keyword options `mesh` takes, in the order of the command line's help.
#[pyfunction]
fn option_names() -> Vec<&'static str> {
    options::OPTIONS.iter().map(|o| o.name).collect()
}

#[pymodule]
fn _delamesh(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Error", m.py().get_type::<Error>())?;
    m.add_function(wrap_pyfunction!(mesh_file, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_surface, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_image, m)?)?;
    m.add_function(wrap_pyfunction!(delaunay, m)?)?;
    m.add_function(wrap_pyfunction!(info, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(write, m)?)?;
    m.add_function(wrap_pyfunction!(option_names, m)?)?;
    Ok(())
}
