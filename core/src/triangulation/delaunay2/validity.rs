//! The validity checker: combinatorics, orientation, exact local Delaunay property, counts.

use super::predicates::orient2d;
use super::{CellId, Triangulation, VertexId};
use super::{Delaunay2, INFINITE, NO_CELL};
use std::cmp::Ordering;

/// The first defect the checker found.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum ValidityError {
    #[error("cell {0:?} has a dead or asymmetric neighbour across edge {1}")]
    Adjacency(CellId, usize),
    #[error("finite cell {0:?} is not counter-clockwise")]
    Orientation(CellId),
    #[error("edge {1} of cell {0:?} is not locally Delaunay")]
    NotDelaunay(CellId, usize),
    #[error("vertex {0:?} does not point to a live cell containing it")]
    VertexCell(VertexId),
    #[error("{found} finite triangles, expected {expected} (2n - b - 2)")]
    Count { found: usize, expected: usize },
}

impl Delaunay2 {
    /// Checks symmetric adjacency, positive orientation, every vertex's cell, the exact (perturbed)
    /// local Delaunay test on every edge including hull convexity, and the triangle count
    /// 2n − b − 2 (b hull vertices).
    pub fn check_validity(&self) -> Result<(), ValidityError> {
        let mut cells = 0;
        let mut hull = 0;
        for c in self.cells() {
            cells += 1;
            let v = self.cell(c);
            if v.contains(&INFINITE) {
                hull += 1;
            } else if orient2d(self.point(v[0]), self.point(v[1]), self.point(v[2]))
                != Ordering::Greater
            {
                return Err(ValidityError::Orientation(c));
            }
            for i in 0..3 {
                let n = self.neighbor(c, i);
                if n == NO_CELL || !self.is_live(n) {
                    return Err(ValidityError::Adjacency(c, i));
                }
                let j = self.mirror_index(c, i);
                let w = self.cell(n);
                if self.neighbor(n, j) != c
                    || w[(j + 1) % 3] != v[(i + 2) % 3]
                    || w[(j + 2) % 3] != v[(i + 1) % 3]
                {
                    return Err(ValidityError::Adjacency(c, i));
                }
                if w[j] != INFINITE && self.in_conflict(c, self.point(w[j])) {
                    return Err(ValidityError::NotDelaunay(c, i));
                }
            }
        }
        if cells == 0 {
            return Ok(());
        }
        for v in self.vertices() {
            let c = self.vertex_cell_of(v);
            if !self.is_live(c) || !self.cell(c).contains(&v) {
                return Err(ValidityError::VertexCell(v));
            }
        }
        let expected = (2 * self.num_vertices()).saturating_sub(hull + 2);
        let found = cells - hull;
        if found != expected || found != self.num_finite_cells() {
            return Err(ValidityError::Count { found, expected });
        }
        Ok(())
    }
}
