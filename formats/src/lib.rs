//! Readers and writers of mesh files: thin adapters over maintained crates (`gltf`, `tobj`, `stl_io`,
//! `ply-rs-bw`, `vtkio`), hand-written only where no crate exists (OFF, MEDIT, Gmsh, VTK writers).
//!
//! Entry points: [`read`], [`read_surface`], [`read_tet_mesh`], [`write_surface`], [`write_tet_mesh`].
//! Every read validates the mesh (finite coordinates, indices in range, not empty); every write is
//! atomic (temp file + rename) so a failure never leaves a partial file behind.

mod atomic;
mod error;
mod format;
mod gltf;
pub mod image;
mod legacy_vtk;
mod medit;
mod msh;
mod msh_read;
mod obj;
mod off;
mod ply;
mod points;
pub mod poly;
mod polygons;
pub mod pslg;
mod sizing;
mod sol;
mod stl;
mod text;
mod vtk;
mod vtk_cells;
mod vtu;

pub use error::{Error, Location, Problem, Result};
pub use format::{Format, UnknownFormat};
pub use points::{parse_point_sizes, parse_xyz, read_point_sizes, read_points};
pub use polygons::{PolygonMesh, read_polygon_bytes, read_polygons};
pub use sizing::{NodeField, read_node_field};

use delamesh_core::mesh::{MeshError, PatchId, SurfaceMesh, TetMesh, weld_exact};
use std::io::Write;
use std::path::Path;

/// What a file held: a surface, or a volume mesh (which may have no tets, only labelled triangles).
#[derive(Clone, Debug, PartialEq)]
pub enum AnyMesh {
    /// A triangle surface.
    Surface(SurfaceMesh),
    /// A tetrahedral mesh.
    Volume(TetMesh),
}

/// A mesh read from a file, with what the reader had to say about it.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshRead {
    /// The mesh.
    pub mesh: AnyMesh,
    /// Things skipped or repaired (unsupported primitives, sections we do not keep...).
    pub warnings: Vec<String>,
    /// Vertices merged by exact-position welding of triangle soups.
    pub welded_vertices: usize,
}

/// A surface read from a file (see [`read_surface`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceRead {
    /// The surface, welded.
    pub mesh: SurfaceMesh,
    /// Things skipped or repaired, as in [`MeshRead`].
    pub warnings: Vec<String>,
    /// Duplicate vertices merged by welding.
    pub welded_vertices: usize,
}

/// Options of the writers; the defaults are the compact binary variants.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// Overrides the format chosen from the extension.
    pub format: Option<Format>,
    /// ASCII `.vtu` / `.vtk` instead of binary.
    pub ascii: bool,
    /// Gmsh 2.2 instead of 4.1.
    pub msh22: bool,
}

fn resolve(path: &Path, format: Option<Format>) -> Result<Format, Problem> {
    format.or_else(|| Format::from_path(path)).ok_or_else(|| {
        Problem::Unsupported(format!(
            "cannot tell the format from the extension {:?}: use --format",
            path.extension()
                .map(|e| e.to_string_lossy().into_owned())
                .unwrap_or_default()
        ))
    })
}

/// Reads any supported mesh file; the format comes from the extension unless given.
pub fn read(path: &Path, format: Option<Format>) -> Result<MeshRead> {
    let run = || -> Result<MeshRead, Problem> {
        let format = resolve(path, format)?;
        if path.is_dir() {
            return Err(Problem::Unsupported(
                "is a directory, not a mesh file".into(),
            ));
        }
        let bytes = std::fs::read(path)?;
        read_bytes(&bytes, format, path.parent())
    };
    run().map_err(|p| Error::new(path, p))
}

/// Parses file contents already in memory (the fuzz targets' entry point). `dir` is where a glTF's
/// external buffers are looked up; `None` forbids external references.
pub fn read_bytes(bytes: &[u8], format: Format, dir: Option<&Path>) -> Result<MeshRead, Problem> {
    if bytes.is_empty() {
        return Err(Problem::bad("the file is empty"));
    }
    // A byte-order mark is text's business; STL decides for itself (a binary header is free-form).
    let bytes = if format == Format::Stl {
        bytes
    } else {
        text::strip_bom(bytes)
    };
    let mut warnings = Vec::new();
    let (mesh, soup) = match format {
        Format::Stl => (AnyMesh::Surface(stl::read(bytes)?), true),
        Format::Off => (AnyMesh::Surface(off::read(bytes)?), false),
        Format::Obj => {
            let (m, w) = obj::read(bytes)?;
            warnings = w;
            (AnyMesh::Surface(m), true)
        }
        Format::Gltf => {
            let (m, w) = gltf::read(bytes, dir)?;
            warnings = w;
            (AnyMesh::Surface(m), true)
        }
        Format::Ply => (AnyMesh::Surface(ply::read(bytes)?), false),
        Format::Medit => {
            let (m, w) = medit::read(bytes)?;
            warnings = w;
            (AnyMesh::Volume(m), false)
        }
        Format::Vtk | Format::Vtu | Format::Vtp => {
            let (m, w) = vtk::read(bytes, format)?;
            warnings = w;
            (m, false)
        }
        other => {
            return Err(Problem::Unsupported(format!(
                "reading {other} files is not supported"
            )));
        }
    };
    let mut welded_vertices = 0;
    let mesh = match mesh {
        AnyMesh::Surface(mut s) => {
            if soup {
                welded_vertices = weld_exact(&mut s.positions, &mut s.triangles);
            }
            if format == Format::Obj {
                // tobj copies shared vertices into every group; count only the file's own duplicates.
                welded_vertices = obj::vertex_count(bytes).saturating_sub(s.positions.len());
            }
            s.validate()?;
            AnyMesh::Surface(s)
        }
        AnyMesh::Volume(v) => {
            v.validate()?;
            AnyMesh::Volume(v)
        }
    };
    Ok(MeshRead {
        mesh,
        warnings,
        welded_vertices,
    })
}

/// Reads a surface; from a volume file, its boundary triangles (or the tets' exterior faces when the
/// file has no triangles).
pub fn read_surface(path: &Path, format: Option<Format>) -> Result<SurfaceRead> {
    let MeshRead {
        mesh,
        warnings,
        welded_vertices,
    } = read(path, format)?;
    let mesh = match mesh {
        AnyMesh::Surface(s) => s,
        AnyMesh::Volume(v) => surface_of(v),
    };
    Ok(SurfaceRead {
        mesh,
        warnings,
        welded_vertices,
    })
}

fn surface_of(mut v: TetMesh) -> SurfaceMesh {
    if v.boundary.is_empty() {
        v.boundary = v.exterior_faces();
        v.boundary_patches = vec![PatchId(0); v.boundary.len()];
    }
    v.boundary_surface()
}

/// Reads a tetrahedral mesh; a file without tetrahedra is an error.
pub fn read_tet_mesh(path: &Path, format: Option<Format>) -> Result<TetMesh> {
    match read(path, format)?.mesh {
        AnyMesh::Volume(v) if !v.tets.is_empty() => Ok(v),
        _ => Err(Error::new(
            path,
            Problem::Unsupported("the file holds no tetrahedra".into()),
        )),
    }
}

/// Checks, before any work, that a mesh could be written at `path`: the format is known (from
/// the extension unless given) and writable, and the folder exists and accepts a new file.
pub fn check_mesh_output(path: &Path, format: Option<Format>) -> Result<()> {
    let run = || -> Result<(), Problem> {
        let format = resolve(path, format)?;
        if matches!(format, Format::Gltf | Format::Vtp) {
            return Err(Problem::Unsupported(format!(
                "writing {format} files is not supported"
            )));
        }
        atomic::check_writable(path)
    };
    run().map_err(|p| Error::new(path, p))
}

/// Checks, before any work, that a document (a report) could be written at `path`.
pub fn check_document_output(path: &Path) -> Result<()> {
    atomic::check_writable(path).map_err(|p| Error::new(path, p))
}

/// Writes any other output (a JSON report, say) the way meshes are written: atomically, with the
/// permissions of an ordinary document, errors naming the file.
pub fn write_document(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    atomic::write_atomic(path, |w| body(w).map_err(Problem::Io)).map_err(|p| Error::new(path, p))
}

/// Writes a surface in any writable format (volume formats get a mesh of labelled triangles).
pub fn write_surface(path: &Path, mesh: &SurfaceMesh, options: &WriteOptions) -> Result<()> {
    write_valid(path, options, mesh.validate(), |w, format| {
        write_surface_to(w, mesh, format, options)
    })
}

/// Writes a tet mesh; surface formats get its boundary triangles.
pub fn write_tet_mesh(path: &Path, mesh: &TetMesh, options: &WriteOptions) -> Result<()> {
    write_valid(path, options, mesh.validate(), |w, format| {
        write_tet_mesh_to(w, mesh, format, options)
    })
}

/// Writes a mesh that passed its `validity` check atomically in the format the options or the
/// path's extension name; a problem, the check's first, becomes an error naming the file.
fn write_valid(
    path: &Path,
    options: &WriteOptions,
    validity: Result<(), MeshError>,
    body: impl FnOnce(&mut dyn Write, Format) -> Result<(), Problem>,
) -> Result<()> {
    let run = || -> Result<(), Problem> {
        validity?;
        let format = resolve(path, options.format)?;
        atomic::write_atomic(path, |w| body(w, format))
    };
    run().map_err(|p| Error::new(path, p))
}

/// Serialises a surface into `w` (no atomicity, no validation: see [`write_surface`]).
pub fn write_surface_to(
    w: &mut dyn Write,
    mesh: &SurfaceMesh,
    format: Format,
    options: &WriteOptions,
) -> Result<(), Problem> {
    match format {
        Format::Off => off::write(w, mesh),
        Format::Stl => stl::write(w, mesh),
        Format::Obj => obj::write(w, mesh),
        Format::Ply => ply::write(w, mesh),
        f if f.is_volume() => write_tet_mesh_to(w, &TetMesh::from(mesh.clone()), f, options),
        f => Err(Problem::Unsupported(format!(
            "writing {f} files is not supported"
        ))),
    }
}

/// Serialises a tet mesh into `w` (no atomicity, no validation: see [`write_tet_mesh`]).
pub fn write_tet_mesh_to(
    w: &mut dyn Write,
    mesh: &TetMesh,
    format: Format,
    options: &WriteOptions,
) -> Result<(), Problem> {
    match format {
        Format::Vtu => vtu::write(w, mesh, options.ascii),
        Format::Vtk => legacy_vtk::write(w, mesh, options.ascii),
        Format::Medit => medit::write(w, mesh),
        Format::Msh => msh::write(w, mesh, options.msh22),
        f if !f.is_volume() => write_surface_to(w, &surface_of(mesh.clone()), f, options),
        f => Err(Problem::Unsupported(format!(
            "writing {f} files is not supported"
        ))),
    }
}
