//! Global smoothing: every interior vertex moves towards the point that minimises an energy of
//! its star, sweep after sweep, until the vertices barely move. ODT (Chen; Alliez, Cohen-Steiner,
//! Yvinec and Desbrun 2005) moves a vertex to the volume-weighted mean of the circumcentres of
//! its cells, Lloyd to the centroid of its Voronoi cell. Vertices whose star meets the outside
//! stay (their Voronoi cells are clipped by the surface), as do surface, curve and corner
//! vertices.

use super::Deadline;
use super::state::Workspace;
use crate::complex::VertexDimension;
use crate::kernel::Point3;
use crate::quality::{tet_circumcenter, tet_volume};
use crate::refine::triangle_circumcenter;
use crate::triangulation::{CellId, Triangulation, VertexId};

/// Which energy a smoothing minimises.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Smoother {
    /// Optimal Delaunay triangulation.
    Odt,
    /// Centroidal Voronoi tessellation.
    Lloyd,
}

/// A vertex whose target is closer than this fraction of its shortest edge does not move
/// (CGAL's freeze bound).
const FREEZE: f64 = 0.01;
/// Sweeps stop once no vertex moves by more than this fraction of its shortest edge (CGAL's
/// convergence bound).
const CONVERGENCE: f64 = 0.02;
/// A move may not create a cell below this smallest dihedral angle (degrees) unless the cells
/// it destroyed were already worse: smoothing must not undo what the perturber will need.
const KEEP_ANGLE: f64 = 5.0;

/// Runs at most `max_sweeps` sweeps of `smoother`. Returns (moves kept, sweeps run).
pub(super) fn smooth(
    ws: &mut Workspace<'_>,
    smoother: Smoother,
    max_sweeps: usize,
    deadline: &Deadline,
) -> (usize, usize) {
    let mut kept = 0;
    let mut cells = Vec::new();
    for sweep in 0..max_sweeps {
        let mut largest = 0.0f64;
        for i in 0..ws.rt.num_vertices() {
            let v = VertexId(i as u32);
            if deadline.passed() {
                return (kept, sweep + 1);
            }
            if ws.dimension[v.0 as usize] != VertexDimension::Volume || ws.rt.is_hidden(v) {
                continue;
            }
            ws.rt.incident_cells(v, &mut cells);
            if cells.iter().any(|&c| !ws.inside(c)) {
                continue;
            }
            let p = ws.rt.point(v);
            let Some(target) = (match smoother {
                Smoother::Odt => odt_target(ws, &cells),
                Smoother::Lloyd => lloyd_target(ws, v, &cells),
            }) else {
                continue;
            };
            let shortest = shortest_edge(ws, v, &cells);
            let relative = target.distance(p) / shortest;
            if relative.is_nan() || relative < FREEZE {
                continue;
            }
            let w = ws.rt.weight(v);
            let keep = |before: f64, after: f64| after >= before.min(KEEP_ANGLE);
            if ws.try_move(v, target, w, keep).is_some() {
                kept += 1;
                largest = largest.max(relative);
            }
        }
        if largest < CONVERGENCE {
            return (kept, sweep + 1);
        }
    }
    (kept, max_sweeps)
}

/// The volume-weighted mean of the circumcentres of `cells`.
fn odt_target(ws: &Workspace<'_>, cells: &[CellId]) -> Option<Point3> {
    let (mut sum, mut total) = (Point3::ZERO, 0.0);
    for &c in cells {
        let p = ws.points(c);
        let vol = tet_volume(&p);
        sum += tet_circumcenter(&p)? * vol;
        total += vol;
    }
    (total > 0.0).then(|| sum / total)
}

/// The centroid of the Voronoi cell of `v`, split into the pieces `(v, edge midpoint, facet
/// circumcentre, cell circumcentre)` of every cell, edge and facet around `v`, each signed by
/// the orientation of the simplices it comes from (so obtuse cells subtract what lies outside).
fn lloyd_target(ws: &Workspace<'_>, v: VertexId, cells: &[CellId]) -> Option<Point3> {
    let p = ws.rt.point(v);
    let (mut sum, mut total) = (Point3::ZERO, 0.0);
    for &c in cells {
        let q = ws.rt.cell(c);
        let others: Vec<Point3> = q
            .iter()
            .filter(|&&u| u != v)
            .map(|&u| ws.rt.point(u))
            .collect();
        let cc = tet_circumcenter(&ws.points(c))?;
        for a in 0..3 {
            for b in 0..3 {
                if a == b {
                    continue;
                }
                let (u, w, x) = (others[a], others[b], others[3 - a - b]);
                let m = 0.5 * (p + u);
                let fc = triangle_circumcenter(p, u, w);
                let piece = [p, m, fc, cc];
                let sign = tet_volume(&[p, u, w, x]).signum();
                let vol = tet_volume(&piece) * sign;
                sum += (p + m + fc + cc) * (vol / 4.0);
                total += vol;
            }
        }
    }
    (total > 0.0).then(|| sum / total)
}

/// Length of the shortest edge at `v` among `cells`.
fn shortest_edge(ws: &Workspace<'_>, v: VertexId, cells: &[CellId]) -> f64 {
    let p = ws.rt.point(v);
    cells
        .iter()
        .flat_map(|&c| ws.rt.cell(c))
        .filter(|&u| u != v)
        .map(|u| ws.rt.point(u).distance(p))
        .fold(f64::INFINITY, f64::min)
}
