//! The curve level of piecewise-smooth meshing: the protecting balls, inserted as weighted
//! vertices before refinement, and the guard that keeps every refinement point out of them.
//!
//! Rules R1–R2 of chapter 4 (restricted curve edges joining consecutive samples, small curve
//! balls) hold by construction of the protection ([`super::protect`]), so this level never has
//! an element of its own to refine; its job is `check`: a point of the surface or cell level
//! inside a protecting ball would be hidden by the regular triangulation (or, with a rounding
//! error, would cut a curve edge), so it is refused for good. With exact predicates and a valid
//! protection this never happens (power-diagram points off the balls have a non-negative power
//! distance to their owners); the guard makes a rounding error cost one refinement point, not a
//! broken curve or an endless loop.

use super::engine::{Candidate, Check, MesherLevel};
use super::protect::{Feature, Protection};
use crate::kernel::Point3;
use crate::oracle::CurveId;
use crate::triangulation::{InsertReport, Triangulation, VertexId};
use rustc_hash::FxHashMap;

/// The protecting balls of a domain, with their vertices in the triangulation.
pub struct CurveLevel {
    protection: Protection,
    /// Vertex of each ball (`None`: hidden by the regular triangulation, so not in the mesh).
    vertices: Vec<Option<VertexId>>,
    /// Balls by grid cell (cell side = the largest diameter): a point is in a ball of its own
    /// cell or of a neighbouring one. Only looked up, never iterated, so order cannot leak.
    grid: FxHashMap<[i64; 3], Vec<u32>>,
    cell_size: f64,
}

impl CurveLevel {
    pub fn new(protection: Protection, vertices: Vec<Option<VertexId>>) -> Self {
        let cell_size = protection
            .balls
            .iter()
            .fold(0.0f64, |m, b| m.max(2.0 * b.radius))
            .max(f64::MIN_POSITIVE);
        let mut level = CurveLevel {
            protection,
            vertices,
            grid: FxHashMap::default(),
            cell_size,
        };
        for (i, b) in level.protection.balls.iter().enumerate() {
            let key = level.key(b.center);
            level.grid.entry(key).or_default().push(i as u32);
        }
        level
    }

    fn key(&self, p: Point3) -> [i64; 3] {
        (p / self.cell_size).floor().to_array().map(|x| x as i64)
    }

    /// Is `p` strictly inside a protecting ball (negative power distance to its vertex)?
    pub fn in_a_ball(&self, p: Point3) -> bool {
        let [x, y, z] = self.key(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(balls) = self.grid.get(&[x + dx, y + dy, z + dz]) else {
                        continue;
                    };
                    if balls.iter().any(|&b| {
                        let b = &self.protection.balls[b as usize];
                        b.center.distance_squared(p) < b.radius * b.radius
                    }) {
                        return true;
                    }
                }
            }
        }
        false
    }

    pub fn protection(&self) -> &Protection {
        &self.protection
    }

    /// The vertex of ball `b`, if it is in the triangulation.
    pub fn ball_vertex(&self, b: usize) -> Option<VertexId> {
        self.vertices.get(b).copied().flatten()
    }

    /// Dimension of the feature a ball lies on, with its curve: 0 for a corner, 1 for a curve.
    pub fn ball_feature(&self, b: usize) -> (u8, Option<CurveId>) {
        match self.protection.balls[b].feature {
            Feature::Corner(_) => (0, None),
            Feature::Curve(c) => (1, Some(c)),
        }
    }
}

impl<T: Triangulation<Point = Point3>> MesherLevel<T> for CurveLevel {
    /// Nothing is ever queued (see the module documentation).
    type Element = std::convert::Infallible;

    fn name(&self) -> &'static str {
        "curve balls"
    }

    fn scan(&mut self, _tr: &T) {}

    fn next_element(&mut self, _tr: &T) -> Option<Self::Element> {
        None
    }

    fn pop_element(&mut self) {}

    fn refinement_point(&mut self, _tr: &T, e: &Self::Element) -> Option<Candidate<Point3>> {
        match *e {}
    }

    fn check(&mut self, _tr: &T, c: &Candidate<Point3>, _own: bool) -> Check {
        if self.in_a_ball(c.point) {
            Check::RejectedForever
        } else {
            Check::Accepted
        }
    }

    fn after_insertion(&mut self, _tr: &T, _v: VertexId, _report: &InsertReport, _own: bool) {}

    fn pending(&self) -> usize {
        0
    }
}
