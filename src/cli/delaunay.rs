//! `delamesh delaunay`: the Delaunay tetrahedralisation of a point set, to try the kernel alone.

use anyhow::{Context, Result, bail};
use clap::Args;
use delamesh_core::mesh::{PatchId, SubdomainId, TetMesh};
use delamesh_core::triangulation::{Delaunay3, Triangulation};
use delamesh_formats::{Format, WriteOptions};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct DelaunayArgs {
    /// Points: `x y z` lines (.xyz, .pts, .txt) or any mesh file whose vertices are taken.
    input: PathBuf,
    /// Output tet mesh (.vtu, .vtk, .mesh, .msh); the convex hull is written as boundary triangles.
    #[arg(short, long)]
    output: PathBuf,
    /// Read the input as this format instead of guessing from its extension.
    #[arg(long)]
    format: Option<Format>,
    /// Write ASCII instead of binary where the format has both.
    #[arg(long)]
    ascii: bool,
}

pub fn run(args: &DelaunayArgs) -> Result<()> {
    let points = delamesh_formats::read_points(&args.input, args.format)?;
    let start = Instant::now();
    let dt = Delaunay3::from_points(&points)
        .with_context(|| format!("{}: cannot triangulate", args.input.display()))?;
    let elapsed = start.elapsed();
    if dt.num_finite_cells() == 0 {
        bail!(
            "{}: the {} distinct points are coplanar, collinear or fewer than 4: no tetrahedra",
            args.input.display(),
            dt.num_vertices()
        );
    }
    let mesh = tet_mesh_of(&dt);
    eprintln!(
        "{} points ({} distinct) -> {} tets, {} hull triangles in {:.3} s",
        points.len(),
        dt.num_vertices(),
        mesh.tets.len(),
        mesh.boundary.len(),
        elapsed.as_secs_f64()
    );
    let options = WriteOptions {
        ascii: args.ascii,
        ..WriteOptions::default()
    };
    delamesh_formats::write_tet_mesh(&args.output, &mesh, &options)?;
    Ok(())
}

/// The finite cells as tets of subdomain 1 and the hull facets (finite facets of infinite cells,
/// oriented outwards) as boundary patch 0.
fn tet_mesh_of(dt: &Delaunay3) -> TetMesh {
    let positions = dt.vertices().map(|v| dt.point(v)).collect();
    let mut tets = Vec::with_capacity(dt.num_finite_cells());
    let mut boundary = Vec::new();
    for c in dt.cells() {
        let [a, b, c3, d] = dt.cell(c);
        if !dt.is_infinite_cell(c) {
            // Cells are positive in Shewchuk's orient3d convention; files want the opposite one
            // (VTK, MEDIT, Gmsh: det[b-a, c-a, d-a] > 0), hence the swap.
            tets.push([a.0, b.0, d.0, c3.0]);
            continue;
        }
        let vs = [a, b, c3, d];
        let Some(i) = vs.iter().position(|&v| dt.is_infinite_vertex(v)) else {
            continue;
        };
        // Read this way, facet i of a cell positive in Shewchuk's convention has its normal pointing
        // away from vertex i; that vertex is the infinite one, so the normal points into the hull
        // and the reversed order below points outwards.
        let f = FACETS[i];
        boundary.push([vs[f[0]].0, vs[f[2]].0, vs[f[1]].0]);
    }
    let n_tets = tets.len();
    let n_bnd = boundary.len();
    TetMesh {
        positions,
        tets,
        subdomains: vec![SubdomainId(1); n_tets],
        boundary,
        boundary_patches: vec![PatchId(0); n_bnd],
        ..TetMesh::default()
    }
}

/// Vertex indices of facet i of a cell (the facet opposite vertex i).
const FACETS: [[usize; 3]; 4] = [[1, 3, 2], [0, 2, 3], [0, 3, 1], [0, 1, 2]];
