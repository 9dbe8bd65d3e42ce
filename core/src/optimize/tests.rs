//! The optimisers on an analytic ball: the triangulation stays exactly regular, the mesh stays a
//! valid mesh of the ball, and the smallest dihedral angle improves.

use super::state::{Workspace, min_dihedral};
use super::{Deadline, OptimizeOptions, exude, optimize, perturb, smooth};
use crate::complex::{MeshComplex, VertexDimension};
use crate::oracle::UnitBall;
use crate::quality::surface_topology;
use crate::refine::criteria::MeshCriteria;
use crate::refine::{MeshOptions, mesh_domain};
use crate::triangulation::Triangulation;
use crate::triangulation::validity::check_regular3;

const DISTANCE: f64 = 0.02;

fn criteria() -> MeshCriteria {
    MeshCriteria::uniform(0.3, DISTANCE)
}

/// The refined mesh of the ball, not optimised.
fn refined() -> MeshComplex {
    let options = MeshOptions {
        optimize: OptimizeOptions::none(),
        ..MeshOptions::new(criteria())
    };
    mesh_domain(&UnitBall, &options, &mut |_| {})
        .expect("the ball is meshed")
        .complex
}

fn smallest(c: &MeshComplex) -> f64 {
    (0..c.tets.len())
        .map(|t| min_dihedral(&c.tet_points(t)))
        .fold(180.0, f64::min)
}

/// A valid mesh of the ball: positive tetrahedra, a closed 2-manifold sphere as boundary with
/// its vertices on the sphere, the volume of the refined mesh up to the facet distance.
fn assert_valid_ball(c: &MeshComplex, refined_volume: f64) {
    for t in 0..c.tets.len() {
        assert!(
            min_dihedral(&c.tet_points(t)) > 0.0,
            "tet {t} is flat or inverted"
        );
    }
    let topology = surface_topology(&c.facets);
    assert!(topology.is_closed_manifold());
    assert_eq!(topology.euler_characteristic, 2);
    for f in &c.facets {
        for &v in f {
            let r = c.points[v as usize].length();
            assert!((r - 1.0).abs() <= DISTANCE, "boundary vertex at radius {r}");
        }
    }
    let volume = volume(c);
    let area = 4.0 * std::f64::consts::PI;
    assert!(
        (volume - refined_volume).abs() <= area * DISTANCE,
        "volume {volume}"
    );
}

fn volume(c: &MeshComplex) -> f64 {
    (0..c.tets.len())
        .map(|t| crate::quality::tet_volume(&c.tet_points(t)))
        .sum()
}

#[test]
fn every_step_keeps_the_triangulation_regular_and_the_mesh_valid() {
    let mesh = refined();
    let refined_volume = volume(&mesh);
    let before = smallest(&mesh);
    let c = criteria();
    let mut ws = Workspace::new(&mesh, &[], &UnitBall, &c).expect("taken over");
    let deadline = Deadline::default();
    // After each step the triangulation is regular and the cached angle of every cell is its
    // angle, recomputed.
    let check = |ws: &Workspace<'_>| {
        assert_eq!(check_regular3(&ws.rt), Ok(()));
        for c in ws.rt.finite_cells() {
            assert_eq!(ws.cell_min_dihedral(c), min_dihedral(&ws.points(c)));
        }
    };
    smooth::smooth(&mut ws, smooth::Smoother::Odt, 3, &deadline);
    check(&ws);
    smooth::smooth(&mut ws, smooth::Smoother::Lloyd, 3, &deadline);
    check(&ws);
    assert!(perturb::perturb(&mut ws, 20.0, &deadline) > 0);
    check(&ws);
    exude::exude(&mut ws, 20.0, &deadline);
    check(&ws);
    let after = ws.into_complex(mesh.clone());
    assert_valid_ball(&after, refined_volume);
    assert!(
        smallest(&after) > before,
        "{} -> {}",
        before,
        smallest(&after)
    );
    // Interior vertices may move, nothing is added or removed, and the numbering is kept.
    assert_eq!(after.points.len(), mesh.points.len());
    assert_eq!(after.vertex_dimension, mesh.vertex_dimension);
}

#[test]
fn the_default_optimisers_lift_the_smallest_angle_and_repeat_exactly() {
    let mesh = refined();
    let options = OptimizeOptions::default();
    let (a, report) = optimize(mesh.clone(), &[], &UnitBall, &criteria(), &options);
    assert!(report.skipped.is_none());
    assert_valid_ball(&a, volume(&mesh));
    assert!(report.after().min_dihedral_deg > report.before.min_dihedral_deg);
    assert!(report.after().below_10_deg <= report.before.below_10_deg);
    assert!(
        smallest(&a) >= 5.0,
        "smallest dihedral angle {}",
        smallest(&a)
    );
    let (b, _) = optimize(mesh.clone(), &[], &UnitBall, &criteria(), &options);
    assert_eq!(a, b);
    // Surface vertices stay surface vertices, on the sphere.
    for (p, d) in a.points.iter().zip(&a.vertex_dimension) {
        if *d == VertexDimension::Surface {
            assert!((p.length() - 1.0).abs() <= DISTANCE);
        }
    }
}

#[test]
fn no_optimiser_leaves_the_mesh_as_it_is() {
    let mesh = refined();
    let (same, report) = optimize(
        mesh.clone(),
        &[],
        &UnitBall,
        &criteria(),
        &OptimizeOptions::none(),
    );
    assert_eq!(same, mesh);
    assert!(report.steps.is_empty());
}

#[test]
fn a_raised_cancel_flag_stops_the_phase_before_any_step() {
    let mesh = refined();
    let flag = crate::refine::Cancel::new();
    let options = OptimizeOptions {
        cancel: Some(flag.clone()),
        ..OptimizeOptions::default()
    };
    let (_, running) = optimize(mesh.clone(), &[], &UnitBall, &criteria(), &options);
    assert!(!running.steps.is_empty());
    flag.cancel();
    let (_, report) = optimize(mesh, &[], &UnitBall, &criteria(), &options);
    assert!(report.steps.is_empty());
}

#[test]
fn surface_vertices_on_the_hull_of_the_mesh_can_move() {
    // Every vertex on the sphere is on the convex hull of the mesh vertices; the workspace's
    // frame puts them inside its triangulation, so a small move inwards is a valid move.
    let mesh = refined();
    let c = criteria();
    let mut ws = Workspace::new(&mesh, &[], &UnitBall, &c).expect("taken over");
    let surface: Vec<_> = (0..ws.rt.num_vertices())
        .map(|i| crate::triangulation::VertexId(i as u32))
        .filter(|&v| ws.dimension[v.0 as usize] == VertexDimension::Surface)
        .take(20)
        .collect();
    assert!(!surface.is_empty());
    for v in surface {
        let p = ws.rt.point(v);
        let change = ws
            .try_move(v, p * (1.0 - 0.1 * DISTANCE), 0.0, |_, _| true)
            .expect("a small move inwards keeps the boundary");
        ws.undo(change);
        assert_eq!(ws.rt.point(v), p);
    }
    assert_eq!(check_regular3(&ws.rt), Ok(()));
    assert_valid_ball(&ws.into_complex(mesh.clone()), volume(&mesh));
}

/// With the floor fixed (the worst cell cannot be helped), a sweep tries only the cells below
/// 10° or the margin above the worst cell after it; without a margin, every cell under the bound.
#[test]
fn a_sweep_stops_at_a_stuck_floor_only_when_asked() {
    let mesh = refined();
    let c = criteria();
    let mut ws = Workspace::new(&mesh, &[], &UnitBall, &c).expect("taken over");
    let deadline = Deadline::default();
    let under = |ws: &Workspace<'_>, bound: f64| ws.slivers(bound).len();
    let (all, slivers) = (under(&ws, 40.0), under(&ws, 10.0));
    assert!(
        all > slivers + 1,
        "{all} cells under 40°, {slivers} under 10°"
    );
    let worst = ws.slivers(40.0)[0].0;
    let near = under(&ws, (worst + 15.0).max(10.0));
    assert!(
        near > slivers.max(1) && near < all,
        "{near} cells near the floor"
    );
    for (margin, expected) in [(None, all), (Some(0.0), slivers.max(1)), (Some(15.0), near)] {
        let mut tried = 0;
        let kept = ws.sweep_slivers(40.0, &deadline, 1, margin, |_, _| {
            tried += 1;
            false
        });
        assert_eq!((kept, tried), (0, expected), "floor margin: {margin:?}");
    }
}
