use super::*;
use crate::mesh::SurfaceMesh;
use crate::oracle::{Aabb, Everywhere};

/// The box of the test domain: enough for a single closed surface.
const BOX: Aabb = Aabb {
    min: Point3::splat(-1.0),
    max: Point3::splat(1.0),
};

fn run(
    points: &[Point3],
    triangles: &[[u32; 3]],
    options: &PreserveOptions,
) -> Result<Preserved, PreserveError> {
    let patches = vec![PatchId(1); triangles.len()];
    preserve_surface(points, triangles, &patches, &Everywhere(BOX), options)
}

#[test]
fn a_cube_is_kept_with_every_input_vertex() {
    let cube = SurfaceMesh::cuboid(Point3::ZERO, Point3::ONE);
    let kept = run(
        &cube.positions,
        &cube.triangles,
        &PreserveOptions::default(),
    )
    .expect("kept");
    for p in &cube.positions {
        assert!(kept.complex.points.contains(p));
    }
    assert_eq!(kept.complex.points.len(), 8 + kept.steiner_points());
    let volume: f64 = (0..kept.complex.tets.len())
        .map(|t| crate::complex::signed_volume(&kept.complex.tet_points(t)) / 6.0)
        .sum();
    assert!((volume - 1.0).abs() < 1e-12, "volume {volume}");
}

#[test]
fn degenerate_and_out_of_range_triangles_are_refused() {
    let points = [Point3::ZERO, Point3::X, Point3::X * 2.0, Point3::Y];
    let options = PreserveOptions::default();
    assert_eq!(
        run(&points, &[[0, 1, 2]], &options).unwrap_err(),
        PreserveError::DegenerateTriangle(0)
    );
    assert!(matches!(
        run(&points, &[[0, 1, 7]], &options).unwrap_err(),
        PreserveError::IndexOutOfRange { index: 7, .. }
    ));
    assert_eq!(
        run(&points, &[], &options).unwrap_err(),
        PreserveError::Empty
    );
}

#[test]
fn coincident_input_vertices_are_refused() {
    let mut cube = SurfaceMesh::cuboid(Point3::ZERO, Point3::ONE);
    cube.positions.push(cube.positions[0]);
    let last = cube.positions.len() as u32 - 1;
    cube.triangles[0][0] = last;
    assert!(matches!(
        run(
            &cube.positions,
            &cube.triangles,
            &PreserveOptions::default()
        )
        .unwrap_err(),
        PreserveError::DuplicateVertex(..)
    ));
}

/// A raised cancel flag stops recovery at its first Steiner point, and the cell level at its
/// first round, whose mesh (the recovered surface) is then returned with the reason; a time
/// limit already passed does the same.
#[test]
fn the_clock_stops_recovery_with_an_error_and_the_cell_level_with_its_mesh() {
    let cancel = Cancel::new();
    cancel.cancel();
    let long = SurfaceMesh::cuboid(Point3::ZERO, Point3::new(10.0, 0.1, 0.1));
    let stopped = PreserveOptions {
        cancel: Some(cancel),
        ..PreserveOptions::default()
    };
    assert_eq!(
        run(&long.positions, &long.triangles, &stopped).unwrap_err(),
        PreserveError::Stopped(RefineError::Cancelled)
    );
    let late = PreserveOptions {
        time_limit: Some(std::time::Duration::ZERO),
        ..PreserveOptions::default()
    };
    assert_eq!(
        run(&long.positions, &long.triangles, &late).unwrap_err(),
        PreserveError::Stopped(RefineError::TimeLimit)
    );
    // A tetrahedron needs no Steiner point: recovery ends, and the cell level stops at once.
    let corner = [Point3::ZERO, Point3::X, Point3::Y, Point3::Z];
    let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let cells = Some(CellCriteria {
        radius_edge_ratio: 1.5,
        size: crate::refine::criteria::Sizing::Constant(0.1),
    });
    for (options, why) in [
        (stopped, RefineError::Cancelled),
        (late, RefineError::TimeLimit),
    ] {
        let options = PreserveOptions {
            cells: cells.clone(),
            ..options
        };
        let kept = run(&corner, &faces, &options).expect("the surface is kept");
        assert_eq!(kept.stopped, Some(why));
        assert_eq!((kept.cell_steiner, kept.complex.points.len()), (0, 4));
    }
    let unbounded = PreserveOptions {
        cells,
        ..PreserveOptions::default()
    };
    let refined = run(&corner, &faces, &unbounded).expect("refined");
    assert_eq!(refined.stopped, None);
    assert!(refined.cell_steiner > 0);
}

#[test]
fn the_vertex_cap_stops_recovery_with_what_is_missing() {
    // Four-point faces of a long box are cocircular, so their diagonals are chosen by the
    // perturbation, not by the input; a long thin box also has facets closer than their size.
    let long = SurfaceMesh::cuboid(Point3::ZERO, Point3::new(10.0, 0.1, 0.1));
    let options = PreserveOptions {
        max_vertices: long.positions.len(),
        ..PreserveOptions::default()
    };
    let kept = run(
        &long.positions,
        &long.triangles,
        &PreserveOptions::default(),
    )
    .expect("kept");
    assert!(kept.steiner_points() > 0, "this box needs Steiner points");
    match run(&long.positions, &long.triangles, &options) {
        Err(PreserveError::VertexCap { cap, edges, facets }) => {
            assert_eq!(cap, long.positions.len());
            assert!(edges + facets > 0);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn labelling_the_new_cells_agrees_with_labelling_every_cell() {
    let cube = SurfaceMesh::cuboid(Point3::ZERO, Point3::ONE);
    let patches = vec![PatchId(1); cube.triangles.len()];
    let constraints = Constraints::new(&cube.positions, &cube.triangles, &patches).expect("valid");
    let options = PreserveOptions::default();
    let clock = Deadline::new(None, None);
    let mut r = Recovery::new(&cube.positions, constraints, &options, clock).expect("recovery");
    let mut faces = Vec::new();
    r.run(&mut faces).expect("recovered");
    let oracle = Everywhere(BOX);
    let pieces = regions::Pieces::new(&faces);
    let mut subdomain = regions::cell_subdomains(&r.dt, &pieces, &oracle);
    // Points inside the cube and outside it, and splits of its edges (breaking pieces, which
    // recovery restores), as the cell level's rounds insert them.
    r.created = Some(Vec::new());
    let near = VertexId(0);
    for p in [
        Point3::new(0.3, 0.4, 0.6),
        Point3::new(1.7, 0.2, 0.5),
        Point3::new(0.5, -0.6, 0.2),
    ] {
        r.insert(p, near).expect("inserted");
    }
    for e in [0, 3, 7] {
        let chain = &r.constraints.edges[e].chain;
        let pair = [chain[0].1, chain[1].1];
        r.split(e, pair).expect("split");
    }
    r.run(&mut faces).expect("recovered again");
    let created = r.created.take().expect("logged");
    let pieces = regions::Pieces::new(&faces);
    let looked_at = quality::round_cells(&r, &pieces, &oracle, Some(created), &[], &mut subdomain);
    // Only the new cells and their neighbours, not the whole mesh again.
    assert!(!looked_at.is_empty() && looked_at.len() < r.dt.num_finite_cells());
    let full = regions::cell_subdomains(&r.dt, &pieces, &oracle);
    let inside = |labels: &[crate::oracle::SubdomainId]| {
        r.dt.cells()
            .filter(|c| labels[c.0 as usize] != crate::oracle::OUTSIDE)
            .count()
    };
    assert!(inside(&full) > 0 && inside(&full) < r.dt.num_cells());
    for c in r.dt.cells() {
        assert_eq!(subdomain[c.0 as usize], full[c.0 as usize], "cell {c:?}");
    }
}
