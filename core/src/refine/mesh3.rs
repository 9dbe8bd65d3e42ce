//! The 3D mesher of the thesis: initial surface points, then the level stack [surface facets,
//! cells] over a Delaunay triangulation (ch. 3), preceded by protecting balls on the sharp
//! features over a regular triangulation for piecewise-smooth domains (ch. 4), then the complex.

use super::cells::CellLevel;
use super::criteria::{MeshCriteria, Sizing};
use super::engine::{Engine, Limits, Progress, RefineError, RefineStats};
use super::facets::SurfaceLevel;
use super::geometry::is_flat;
use super::guard::CurveLevel;
use super::manifold::{
    absorb_sliver_islands, relabel_interfaces, relabel_to_manifold, remove_stray_pieces,
};
use super::protect::{ProtectError, ProtectLimits, protect};
use super::repair::{Validity, ValidityOptions, find_defects};
use crate::complex::MeshComplex;
use crate::kernel::Point3;
use crate::optimize::{OptimizeOptions, OptimizeReport, optimize};
use crate::oracle::{FeatureCurve, Oracle, PatchId, SurfacePoint};
use crate::triangulation::{
    Delaunay3, InsertOutcome, InsertReport, Regular3, Triangulation, TriangulationError, VertexId,
};
use rustc_hash::FxHashMap;
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
    /// Protection of features and the initial points on the boundary (with the earlier
    /// attempts, when the features were protected again: [`mesh_with_features`]).
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
    let initial = spread_out(oracle.initial_points(), SAME_POINT * floor);
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
    let mut refined =
        refine_with_repairs(tr, surface, cells, None, options, initial_points, progress);
    relabel(&mut refined, options);
    collect_and_optimize(oracle, refined, options)
}

/// Initial points closer than this fraction of the refinement floor are one point (see
/// [`spread_out`]); farther apart, they may be a small component's only points.
const SAME_POINT: f64 = 1e-3;

/// The initial points less those within `spacing` of an earlier one. An oracle may find one
/// surface point twice (two probes crossing the surface at the same spot, a few ulps apart), and
/// two vertices that close make every cell around them flat: refining those cells only adds
/// more points in the gap, down to the rounding of coordinates.
fn spread_out(points: Vec<SurfacePoint>, spacing: f64) -> Vec<SurfacePoint> {
    if spacing.is_nan() || spacing <= 0.0 {
        return points;
    }
    let key = |p: Point3| (p / spacing).floor().to_array().map(|x| x as i64);
    // Only looked up, never iterated: the order kept is the oracle's.
    let mut grid: FxHashMap<[i64; 3], Vec<Point3>> = FxHashMap::default();
    let mut kept = Vec::with_capacity(points.len());
    for p in points {
        let [x, y, z] = key(p.point);
        let crowded = (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                (-1..=1).any(|dz| {
                    grid.get(&[x + dx, y + dy, z + dz])
                        .is_some_and(|c| c.iter().any(|q| q.distance(p.point) < spacing))
                })
            })
        });
        if !crowded {
            grid.entry([x, y, z]).or_default().push(p.point);
            kept.push(p);
        }
    }
    kept
}

/// Inserts a protecting ball as a weighted vertex; `None` when the triangulation hides it.
pub type InsertBall<'a, T> =
    dyn FnMut(&mut T, Point3, f64) -> Result<Option<VertexId>, TriangulationError> + 'a;

/// The mesher of chapter 4 with CGAL's protection: protecting balls on corners and curves
/// (weighted vertices of `tr`, inserted by `insert_ball`), the initial surface points outside
/// them, then [curve balls, surface facets with patch checks, cells].
///
/// Where the repairs leave a flat cell, or a non-manifold spot whose relabelling changes the
/// input's topology, at a protected vertex, the balls there were too big for the geometry around
/// them (a slot or a wall thinner than the ball, which refinement may not enter): the features
/// are protected again with smaller balls around those vertices and the domain meshed again from
/// `tr`, at most [`MAX_REPROTECTIONS`] times (as CGAL refines its protecting balls).
pub fn mesh_with_features<T: Triangulation<Point = Point3> + Clone>(
    oracle: &dyn Oracle,
    options: &MeshOptions,
    curves: &[FeatureCurve],
    corners: &[Point3],
    tr: T,
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
    let floor = options.criteria.refinement_floor(&oracle.bounding_box());
    let mut spots: Vec<StuckSpot> = Vec::new();
    let mut options = options.clone();
    let mut attempt = 0;
    let mut best_so_far: Option<Refined<'_, T>> = None;
    loop {
        let attempt_start = Instant::now();
        // A retry that cannot be protected (more balls than allowed, the time limit) falls back
        // on the attempt before it.
        let attempt_outcome = (|| -> Result<Refined<'_, T>, MeshError> {
            let edge_size = shrunk_near(&options.criteria.edge_size, &spots);
            let protection = protect(curves, corners, &edge_size, &limits, &|c, p| {
                oracle.project_to_curve(c, p)
            })?;
            let mut surface = SurfaceLevel::new(oracle, options.criteria.facet.clone())
                .check_patches()
                .min_radius(floor);
            let cells = CellLevel::new(oracle, options.criteria.cell.clone())
                .outside_box()
                .min_radius(floor);
            let mut tr = tr.clone();
            let mut vertices = Vec::with_capacity(protection.balls.len());
            for b in &protection.balls {
                let v = insert_ball(&mut tr, b.center, b.radius * b.radius)
                    .map_err(MeshError::InitialPoint)?;
                if let Some(v) = v {
                    surface.mark_on_patch(v, PatchId(0));
                }
                vertices.push(v);
            }
            let curve_level = CurveLevel::new(protection, vertices);
            for p in spread_out(oracle.initial_points(), SAME_POINT * floor) {
                if curve_level.in_a_ball(p.point) {
                    continue;
                }
                if let InsertOutcome::Inserted(v) =
                    tr.insert(p.point).map_err(MeshError::InitialPoint)?
                {
                    surface.mark_on_patch(v, p.patch);
                }
            }
            let initial_points = attempt_start.elapsed();
            Ok(refine_with_repairs(
                tr,
                surface,
                cells,
                Some(curve_level),
                &options,
                initial_points,
                progress,
            ))
        })();
        let mut refined = match attempt_outcome {
            Ok(refined) => refined,
            Err(e) => {
                return match best_so_far {
                    Some(best) => collect_and_optimize(oracle, best, &options),
                    None => Err(e),
                };
            }
        };
        relabel(&mut refined, &options);
        refined.times.initial_points += attempt_start.duration_since(start);
        if let Ok(stats) = refined.result.as_mut() {
            stats.reprotections = attempt;
        }
        // Relabelling resolves most pinches harmlessly; where it changed the topology, or where
        // flat cells are left, the protection is refined instead. The attempt with the fewest
        // flat cells, then the closest to the input's topology, is kept (the first of equals), and
        // a failed retry falls back on it.
        let defect = |r: &Refined<'_, T>| (r.validity.flat_cells, r.validity.topology_gap);
        let new_spots = match (&refined.result, &refined.curves) {
            (Ok(_), Some(level)) if attempt < MAX_REPROTECTIONS && defect(&refined) != (0, 0) => {
                stuck_spots(level, &refined.stuck, limits.min_radius)
            }
            _ => Vec::new(),
        };
        let best = match best_so_far.take() {
            Some(b) if refined.result.is_err() || defect(&b) <= defect(&refined) => b,
            _ => refined,
        };
        if new_spots.is_empty() {
            return collect_and_optimize(oracle, best, &options);
        }
        best_so_far = Some(best);
        spots.extend(new_spots);
        attempt += 1;
        // The next attempt has what is left of the time limit.
        if let Some(t) = options.limits.time_limit.as_mut() {
            *t = t.saturating_sub(attempt_start.elapsed());
        }
    }
}

/// Most times the features are protected again with smaller balls where refinement left a
/// defect at a protecting ball ([`mesh_with_features`]).
pub const MAX_REPROTECTIONS: usize = 1;

/// How fast the edge size grows back away from a stuck spot (|∇h|).
const SPOT_GRADATION: f64 = 0.5;

/// A protected vertex of a defect refinement left (a flat cell, a non-manifold spot): the edge
/// size is `radius` there.
#[derive(Clone, Copy, Debug)]
struct StuckSpot {
    center: Point3,
    radius: f64,
}

/// The protecting balls among the `stuck` vertices, each as a spot asking for half its radius
/// (none when that is below the smallest ball radius allowed: nothing more to gain).
fn stuck_spots(level: &CurveLevel, stuck: &[VertexId], min_radius: f64) -> Vec<StuckSpot> {
    let balls = &level.protection().balls;
    let ball_of: HashMap<VertexId, usize> = (0..balls.len())
        .filter_map(|b| Some((level.ball_vertex(b)?, b)))
        .collect();
    let mut spots: Vec<StuckSpot> = stuck
        .iter()
        .filter_map(|v| ball_of.get(v))
        .map(|&b| StuckSpot {
            center: balls[b].center,
            radius: 0.5 * balls[b].radius,
        })
        .filter(|s| s.radius >= min_radius)
        .collect();
    spots.sort_by(|a, b| {
        (a.center.to_array(), a.radius)
            .partial_cmp(&(b.center.to_array(), b.radius))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    spots.dedup_by(|a, b| a.center == b.center);
    spots
}

/// `base`, bounded near each spot by the spot's radius growing at [`SPOT_GRADATION`].
fn shrunk_near(base: &Sizing, spots: &[StuckSpot]) -> Sizing {
    if spots.is_empty() {
        return base.clone();
    }
    let (base, spots) = (base.clone(), spots.to_vec());
    Sizing::function(move |p, label| {
        spots.iter().fold(base.at(p, label), |h, s| {
            h.min(s.radius + SPOT_GRADATION * s.center.distance(p))
        })
    })
}

/// One refinement's triangulation and levels, and where the validity repairs left them.
struct Refined<'o, T> {
    tr: T,
    surface: SurfaceLevel<'o>,
    cells: CellLevel<'o>,
    curves: Option<CurveLevel>,
    result: Result<RefineStats, RefineError>,
    validity: Validity,
    /// Vertices of the flat cells and non-manifold spots refinement left (relabelling comes
    /// later).
    stuck: Vec<VertexId>,
    times: PhaseTimes,
    start: Instant,
}

/// Run the level stack (curve balls first when given) to the criteria, then the validity
/// repairs in bounded rounds. (The levels are the two meshers' own; bundling them would only
/// move the argument list.)
fn refine_with_repairs<'o, T: Triangulation<Point = Point3>>(
    mut tr: T,
    mut surface: SurfaceLevel<'o>,
    mut cells: CellLevel<'o>,
    mut curves: Option<CurveLevel>,
    options: &MeshOptions,
    initial_points: Duration,
    progress: &mut dyn FnMut(&Progress),
) -> Refined<'o, T> {
    let times = PhaseTimes {
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
    let mut stuck = Vec::new();
    if let Ok(stats) = result.as_mut() {
        loop {
            let defects = find_defects(&tr, &cells, &options.validity, true);
            validity = defects.validity();
            stuck = defects.stuck.clone();
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
                Ok(more) => {
                    stats.absorb(&more);
                    // A round that inserted nothing leaves the same defects: the next would too.
                    if more.insertions.iter().all(|&n| n == 0) {
                        let defects = find_defects(&tr, &cells, &options.validity, false);
                        validity = defects.validity();
                        stuck = defects.stuck;
                        break;
                    }
                }
                // The vertex guard stops the repairs, not the meshing: the mesh so far is kept
                // and the validity says what is left.
                Err(RefineError::TooManyVertices { .. }) => {
                    let defects = find_defects(&tr, &cells, &options.validity, false);
                    validity = defects.validity();
                    stuck = defects.stuck;
                    break;
                }
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
        }
    }
    Refined {
        tr,
        surface,
        cells,
        curves,
        result,
        validity,
        stuck,
        times,
        start,
    }
}

/// Where refinement could not resolve a pinch, relabel cells (one move per vertex at most, so it
/// ends); then give stray pieces the other label.
fn relabel<T: Triangulation<Point = Point3>>(refined: &mut Refined<'_, T>, options: &MeshOptions) {
    let Refined {
        tr,
        surface,
        cells,
        result,
        validity,
        stuck,
        ..
    } = refined;
    if result.is_err() || !options.validity.manifold {
        return;
    }
    if !validity.manifold {
        let on_surface = |v| surface.is_on_surface(v);
        let mut relabelling = relabel_to_manifold(tr, cells, stuck, &on_surface, tr.num_vertices());
        let mut defects = find_defects(tr, cells, &options.validity, false);
        if !defects.validity().manifold {
            relabel_interfaces(tr, cells, &defects.stuck, &mut relabelling);
            defects = find_defects(tr, cells, &options.validity, false);
        }
        *validity = defects.validity();
        validity.relabelling = relabelling;
    }
    if validity.manifold && validity.extra_components > 0 {
        let mut relabelling = validity.relabelling;
        remove_stray_pieces(tr, cells, validity.extra_components, &mut relabelling);
        *validity = find_defects(tr, cells, &options.validity, false).validity();
        validity.relabelling = relabelling;
    }
    // Without an input topology to hold to (an image), a one-cell component that is a sliver is
    // noise below the floor; with one, the topology rule refined such components instead.
    if options.validity.input_euler.is_none() {
        let mut relabelling = validity.relabelling;
        if absorb_sliver_islands(tr, cells, &mut relabelling) > 0 {
            *validity = find_defects(tr, cells, &options.validity, false).validity();
            validity.relabelling = relabelling;
        }
    }
}

/// Finish a relabelled refinement: collect the complex and optimise it.
fn collect_and_optimize<T: Triangulation<Point = Point3>>(
    oracle: &dyn Oracle,
    refined: Refined<'_, T>,
    options: &MeshOptions,
) -> Result<MeshOutcome, MeshError> {
    let Refined {
        tr,
        surface,
        cells,
        curves,
        result,
        mut validity,
        mut times,
        start,
        ..
    } = refined;
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
            validity.flat_cells = (0..complex.tets.len())
                .filter(|&t| is_flat(&complex.tet_points(t)))
                .count();
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
