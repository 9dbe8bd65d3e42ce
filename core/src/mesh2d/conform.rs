//! Pébay's algorithms 3.1, 3.1′ and 3.2: split the segments of a PSLG, before triangulating, until
//! every sub-edge is strongly Delaunay-admissible; then triangulate the enlarged point set.
//!
//! Two primitives: *projection* splits an edge at the foot of a point of its diametral disk
//! (Lemma 3.1: the disks' point counts strictly drop), and *cleaning* (nettoyage) cuts every edge of
//! an acute node at the same distance d from the centre (Lemma 3.4: the short pieces are type 0).
//! New points are evaluated on the *original* segment from a parameter, so the sub-edges of a
//! segment stay as collinear as floating point allows.

use super::admissible::{Classification, Witness, classify_with};
use super::grid::PointGrid;
use super::pslg::{Pslg, PslgError};
use crate::triangulation::delaunay2::predicates::{dot_sign, orient2d};
use crate::triangulation::delaunay2::{Delaunay2, InsertOutcome, TriangulationError, VertexId};
use glam::DVec2;
use std::cmp::{Ordering, Reverse};
use std::collections::BTreeSet;

/// Which of Pébay's algorithms to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Algorithm {
    /// 3.1: clean every acute angle met by a non-admissible edge, project otherwise.
    Brute,
    /// 3.1′: like 3.1 but clean only at nodes of more than two edges.
    BruteLargeNodes,
    /// 3.2: clean only at closed nodes (every angular gap < π/2), project otherwise.
    ClosedNodes,
    /// Projection alone: not guaranteed to terminate (Pébay's Figs. 20–21); for comparison.
    ProjectionOnly,
}

/// Options of [`conform`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConformOptions {
    /// Which of Pébay's algorithms makes the constraints admissible.
    pub algorithm: Algorithm,
    /// Maximum number of projection / cleaning steps before giving up.
    pub max_iterations: usize,
    /// Shortest sub-edge allowed, relative to the diagonal of the input's bounding box.
    pub min_relative_length: f64,
}

impl Default for ConformOptions {
    fn default() -> Self {
        Self {
            algorithm: Algorithm::ClosedNodes,
            max_iterations: 100_000,
            min_relative_length: 1e-10,
        }
    }
}

/// Why [`conform`] failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum ConformError {
    #[error("invalid constraint")]
    Invalid(#[from] PslgError),
    #[error("no Delaunay-admissible subdivision after {0} steps (iteration cap)")]
    IterationCap(usize),
    #[error(
        "a split of segment {segment} would create a sub-edge of length {length:e}, below the minimum"
    )]
    TooShort { segment: usize, length: f64 },
    #[error("triangulation failed")]
    Triangulation(#[from] TriangulationError),
}

/// The subdivided constraint and the Delaunay triangulation of its points.
#[derive(Debug)]
pub struct Conformed {
    /// The input points first, then the inserted ones.
    pub points: Vec<DVec2>,
    /// Sub-edges (indices into `points`), each oriented like its original segment.
    pub segments: Vec<[u32; 2]>,
    /// For each sub-edge, the input segment it is part of.
    pub segment_origins: Vec<u32>,
    /// Projection and cleaning steps performed.
    pub iterations: usize,
    /// The conforming triangulation.
    pub triangulation: Delaunay2,
    /// The triangulation vertex of each point.
    pub vertex_of_point: Vec<VertexId>,
}

#[derive(Debug, Clone)]
struct SubEdge {
    ends: [u32; 2],
    origin: u32,
    /// Parameters of the ends along the original segment (0 at its start, 1 at its end).
    params: [f64; 2],
    alive: bool,
    admissible: bool,
    witness: Witness,
    bounds: (DVec2, DVec2),
}

/// The working state of the algorithms.
pub(crate) struct Conformer {
    points: Vec<DVec2>,
    originals: Vec<(DVec2, DVec2)>,
    edges: Vec<SubEdge>,
    incident: Vec<Vec<u32>>,
    grid: PointGrid,
    /// T(Γ): non-admissible edges, most encroached first.
    queue: BTreeSet<(Reverse<usize>, u32)>,
    min_length: f64,
}

/// Runs the chosen algorithm on `pslg` and triangulates the result.
pub fn conform(pslg: &Pslg, options: &ConformOptions) -> Result<Conformed, ConformError> {
    pslg.validate()?;
    let mut c = Conformer::new(pslg, options.min_relative_length);
    let iterations = c.run(options.algorithm, options.max_iterations)?;
    c.finish(iterations)
}

impl Conformer {
    pub(crate) fn new(pslg: &Pslg, min_relative_length: f64) -> Self {
        let (lo, hi) = pslg.bounds().unwrap_or((DVec2::ZERO, DVec2::ONE));
        let mut grid = PointGrid::new(lo, hi, pslg.points.len());
        for (i, &p) in pslg.points.iter().enumerate() {
            grid.insert(p, i as u32);
        }
        let originals = pslg
            .segments
            .iter()
            .map(|&[a, b]| (pslg.points[a as usize], pslg.points[b as usize]))
            .collect();
        let mut c = Self {
            points: pslg.points.clone(),
            originals,
            edges: Vec::new(),
            incident: vec![Vec::new(); pslg.points.len()],
            grid,
            queue: BTreeSet::new(),
            min_length: min_relative_length * (hi - lo).length(),
        };
        for (s, &ends) in pslg.segments.iter().enumerate() {
            c.add_edge(ends, s as u32, [0.0, 1.0]);
        }
        for e in 0..c.edges.len() as u32 {
            c.classify(e);
        }
        c
    }

    fn add_edge(&mut self, ends: [u32; 2], origin: u32, params: [f64; 2]) -> u32 {
        let id = self.edges.len() as u32;
        self.edges.push(SubEdge {
            ends,
            origin,
            params,
            alive: true,
            admissible: true,
            witness: Witness::Diametral,
            bounds: (DVec2::ZERO, DVec2::ZERO),
        });
        for v in ends {
            self.incident[v as usize].push(id);
        }
        id
    }

    fn end_points(&self, e: u32) -> (DVec2, DVec2) {
        let [a, b] = self.edges[e as usize].ends;
        (self.points[a as usize], self.points[b as usize])
    }

    /// Θ₂ of edge `e` against the current points; updates its status and T(Γ).
    pub(crate) fn classify(&mut self, e: u32) -> Classification {
        let [a, b] = self.edges[e as usize].ends;
        let grid = &self.grid;
        let cls = classify_with(&self.points, a, b, |lo, hi, out| {
            grid.candidates(lo, hi, out)
        });
        let (pa, pb) = self.end_points(e);
        let edge = &mut self.edges[e as usize];
        edge.admissible = cls.class.is_strongly_admissible();
        edge.witness = cls.witness;
        edge.bounds = cls.witness.bounds(pa, pb);
        if !edge.admissible {
            self.queue.insert((Reverse(cls.encroaching.len()), e));
        }
        cls
    }

    /// Splits edge `e` at parameter `s` of its original segment; returns the new point.
    fn split(&mut self, e: u32, s: f64) -> Result<u32, ConformError> {
        let edge = self.edges[e as usize].clone();
        let (o0, o1) = self.originals[edge.origin as usize];
        let m = o0 + (o1 - o0) * s;
        let (pa, pb) = self.end_points(e);
        let shortest = (m - pa).length().min((pb - m).length());
        if !(shortest >= self.min_length && shortest > 0.0) {
            return Err(ConformError::TooShort {
                segment: edge.origin as usize,
                length: shortest,
            });
        }
        let id = self.points.len() as u32;
        self.points.push(m);
        self.incident.push(Vec::new());
        self.grid.insert(m, id);
        self.edges[e as usize].alive = false;
        self.queue.retain(|&(_, x)| x != e);
        for v in edge.ends {
            self.incident[v as usize].retain(|&x| x != e);
        }
        let [a, b] = edge.ends;
        let e1 = self.add_edge([a, id], edge.origin, [edge.params[0], s]);
        let e2 = self.add_edge([id, b], edge.origin, [s, edge.params[1]]);
        // Admissible edges whose witness disk now holds the new point may have lost admissibility;
        // non-admissible ones cannot regain it by adding points.
        let stale: Vec<u32> = (0..e1)
            .filter(|&f| {
                let edge = &self.edges[f as usize];
                let (lo, hi) = edge.bounds;
                edge.alive && edge.admissible && m.cmpge(lo).all() && m.cmple(hi).all() && {
                    let (fa, fb) = self.end_points(f);
                    edge.witness.holds(fa, fb, m)
                }
            })
            .collect();
        for f in stale.into_iter().chain([e1, e2]) {
            self.classify(f);
        }
        Ok(id)
    }

    /// Lemma 3.1: split `e` at the orthogonal projection of one of its encroaching points (the one
    /// whose foot is nearest the middle, for balanced pieces).
    pub(crate) fn project(&mut self, e: u32, encroaching: &[u32]) -> Result<u32, ConformError> {
        let (pa, pb) = self.end_points(e);
        let d = pb - pa;
        let t = encroaching
            .iter()
            .map(|&k| (self.points[k as usize] - pa).dot(d) / d.length_squared())
            .min_by(|x, y| (x - 0.5).abs().total_cmp(&(y - 0.5).abs()))
            .unwrap_or(0.5);
        let [s0, s1] = self.edges[e as usize].params;
        self.split(e, s0 + t * (s1 - s0))
    }

    /// Lemma 3.4: cut every edge of `node` (all incident to `center`) at the same distance
    /// d = d*/2, d* the distance from `center` to the nearest other point in their diametral disks.
    pub(crate) fn clean(&mut self, center: u32, node: &[u32]) -> Result<f64, ConformError> {
        let pc = self.points[center as usize];
        let mut dstar = f64::INFINITY;
        let mut cand = Vec::new();
        for &e in node {
            let (pa, pb) = self.end_points(e);
            let (lo, hi) = Witness::Diametral.bounds(pa, pb);
            self.grid.candidates(lo, hi, &mut cand);
            for &k in &cand {
                let p = self.points[k as usize];
                if k != center && dot_sign(p, pa, pb) != Ordering::Greater {
                    dstar = dstar.min((p - pc).length());
                }
            }
        }
        let d = dstar / 2.0;
        for &e in node {
            let edge = &self.edges[e as usize];
            let (pa, pb) = self.end_points(e);
            let len = (pb - pa).length();
            let [s0, s1] = edge.params;
            let s = if edge.ends[0] == center {
                s0 + (d / len) * (s1 - s0)
            } else {
                s1 + (d / len) * (s0 - s1)
            };
            self.split(e, s)?;
        }
        Ok(d)
    }

    /// Edges at `v`, in counter-clockwise order of direction (exact comparison).
    fn sorted_spokes(&self, v: u32) -> Vec<(u32, DVec2)> {
        let pv = self.points[v as usize];
        let mut spokes: Vec<(u32, DVec2)> = self.incident[v as usize]
            .iter()
            .map(|&e| {
                let [a, b] = self.edges[e as usize].ends;
                let w = if a == v { b } else { a };
                (e, self.points[w as usize])
            })
            .collect();
        let half = |p: DVec2| p.y < pv.y || (p.y == pv.y && p.x < pv.x);
        spokes.sort_by(|&(_, p), &(_, q)| {
            half(p)
                .cmp(&half(q))
                .then_with(|| orient2d(pv, q, p))
                .then(Ordering::Equal)
        });
        spokes
    }

    /// Edges at `v` that form an acute angle with another edge at `v` (the list L).
    fn acute_edges(&self, v: u32) -> Vec<u32> {
        let pv = self.points[v as usize];
        let spokes = self.sorted_spokes(v);
        spokes
            .iter()
            .filter(|&&(e, p)| {
                spokes
                    .iter()
                    .any(|&(f, q)| f != e && dot_sign(pv, p, q) == Ordering::Greater)
            })
            .map(|&(e, _)| e)
            .collect()
    }

    /// Def. 3.1: a closed node has every angular gap between consecutive edges below π/2.
    pub(crate) fn is_closed_node(&self, v: u32) -> bool {
        let pv = self.points[v as usize];
        let spokes = self.sorted_spokes(v);
        spokes.len() >= 5
            && (0..spokes.len()).all(|k| {
                let p = spokes[k].1;
                let q = spokes[(k + 1) % spokes.len()].1;
                orient2d(pv, p, q) == Ordering::Greater && dot_sign(pv, p, q) == Ordering::Greater
            })
    }

    /// Runs the algorithm until T(Γ) is empty; returns the number of steps.
    pub(crate) fn run(&mut self, algorithm: Algorithm, cap: usize) -> Result<usize, ConformError> {
        let closed_nodes: Vec<u32> = if algorithm == Algorithm::ClosedNodes {
            (0..self.points.len() as u32)
                .filter(|&v| self.is_closed_node(v))
                .collect()
        } else {
            Vec::new()
        };
        let mut steps = 0;
        loop {
            if self.queue.is_empty() {
                return Ok(steps);
            }
            if steps >= cap {
                return Err(ConformError::IterationCap(steps));
            }
            steps += 1;
            let node = closed_nodes.iter().copied().find(|&v| {
                self.incident[v as usize]
                    .iter()
                    .any(|&e| !self.edges[e as usize].admissible)
            });
            if let Some(v) = node {
                let spokes = self.incident[v as usize].clone();
                self.clean(v, &spokes)?;
                continue;
            }
            let Some((_, e)) = self.queue.pop_first() else {
                return Ok(steps);
            };
            // Reclassify against the current points (the queued count may be stale).
            let cls = self.classify(e);
            if cls.class.is_strongly_admissible() {
                continue;
            }
            let mut cleaned = false;
            if matches!(algorithm, Algorithm::Brute | Algorithm::BruteLargeNodes) {
                for v in self.edges[e as usize].ends {
                    let list = self.acute_edges(v);
                    let large = self.incident[v as usize].len() > 2;
                    if !list.is_empty() && (algorithm == Algorithm::Brute || large) {
                        self.clean(v, &list)?;
                        cleaned = true;
                    }
                }
            }
            if !cleaned && self.edges[e as usize].alive {
                self.project(e, &cls.encroaching)?;
            }
        }
    }

    /// The live sub-edges as a constraint, and the Delaunay triangulation of all points.
    fn finish(self, iterations: usize) -> Result<Conformed, ConformError> {
        let (triangulation, outcomes) = Delaunay2::from_points(&self.points)?;
        let vertex_of_point = outcomes.into_iter().map(InsertOutcome::vertex).collect();
        let live: Vec<&SubEdge> = self.edges.iter().filter(|e| e.alive).collect();
        Ok(Conformed {
            segments: live.iter().map(|e| e.ends).collect(),
            segment_origins: live.iter().map(|e| e.origin).collect(),
            points: self.points,
            iterations,
            triangulation,
            vertex_of_point,
        })
    }

    #[cfg(test)]
    pub(crate) fn live_edges(&self) -> Vec<(u32, [u32; 2])> {
        (0..self.edges.len() as u32)
            .filter(|&e| self.edges[e as usize].alive)
            .map(|e| (e, self.edges[e as usize].ends))
            .collect()
    }

    #[cfg(test)]
    pub(crate) fn points(&self) -> &[DVec2] {
        &self.points
    }
}
