//! The optimisers on an analytic ball: the triangulation stays exactly regular, the mesh stays a
//! valid mesh of the ball, and the smallest dihedral angle improves.

use super::state::{Workspace, min_dihedral};
use super::{
    Deadline, Flips, OptimizeOptions, STUCK_FLIP_DEG, exude, flip, optimize, perturb, smooth,
};
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

/// The cells of `c` tile the region they tiled before and keep its boundary facets: every cell
/// positive (exact orientation), every face in one cell (then an outer boundary facet) or two,
/// every boundary facet a face, each subdomain of the same volume as in `before`.
fn assert_same_tiling(c: &MeshComplex, before: &MeshComplex) {
    use crate::kernel::{Sign, orient3d};
    use std::collections::{BTreeMap, HashMap, HashSet};
    let sorted = |mut f: [u32; 3]| {
        f.sort_unstable();
        f
    };
    let mut faces: HashMap<[u32; 3], usize> = HashMap::new();
    for (t, tet) in c.tets.iter().enumerate() {
        let p = c.tet_points(t);
        // Positive output cells are negative in Shewchuk's sign.
        assert_eq!(orient3d(p[0], p[1], p[2], p[3]), Sign::Negative, "cell {t}");
        for k in 0..4 {
            let f = [0, 1, 2, 3].map(|i| tet[i]);
            *faces
                .entry(sorted([f[(k + 1) % 4], f[(k + 2) % 4], f[(k + 3) % 4]]))
                .or_default() += 1;
        }
    }
    let outer: HashSet<[u32; 3]> = before
        .facets
        .iter()
        .zip(&before.facet_subdomains)
        .filter(|(_, s)| s.contains(&crate::oracle::OUTSIDE))
        .map(|(&f, _)| sorted(f))
        .collect();
    for (f, n) in &faces {
        let want = if outer.contains(f) { 1 } else { 2 };
        assert_eq!(*n, want, "face {f:?}");
    }
    for f in &before.facets {
        assert!(faces.contains_key(&sorted(*f)), "facet {f:?} lost");
    }
    let volumes = |m: &MeshComplex| {
        let mut v: BTreeMap<u32, f64> = BTreeMap::new();
        for t in 0..m.tets.len() {
            *v.entry(m.tet_subdomain[t].0).or_default() +=
                crate::quality::tet_volume(&m.tet_points(t));
        }
        v
    };
    let (got, want) = (volumes(c), volumes(before));
    assert_eq!(got.len(), want.len());
    for ((s, g), w) in got.iter().zip(want.values()) {
        assert!(
            (g - w).abs() <= 1e-12 * w,
            "subdomain {s}: volume {g}, before {w}"
        );
    }
}

/// The refined ball cut by the plane x = 0 into two subdomains, the faces between them
/// interface facets.
fn two_subdomains(mut c: MeshComplex) -> MeshComplex {
    use crate::oracle::SubdomainId;
    use std::collections::HashMap;
    for t in 0..c.tets.len() {
        let p = c.tet_points(t);
        if (p[0] + p[1] + p[2] + p[3]).x < 0.0 {
            c.tet_subdomain[t] = SubdomainId(2);
        }
    }
    let mut faces: HashMap<[u32; 3], Vec<usize>> = HashMap::new();
    for (t, tet) in c.tets.iter().enumerate() {
        for k in 0..4 {
            let mut f: Vec<u32> = (0..4).filter(|&i| i != k).map(|i| tet[i]).collect();
            f.sort_unstable();
            faces.entry([f[0], f[1], f[2]]).or_default().push(t);
        }
    }
    let mut interface: Vec<([u32; 3], [SubdomainId; 2])> = faces
        .into_iter()
        .filter_map(|(f, ts)| match ts[..] {
            [a, b] if c.tet_subdomain[a] != c.tet_subdomain[b] => {
                Some((f, [c.tet_subdomain[a], c.tet_subdomain[b]]))
            }
            _ => None,
        })
        .collect();
    interface.sort_unstable();
    for (f, s) in interface {
        c.facets.push(f);
        c.facet_patch.push(crate::oracle::PatchId(9));
        c.facet_subdomains.push(s);
    }
    for v in c.facets.iter().flatten() {
        c.vertex_dimension[*v as usize] = VertexDimension::Surface;
    }
    c
}

fn below(c: &MeshComplex, deg: f64) -> usize {
    (0..c.tets.len())
        .filter(|&t| min_dihedral(&c.tet_points(t)) < deg)
        .count()
}

#[test]
fn flips_keep_the_tiling_and_its_boundary_and_remove_slivers() {
    let mesh = two_subdomains(refined());
    let mut c = mesh.clone();
    let changes = flip::flip(&mut c, 18.0, &criteria().cell.size, &Deadline::default());
    assert!(changes > 0);
    assert_same_tiling(&c, &mesh);
    assert_eq!(c.facets, mesh.facets);
    // Only interior vertices move, and new ones come after the old.
    for (i, p) in mesh.points.iter().enumerate() {
        if mesh.vertex_dimension[i] != VertexDimension::Volume {
            assert_eq!(c.points[i], *p, "boundary vertex {i} moved");
        }
    }
    assert_eq!(c.points.len(), c.vertex_dimension.len());
    assert!(smallest(&c) > smallest(&mesh));
    assert!(
        below(&c, 10.0) < below(&mesh, 10.0) / 2,
        "{} slivers left of {}",
        below(&c, 10.0),
        below(&mesh, 10.0)
    );
}

#[test]
fn the_default_flips_follow_perturbation_and_exudation_and_keep_what_they_leave_above_the_bound() {
    let mesh = refined();
    let c = criteria();
    let off = OptimizeOptions {
        flip: Flips::Off,
        ..OptimizeOptions::default()
    };
    let (regular, _) = optimize(mesh.clone(), &[], &UnitBall, &c, &off);
    let (flipped, report) = optimize(
        mesh.clone(),
        &[],
        &UnitBall,
        &c,
        &OptimizeOptions::default(),
    );
    let names: Vec<&str> = report.steps.iter().map(|s| s.step.name()).collect();
    assert_eq!(names, ["perturb", "exude", "flip"]);
    // The flips work on the mesh the other steps leave: same tiling and boundary, no smaller
    // angle, no more cells below the bound, and the cells above it kept (the image plugin's
    // tests show them mending slivers the other steps cannot).
    assert_same_tiling(&flipped, &regular);
    assert_eq!(flipped.facets, regular.facets);
    assert!(smallest(&flipped) >= smallest(&regular));
    assert!(below(&flipped, STUCK_FLIP_DEG) <= below(&regular, STUCK_FLIP_DEG));
    let cells = |m: &MeshComplex| -> std::collections::HashSet<[u32; 4]> {
        (0..m.tets.len())
            .filter(|&t| min_dihedral(&m.tet_points(t)) >= STUCK_FLIP_DEG)
            .map(|t| {
                let mut v = m.tets[t];
                v.sort_unstable();
                v
            })
            .collect()
    };
    let (kept, before) = (cells(&flipped), cells(&regular));
    assert!(
        kept.intersection(&before).count() * 10 >= before.len() * 9,
        "{} of {} good cells kept",
        kept.intersection(&before).count(),
        before.len()
    );
    // Without perturbation and exudation there is nothing for them to finish; `Flips::All`
    // still runs.
    let none = OptimizeOptions {
        perturb: false,
        exude: false,
        ..OptimizeOptions::default()
    };
    let (same, report) = optimize(mesh.clone(), &[], &UnitBall, &c, &none);
    assert!(report.steps.is_empty());
    assert_eq!(same, mesh);
    let all = OptimizeOptions {
        flip: Flips::All,
        ..none
    };
    let (_, report) = optimize(mesh, &[], &UnitBall, &c, &all);
    let names: Vec<&str> = report.steps.iter().map(|s| s.step.name()).collect();
    assert_eq!(names, ["flip"]);
}
