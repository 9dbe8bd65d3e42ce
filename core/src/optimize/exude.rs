//! Sliver exudation (Cheng, Dey, Edelsbrunner, Facello and Teng 2000): a vertex of a sliver gets
//! a larger weight, which changes the regular triangulation around it and can flip the sliver
//! away without moving any point. Weights stay below `DELTA²` times the squared distance from
//! the vertex to the nearest ball of another vertex, the bound under which no vertex gets
//! hidden and the weighted points stay close to the unweighted ones; the boundary facets are
//! kept by the workspace, so the restricted surface does not change.

use super::Deadline;
use super::state::Workspace;
use crate::complex::VertexDimension;
use crate::triangulation::{CellId, Triangulation, VertexId};

/// The weight bound as a fraction of the distance to the nearest other ball (Cheng et al.
/// require less than 1/2; CGAL uses 0.3).
const DELTA: f64 = 0.35;
/// Weights tried per vertex, as fractions of the interval between its weight and the bound.
const PUMPS: [f64; 3] = [1.0, 0.67, 0.33];
/// Sweeps over the slivers at most.
const MAX_SWEEPS: usize = 3;

/// Exudation works on no cell above this (degrees), whatever the sliver bound: after the
/// perturbation, pumping the cells above it cost most of the step's time for no gain in the
/// smallest angle nor in the share of cells below 10° (CGAL's models, bound 20°).
const MAX_BOUND_DEG: f64 = 14.0;

/// Pumps the vertices of the cells below `bound` degrees (at most [`MAX_BOUND_DEG`]), worst
/// first, until a sweep improves nothing or the deadline passes; once the worst cell is stuck,
/// only the slivers below 10° (the perturbation's rule). Returns the number of weight changes
/// kept.
pub(super) fn exude(ws: &mut Workspace<'_>, bound: f64, deadline: &Deadline) -> usize {
    ws.sweep_slivers(
        bound.min(MAX_BOUND_DEG),
        deadline,
        MAX_SWEEPS,
        Some(0.0),
        |ws, c| {
            let cell = ws.rt.cell(c);
            cell.iter().any(|&v| pump(ws, v))
        },
    )
}

/// Gives `v` a larger weight (among a few up to its bound) that improves the smallest dihedral
/// angle around it, if one does.
fn pump(ws: &mut Workspace<'_>, v: VertexId) -> bool {
    if !matches!(
        ws.dimension[v.0 as usize],
        VertexDimension::Volume | VertexDimension::Surface
    ) {
        return false;
    }
    let p = ws.rt.point(v);
    let w0 = ws.rt.weight(v);
    let Some(bound) = weight_bound(ws, v) else {
        return false;
    };
    if bound <= w0 {
        return false;
    }
    // The largest weight first (it changes the most cells); the first that helps is kept, as
    // each try costs a move and an undo in the triangulation.
    for f in PUMPS {
        let w = w0 + (bound - w0) * f;
        if ws
            .try_move(v, p, w, |before, after| after > before)
            .is_some()
        {
            return true;
        }
    }
    false
}

/// `DELTA²` times the squared distance from `v` to the nearest ball of a neighbour (`None` when
/// it touches one).
fn weight_bound(ws: &Workspace<'_>, v: VertexId) -> Option<f64> {
    let mut cells: Vec<CellId> = Vec::new();
    ws.rt.incident_cells(v, &mut cells);
    let p = ws.rt.point(v);
    let inf = ws.rt.infinite_vertex();
    let mut nearest = f64::INFINITY;
    for &c in &cells {
        for u in ws.rt.cell(c) {
            if u != v && u != inf {
                let gap = p.distance(ws.rt.point(u)) - ws.rt.weight(u).sqrt();
                nearest = nearest.min(gap);
            }
        }
    }
    (nearest > 0.0 && nearest.is_finite()).then_some(DELTA * DELTA * nearest * nearest)
}
