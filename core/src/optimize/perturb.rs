//! Sliver perturbation (Tournois, Srinivasan and Alliez 2009): a vertex of a sliver moves along
//! the gradient of the sliver's smallest dihedral angle (or, when that does not help, in a few
//! pseudo-random directions), by a fraction of its distance to the sliver's other vertices. A
//! surface vertex moves in the tangent plane and is put back on its patch by the oracle; curve
//! vertices and corners stay. A move is kept when the smallest dihedral angle of the cells it
//! changed is larger than that of the cells it destroyed. A sliver lying on the surface with two
//! boundary facets cannot be moved away without changing the surface: it is peeled off instead
//! (see [`Workspace::peel`]), which flips the surface edge under it.

use super::Deadline;
use super::state::{Workspace, min_dihedral};
use crate::complex::VertexDimension;
use crate::kernel::Point3;
use crate::oracle::{PatchId, SurfaceHit};
use crate::triangulation::{CellId, Triangulation, VertexId};

/// Step lengths tried along a direction, as fractions of the distance to the nearest other
/// vertex of the sliver (smallest last: a small step is the likeliest to be accepted but gains
/// least).
const STEPS: [f64; 3] = [0.25, 0.1, 0.04];
/// Pseudo-random directions tried when the gradient does not help (with the middle step).
const RANDOM_TRIES: usize = 2;
/// Whether surface vertices move (along the surface). Off: on two boxes sharing a face the
/// moves lost a tenth of one box's volume (tests/cli_features.rs), a defect not found yet.
const MOVE_SURFACE_VERTICES: bool = true;
/// Sweeps over the slivers at most.
const MAX_SWEEPS: usize = 6;

/// Perturbs the vertices of the cells below `bound` degrees, worst first, until a sweep improves
/// nothing or the deadline passes. Returns the number of moves kept.
pub(super) fn perturb(ws: &mut Workspace<'_>, bound: f64, deadline: &Deadline) -> usize {
    let mut rng = 0x9E37_79B9_7F4A_7C15u64;
    ws.sweep_slivers(bound, deadline, MAX_SWEEPS, |ws, c| {
        ws.peel(c) || perturb_cell(ws, c, &mut rng)
    })
}

/// Tries to improve sliver `c` by moving one of its vertices.
fn perturb_cell(ws: &mut Workspace<'_>, c: CellId, rng: &mut u64) -> bool {
    let cell = ws.rt.cell(c);
    for k in 0..4 {
        let v = cell[k];
        let surface = match ws.dimension[v.0 as usize] {
            VertexDimension::Volume => None,
            VertexDimension::Surface if MOVE_SURFACE_VERTICES => match surface_frame(ws, v) {
                Some(frame) => Some(frame),
                None => continue,
            },
            VertexDimension::Surface | VertexDimension::Curve | VertexDimension::Corner => continue,
        };
        let p = ws.rt.point(v);
        let others: Vec<Point3> = (0..4)
            .filter(|&j| j != k)
            .map(|j| ws.rt.point(cell[j]))
            .collect();
        let reach = others
            .iter()
            .map(|q| q.distance(p))
            .fold(f64::INFINITY, f64::min);
        let tangent = |d: Point3| match surface {
            Some((n, _)) => d - n * d.dot(n),
            None => d,
        };
        let angle_at = |x: Point3| {
            let mut t = cell.map(|u| ws.rt.point(u));
            t[k] = x;
            t.swap(0, 1);
            min_dihedral(&t)
        };
        let mut tries = Vec::with_capacity(STEPS.len() + RANDOM_TRIES);
        let g = tangent(gradient(angle_at, p, 1e-4 * reach));
        if g.length() > 0.0 {
            tries.extend(STEPS.map(|s| (g.normalize(), s)));
        }
        for _ in 0..RANDOM_TRIES {
            let d = tangent(random_unit(rng));
            if d.length() > 1e-3 {
                tries.push((d.normalize(), STEPS[1]));
            }
        }
        for (d, s) in tries {
            let mut q = p + d * (s * reach);
            if let Some((n, patch)) = surface {
                match project(ws, q, n, reach, patch) {
                    Some(on) => q = on,
                    None => continue,
                }
            }
            let w = ws.rt.weight(v);
            if let Some(change) = ws.try_move(v, q, w) {
                let on_surface = surface
                    .is_none_or(|(n, _)| facets_face(ws, v, n) && ws.surface_near_around(v));
                if change.after > change.before && on_surface {
                    return true;
                }
                ws.undo(change);
            }
        }
    }
    false
}

/// Central-difference gradient of `f` at `p` with step `h`.
fn gradient(f: impl Fn(Point3) -> f64, p: Point3, h: f64) -> Point3 {
    let axis = [Point3::X, Point3::Y, Point3::Z];
    let d = axis.map(|e| (f(p + e * h) - f(p - e * h)) / (2.0 * h));
    Point3::new(d[0], d[1], d[2])
}

/// A pseudo-random unit vector (xorshift; the sequence is fixed, so runs repeat).
fn random_unit(state: &mut u64) -> Point3 {
    let mut next = || {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let d = Point3::new(next(), next(), next());
    if d.length() > 0.0 {
        d.normalize()
    } else {
        Point3::X
    }
}

/// The unit normal of the surface at surface vertex `v` (area-weighted over its boundary
/// facets) and its patch, when all its boundary facets lie on one patch between the same two
/// subdomains (a vertex on several patches, or where a third subdomain meets them, sits on a
/// feature and stays).
pub(super) fn surface_frame(ws: &Workspace<'_>, v: VertexId) -> Option<(Point3, PatchId)> {
    let mut normals = Vec::new();
    let patch = facet_normals(ws, v, &mut normals)?;
    let normal = normals.iter().fold(Point3::ZERO, |s, &n| s + n);
    (normal.length() > 0.0).then(|| (normal.normalize(), patch))
}

/// Whether every boundary facet around `v` faces the side `n` points to: a surface move that
/// folds a facet over is refused even when the facet stays near the surface.
fn facets_face(ws: &Workspace<'_>, v: VertexId, n: Point3) -> bool {
    let mut normals = Vec::new();
    facet_normals(ws, v, &mut normals).is_some() && normals.iter().all(|m| m.dot(n) > 0.0)
}

/// The area-weighted normals of the boundary facets around `v`, oriented from the first of the
/// two subdomains they separate to the second, and their patch; `None` when they lie on several
/// patches or between several pairs of subdomains.
fn facet_normals(ws: &Workspace<'_>, v: VertexId, out: &mut Vec<Point3>) -> Option<PatchId> {
    let mut cells = Vec::new();
    ws.rt.incident_cells(v, &mut cells);
    let mut patch = None;
    let mut sides = None;
    for &c in &cells {
        if !ws.inside(c) {
            continue;
        }
        let q = ws.rt.cell(c);
        for i in 0..4 {
            if q[i] == v {
                continue;
            }
            let mut key = [0u32; 3];
            let mut n = 0;
            for (j, u) in q.iter().enumerate() {
                if j != i {
                    key[n] = u.0;
                    n += 1;
                }
            }
            key.sort_unstable();
            let (Some(pt), Some(sd)) = (ws.patch(&key), ws.sides(&key)) else {
                continue;
            };
            if *patch.get_or_insert(pt) != pt || *sides.get_or_insert(sd) != sd {
                return None;
            }
            let f: Vec<Point3> = (0..4)
                .filter(|&j| j != i)
                .map(|j| ws.rt.point(q[j]))
                .collect();
            let mut n = (f[1] - f[0]).cross(f[2] - f[0]);
            // Out of the cell, then from the first side to the second.
            if (n.dot(ws.rt.point(q[i]) - f[0]) > 0.0) == (ws.label(c) == sd[0]) {
                n = -n;
            }
            out.push(n);
        }
    }
    patch
}

/// The point of `patch` nearest to `q` along the line through `q` with direction `n`, within
/// `reach` of `q`.
pub(super) fn project(
    ws: &Workspace<'_>,
    q: Point3,
    n: Point3,
    reach: f64,
    patch: PatchId,
) -> Option<Point3> {
    let mut hits: Vec<SurfaceHit> = Vec::new();
    ws.oracle
        .segment_hits(q - n * reach, q + n * reach, &mut hits);
    hits.iter()
        .filter(|h| h.patch == patch)
        .min_by(|a, b| (a.t - 0.5).abs().total_cmp(&(b.t - 0.5).abs()))
        .map(|h| h.point)
}
