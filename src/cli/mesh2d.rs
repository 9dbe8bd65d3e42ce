//! `delamesh mesh2d`: quality triangle mesh of a planar straight-line graph (Ruppert/Shewchuk).

use super::output::outln;
use anyhow::{Context, Result};
use delamesh_core::mesh::{CurveId, PatchId, TetMesh};
use delamesh_core::mesh2d::Point2;
use delamesh_core::mesh2d::mesher::{MeshOptions, mesh};
use delamesh_formats::WriteOptions;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Input planar straight-line graph: Triangle `.poly` (points, segments, holes, regions), or
    /// polylines in the z = 0 plane from OBJ `l` lines or VTK line cells (`.vtk`, `.vtu`, `.vtp`),
    /// which cannot mark holes: see `--hole`.
    pub input: PathBuf,
    /// A point inside a hole, as `X,Y` (repeat for several holes; added to the holes of a `.poly`).
    #[arg(long = "hole", value_name = "X,Y", value_parser = parse_point)]
    pub holes: Vec<Point2>,
    /// Output mesh (`.vtu`, `.vtk`, `.mesh`, `.msh`...): domain triangles in the z = 0 plane, with
    /// the region attribute as `patch`, and the constraint sub-segments as lines.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Smallest angle of the triangles, in degrees (at most 34).
    #[arg(long, default_value_t = 20.0)]
    pub min_angle: f64,
    /// Largest triangle area (regions of the `.poly` file may set their own).
    #[arg(long)]
    pub max_area: Option<f64>,
    /// Stop with an error beyond this many vertices.
    #[arg(long, default_value_t = 10_000_000)]
    pub max_vertices: usize,
}

pub fn run(args: &Args) -> Result<()> {
    delamesh_formats::check_mesh_output(&args.output, None)?;
    let mut pslg = delamesh_formats::pslg::read_pslg(&args.input)?;
    pslg.holes.extend(&args.holes);
    let start = std::time::Instant::now();
    let options = MeshOptions {
        min_angle_deg: args.min_angle,
        max_area: args.max_area,
        max_vertices: args.max_vertices,
    };
    let m = mesh(&pslg, &options).with_context(|| format!("meshing {}", args.input.display()))?;
    let elapsed = start.elapsed();
    let worst = m.smallest_angle_deg();
    write_planar_mesh(
        &args.output,
        &m.points,
        &m.triangles,
        &patches(&m.triangle_attributes),
        &m.segments,
        &m.segment_origins,
    )?;
    outln!(
        "{} vertices, {} triangles, {} sub-segments, smallest angle {:.2}°, {:.6} s -> {}",
        m.points.len(),
        m.triangles.len(),
        m.segments.len(),
        worst,
        elapsed.as_secs_f64(),
        args.output.display()
    )?;
    Ok(())
}

/// A finite point given as `X,Y`.
fn parse_point(s: &str) -> Result<Point2, String> {
    let coords: Vec<f64> = s
        .split(',')
        .map(|w| w.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{s:?} is not X,Y: {e}"))?;
    match coords[..] {
        [x, y] if x.is_finite() && y.is_finite() => Ok(Point2::new(x, y)),
        _ => Err(format!("{s:?} is not X,Y with two finite numbers")),
    }
}

/// Patch ids for regional attributes: the attribute itself when it is a small non-negative
/// integer (the usual case), otherwise its rank among the distinct attributes.
fn patches(attributes: &[f64]) -> Vec<PatchId> {
    let integral = attributes
        .iter()
        .all(|&a| a >= 0.0 && a.fract() == 0.0 && a < 1e6);
    if integral {
        return attributes.iter().map(|&a| PatchId(a as u32)).collect();
    }
    let mut distinct: Vec<f64> = attributes.to_vec();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup();
    attributes
        .iter()
        .map(|a| PatchId(distinct.partition_point(|d| d.total_cmp(a).is_lt()) as u32))
        .collect()
}

/// Writes a planar triangle mesh to `output` in the z = 0 plane, as the writers' mesh model
/// (triangles and lines): what `mesh2d` and `conform2d` both produce.
pub fn write_planar_mesh(
    output: &Path,
    points: &[Point2],
    triangles: &[[u32; 3]],
    patches: &[PatchId],
    segments: &[[u32; 2]],
    segment_origins: &[u32],
) -> Result<()> {
    let mesh = TetMesh {
        positions: points.iter().map(|p| p.extend(0.0)).collect(),
        boundary: triangles.to_vec(),
        boundary_patches: patches.to_vec(),
        feature_edges: segments.to_vec(),
        feature_curves: segment_origins.iter().map(|&s| CurveId(s)).collect(),
        ..TetMesh::default()
    };
    delamesh_formats::write_tet_mesh(output, &mesh, &WriteOptions::default())?;
    Ok(())
}
