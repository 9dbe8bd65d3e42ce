//! The 3D mesher of the thesis: initial surface points, then the level stack [surface facets,
//! cells] over a Delaunay triangulation (ch. 3), preceded by protecting balls on the sharp
//! features over a regular triangulation for piecewise-smooth domains (ch. 4), then the complex.

use super::cells::CellLevel;
use super::criteria::MeshCriteria;
use super::engine::{Engine, Limits, Progress, RefineError, RefineStats};
use super::facets::SurfaceLevel;
use super::guard::CurveLevel;
use super::manifold::{relabel_to_manifold, remove_stray_pieces};
use super::protect::{ProtectError, ProtectLimits, protect};
use super::repair::{Validity, ValidityOptions, find_defects};
use crate::complex::MeshComplex;
use crate::kernel::Point3;
use crate::optimize::{OptimizeOptions, OptimizeReport, optimize};
use crate::oracle::{FeatureCurve, Oracle, PatchId};
use crate::triangulation::{
    Delaunay3, InsertOutcome, InsertReport, Regular3, Triangulation, TriangulationError, VertexId,
};
use std::collections::HashMap;
use std::time::{Duration, Instant};

#[derive(Clone, Debug)]
/// What [`mesh_domain`] is asked for: criteria, guards and what to keep on failure.
pub struct MeshOptions {
    /// The quality and size criteria.
    pub criteria: MeshCriteria,
    /// Guards against runs that would not end (vertex cap, time, cancellation).
    pub limits: Limits,
    /// On a tripped guard, return the mesh reached so far inside the error.
    pub keep_partial: bool,
    /// Repairs after the criteria: flat cells, manifold boundary, input topology.
    pub validity: ValidityOptions,
    /// The optimisers run on the refined mesh (not on a partial one).
    pub optimize: OptimizeOptions,
}

impl MeshOptions {
    /// `criteria` with the default guards, repairs and optimisers, nothing kept on failure.
    pub fn new(criteria: MeshCriteria) -> Self {
        MeshOptions {
            criteria,
            limits: Limits::default(),
            keep_partial: false,
            validity: ValidityOptions::default(),
            optimize: OptimizeOptions::default(),
        }
    }
}

/// Wall time of each phase.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhaseTimes {
    /// Protection of features and the initial points on the boundary.
    pub initial_points: Duration,
    /// Refinement to the criteria, validity repairs included.
    pub refinement: Duration,
    /// Building the output complex.
    pub complex: Duration,
    /// Sliver perturbation, exudation and smoothing.
    pub optimization: Duration,
}

#[derive(Debug)]
/// The result of [`mesh_domain`]: the complex, with what it took to get there.
pub struct MeshOutcome {
    /// The mesh.
    pub complex: MeshComplex,
    /// Counts of the refinement.
    pub stats: RefineStats,
    /// Time of each phase.
    pub times: PhaseTimes,
    /// What the validity repairs reached (see [`ValidityOptions`]).
    pub validity: Validity,
    /// Quality before and after each optimisation step.
    pub optimization: OptimizeReport,
}

#[derive(Debug, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum MeshError {
    #[error("cannot protect the sharp features")]
    Protection(#[from] ProtectError),
    #[error("the domain gave no initial surface points (is the boundary empty?)")]
    NoInitialPoints,
    #[error("an initial surface point was refused by the triangulation: {0}")]
    InitialPoint(TriangulationError),
    #[error("refinement stopped")]
    Refinement {
        source: RefineError,
        /// The mesh reached when the guard tripped, if it was asked for.
        partial: Option<Box<MeshComplex>>,
    },
}

/// Mesh the domain described by `oracle`: over a Delaunay triangulation for a smooth domain, over
/// a regular triangulation with protecting balls when the oracle has corners or feature curves.
pub fn mesh_domain(
    oracle: &dyn Oracle,
    options: &MeshOptions,
    progress: &mut dyn FnMut(&Progress),
) -> Result<MeshOutcome, MeshError> {
    let curves = oracle.feature_curves();
    let corners = oracle.corners();
    if curves.is_empty() && corners.is_empty() {
        return mesh_smooth(oracle, options, progress);
    }
    mesh_with_features(
        oracle,
        options,
        &curves,
        &corners,
        Regular3::new(),
        &mut |tr, p, w| {
            let mut report = InsertReport::default();
            Ok(match tr.insert_weighted(p, w, None, &mut report)? {
                InsertOutcome::Inserted(v) | InsertOutcome::Duplicate(v) => Some(v),
                InsertOutcome::Hidden(_) => None,
            })
        },
        progress,
    )
}

/// The mesher of chapter 3: initial surface points, then [surface facets, cells].
fn mesh_smooth(
    oracle: &dyn Oracle,
    options: &MeshOptions,
    progress: &mut dyn FnMut(&Progress),
) -> Result<MeshOutcome, MeshError> {
    let start = Instant::now();
    let mut tr = Delaunay3::new();
    let floor = options
        .criteria
        .smooth_refinement_floor(&oracle.bounding_box());
    let mut surface = SurfaceLevel::new(oracle, options.criteria.facet.clone()).min_radius(floor);
    let cells = CellLevel::new(oracle, options.criteria.cell.clone()).min_radius(floor);
    let initial = oracle.initial_points();
    if initial.is_empty() {
        return Err(MeshError::NoInitialPoints);
    }
    for p in initial {
        let v = tr
            .insert(p.point)
            .map_err(MeshError::InitialPoint)?
            .vertex();
        surface.mark_on_surface(v);
    }
    let initial_points = start.elapsed();
    refine_and_collect(
        oracle,
        tr,
        surface,
        cells,
        None,
        options,
        initial_points,
        progress,
    )
}

/// Inserts a protecting ball as a weighted vertex; `None` when the triangulation hides it.
pub type InsertBall<'a, T> =
    dyn FnMut(&mut T, Point3, f64) -> Result<Option<VertexId>, TriangulationError> + 'a;

/// The mesher of chapter 4 with CGAL's protection: protecting balls on corners and curves
/// (weighted vertices of `tr`, inserted by `insert_ball`), the initial surface points outside
/// them, then [curve balls, surface facets with patch checks, cells].
pub fn mesh_with_features<T: Triangulation<Point = Point3>>(
    oracle: &dyn Oracle,
    options: &MeshOptions,
    curves: &[FeatureCurve],
    corners: &[Point3],
    mut tr: T,
    insert_ball: &mut InsertBall<'_, T>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<MeshOutcome, MeshError> {
    let start = Instant::now();
    let limits = ProtectLimits {
        min_radius: options.criteria.edge_min_size_for(&oracle.bounding_box()),
        max_balls: options.limits.max_vertices,
        deadline: options.limits.time_limit.map(|t| start + t),
        bend_tolerance: options.criteria.bend_tolerance(),
    };
    let protection = protect(curves, corners, &options.criteria.edge_size, &limits)?;
    let floor = options.criteria.refinement_floor(&oracle.bounding_box());
    let mut surface = SurfaceLevel::new(oracle, options.criteria.facet.clone())
        .check_patches()
        .min_radius(floor);
    let cells = CellLevel::new(oracle, options.criteria.cell.clone())
        .outside_box()
        .min_radius(floor);
    let mut vertices = Vec::with_capacity(protection.balls.len());
    for b in &protection.balls {
        let v =
            insert_ball(&mut tr, b.center, b.radius * b.radius).map_err(MeshError::InitialPoint)?;
        if let Some(v) = v {
            surface.mark_on_patch(v, PatchId(0));
        }
        vertices.push(v);
    }
    let curve_level = CurveLevel::new(protection, vertices);
    for p in oracle.initial_points() {
        if curve_level.in_a_ball(p.point) {
            continue;
        }
        if let InsertOutcome::Inserted(v) = tr.insert(p.point).map_err(MeshError::InitialPoint)? {
            surface.mark_on_patch(v, p.patch);
        }
    }
    let initial_points = start.elapsed();
    refine_and_collect(
        oracle,
        tr,
        surface,
        cells,
        Some(curve_level),
        options,
        initial_points,
        progress,
    )
}

/// Run the level stack (curve balls first when given), collect the complex and optimise it.
/// (The levels are the two meshers' own; bundling them would only move the argument list.)
#[allow(clippy::too_many_arguments)]
fn refine_and_collect<T: Triangulation<Point = Point3>>(
    oracle: &dyn Oracle,
    mut tr: T,
    mut surface: SurfaceLevel<'_>,
    mut cells: CellLevel<'_>,
    mut curves: Option<CurveLevel>,
    options: &MeshOptions,
    initial_points: Duration,
    progress: &mut dyn FnMut(&Progress),
) -> Result<MeshOutcome, MeshError> {
    let mut times = PhaseTimes {
        initial_points,
        ..PhaseTimes::default()
    };
    let start = Instant::now();
    cells.share_clear_facets(surface.clear_facets());
    let mut run = |tr: &mut T,
                   surface: &mut SurfaceLevel<'_>,
                   cells: &mut CellLevel<'_>,
                   curves: Option<&mut CurveLevel>,
                   limits: Limits,
                   first: bool| {
        let mut engine = Engine::new(limits);
        if let Some(curves) = curves {
            engine.push_level(curves);
        }
        engine.push_level(surface).push_level(cells);
        if first {
            engine.refine(tr, progress)
        } else {
            engine.resume(tr, progress)
        }
    };
    let mut result = run(
        &mut tr,
        &mut surface,
        &mut cells,
        curves.as_mut(),
        options.limits.clone(),
        true,
    );
    // Validity repairs, in bounded rounds and within a vertex budget (refinement near tiny
    // protecting balls can cascade).
    let budget = (options.validity.max_vertex_growth * tr.num_vertices() as f64) as usize;
    let repair_limits = Limits {
        max_vertices: budget.min(options.limits.max_vertices),
        ..options.limits.clone()
    };
    let mut validity = Validity::default();
    if let Ok(stats) = result.as_mut() {
        loop {
            let defects = find_defects(&tr, &cells, &options.validity, true);
            validity = defects.validity();
            if defects.is_empty() || stats.repair_rounds >= options.validity.max_rounds {
                break;
            }
            defects.queue(&tr, &mut surface, &mut cells);
            stats.repair_rounds += 1;
            match run(
                &mut tr,
                &mut surface,
                &mut cells,
                curves.as_mut(),
                repair_limits.clone(),
                false,
            ) {
                Ok(more) => stats.absorb(&more),
                // The vertex guard stops the repairs, not the meshing: the mesh so far is kept
                // and the validity says what is left.
                Err(RefineError::TooManyVertices { .. }) => {
                    validity = find_defects(&tr, &cells, &options.validity, false).validity();
                    break;
                }
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
        }
        // Where refinement could not resolve a pinch, relabelling does (one move per vertex at
        // most, so it ends).
        if options.validity.manifold && !validity.manifold {
            let on_surface = |v| surface.is_on_surface(v);
            let relabelling = relabel_to_manifold(&tr, &mut cells, &on_surface, tr.num_vertices());
            validity = find_defects(&tr, &cells, &options.validity, false).validity();
            validity.relabelling = relabelling;
        }
        if options.validity.manifold && validity.manifold && validity.extra_components > 0 {
            let mut relabelling = validity.relabelling;
            remove_stray_pieces(&tr, &mut cells, validity.extra_components, &mut relabelling);
            validity = find_defects(&tr, &cells, &options.validity, false).validity();
            validity.relabelling = relabelling;
        }
    }
    validity.unresolved_sheets = surface
        .restricted_facets(&tr)
        .filter(|(_, _, ball)| ball.twin_patch != PatchId(0))
        .count();
    times.refinement = start.elapsed();

    let start = Instant::now();
    let collect = || MeshComplex::from_refinement(&tr, &surface, &cells, curves.as_ref());
    match result {
        Ok(stats) => {
            let complex = collect();
            times.complex = start.elapsed();
            let start = Instant::now();
            let weights = vertex_weights(&tr, &complex);
            let (complex, optimization) = optimize(
                complex,
                &weights,
                oracle,
                &options.criteria,
                &options.optimize,
            );
            times.optimization = start.elapsed();
            Ok(MeshOutcome {
                complex,
                stats,
                times,
                validity,
                optimization,
            })
        }
        Err(source) => {
            let partial = options.keep_partial.then(|| Box::new(collect()));
            Err(MeshError::Refinement { source, partial })
        }
    }
}

/// The weight each vertex of `complex` has in `tr` (the optimisers need the regular
/// triangulation refinement built; the complex numbers vertices compactly, so they are matched by
/// position: a hidden vertex at a visible one's position is the lighter of the two).
fn vertex_weights<T: Triangulation<Point = Point3>>(tr: &T, complex: &MeshComplex) -> Vec<f64> {
    let key = |p: Point3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let mut weight: HashMap<[u64; 3], f64> = HashMap::new();
    for v in tr.vertices() {
        let w = tr.weight(v);
        if w > 0.0 {
            let e = weight.entry(key(tr.point(v))).or_insert(w);
            *e = e.max(w);
        }
    }
    if weight.is_empty() {
        return Vec::new();
    }
    complex
        .points
        .iter()
        .map(|&p| weight.get(&key(p)).copied().unwrap_or(0.0))
        .collect()
}
