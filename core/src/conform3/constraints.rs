//! The constraints being recovered: each input edge as a chain of sub-segments, each input
//! triangle as its corners, its three edges and the Steiner points inside it.

use super::PreserveError;
use crate::kernel::{Point2, Point3, Sign, orient2d};
use crate::mesh::first_out_of_range;
use crate::oracle::PatchId;
use crate::triangulation::VertexId;

/// An input edge and the vertices along it.
#[derive(Clone, Debug)]
pub(super) struct InputEdge {
    /// Its input vertices, the smaller index first.
    pub ends: [u32; 2],
    /// The positions of `ends`.
    pub points: [Point3; 2],
    /// `(parameter from ends[0], vertex)` in increasing parameter, from 0 to 1: consecutive
    /// entries are the sub-segments.
    pub chain: Vec<(f64, VertexId)>,
}

impl InputEdge {
    /// Where to split sub-segment `i` (between `chain[i]` and `chain[i + 1]`): its midpoint, or,
    /// when exactly one end is an input vertex, the power-of-two distance from that vertex closest
    /// to the midpoint (so that edges meeting there at a small angle are split on the same
    /// spheres and stop encroaching each other). Between two Steiner points, or on a whole
    /// edge, the foot of `encroacher` (the vertex that most encroaches the sub-segment) is
    /// taken instead when it is not near an end: both pieces then leave that vertex out of
    /// their diametral balls (Pébay's projection). `None` when a piece would be shorter than
    /// `min_length` or the point would round onto an end.
    pub fn split_point(
        &self,
        i: usize,
        encroacher: Option<Point3>,
        min_length: f64,
    ) -> Option<(f64, Point3)> {
        let [a, b] = self.points;
        let length = (b - a).length();
        let (t0, t1) = (self.chain[i].0, self.chain[i + 1].0);
        let piece = (t1 - t0) * length;
        let shell = (piece / 2.0).log2().round().exp2() / length;
        let (from_start, to_end) = (i == 0, i + 2 == self.chain.len());
        let t = match (from_start, to_end) {
            (true, false) => t0 + shell,
            (false, true) => t1 - shell,
            _ => {
                let foot = encroacher.map_or(0.5, |x| {
                    let (p, q) = (self.at(t0), self.at(t1));
                    (x - p).dot(q - p) / (q - p).length_squared()
                });
                let s = if (0.1..=0.9).contains(&foot) {
                    foot
                } else {
                    0.5
                };
                t0 + s * (t1 - t0)
            }
        };
        let shortest = (t - t0).min(t1 - t) * length;
        if !(shortest >= min_length && shortest > 0.0) {
            return None;
        }
        let p = self.at(t);
        (p != a && p != b && p.is_finite()).then_some((t, p))
    }

    /// The point at parameter `t`, from the nearer end for accuracy.
    fn at(&self, t: f64) -> Point3 {
        let [a, b] = self.points;
        if t <= 0.5 {
            a + (b - a) * t
        } else {
            b + (a - b) * (1.0 - t)
        }
    }
}

/// An input triangle and the vertices on it.
#[derive(Clone, Debug)]
pub(super) struct Facet {
    /// Its corners as input vertices, in the input's order.
    pub input: [u32; 3],
    /// Its corners' triangulation vertices.
    pub corners: [VertexId; 3],
    /// Edge `k` joins corner `k` to corner `k + 1`: its input edge.
    pub edges: [u32; 3],
    /// Steiner points inside the triangle.
    pub interior: Vec<VertexId>,
    /// The input's patch of the triangle.
    pub patch: PatchId,
}

/// Every input edge and triangle, and the triangulation vertex of every input vertex.
#[derive(Clone, Debug)]
pub(super) struct Constraints {
    pub edges: Vec<InputEdge>,
    pub facets: Vec<Facet>,
    /// The input vertices used by a triangle, in increasing order.
    used: Vec<u32>,
}

impl Constraints {
    /// Checks the triangles and lists their edges.
    pub fn new(
        points: &[Point3],
        triangles: &[[u32; 3]],
        patches: &[PatchId],
    ) -> Result<Self, PreserveError> {
        if triangles.is_empty() {
            return Err(PreserveError::Empty);
        }
        if patches.len() != triangles.len() {
            return Err(PreserveError::PatchCount(patches.len(), triangles.len()));
        }
        if let Some((triangle, index)) = first_out_of_range(triangles, points.len()) {
            return Err(PreserveError::IndexOutOfRange {
                triangle,
                index,
                count: points.len(),
            });
        }
        let degenerate = |tri: &[u32; 3]| is_degenerate(tri.map(|v| points[v as usize]));
        if let Some(t) = triangles.iter().position(degenerate) {
            return Err(PreserveError::DegenerateTriangle(t));
        }
        let mut keys: Vec<[u32; 2]> = triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| sorted(t[k], t[(k + 1) % 3])))
            .collect();
        keys.sort_unstable();
        keys.dedup();
        let edges = keys
            .iter()
            .map(|&ends| InputEdge {
                ends,
                points: ends.map(|v| points[v as usize]),
                chain: Vec::new(),
            })
            .collect();
        let facets = triangles
            .iter()
            .zip(patches)
            .map(|(t, &patch)| Facet {
                input: *t,
                corners: [VertexId(0); 3],
                edges: [0, 1, 2].map(|k| {
                    let key = sorted(t[k], t[(k + 1) % 3]);
                    keys.binary_search(&key).map_or(0, |e| e as u32)
                }),
                interior: Vec::new(),
                patch,
            })
            .collect();
        let mut used: Vec<u32> = triangles.iter().flatten().copied().collect();
        used.sort_unstable();
        used.dedup();
        Ok(Constraints {
            edges,
            facets,
            used,
        })
    }

    /// The positions of the used input vertices, in the order of `used`.
    pub fn used_points(&self, points: &[Point3]) -> Vec<Point3> {
        self.used.iter().map(|&v| points[v as usize]).collect()
    }

    /// Two used input vertices that became one triangulation vertex (same position), if any.
    pub fn first_duplicate(&self, vertices: &[VertexId]) -> Option<(u32, u32)> {
        let mut by_vertex: Vec<(VertexId, u32)> = vertices
            .iter()
            .zip(&self.used)
            .map(|(&v, &i)| (v, i))
            .collect();
        by_vertex.sort_unstable();
        by_vertex
            .windows(2)
            .find(|w| w[0].0 == w[1].0)
            .map(|w| (w[0].1, w[1].1))
    }

    /// Records the triangulation vertex of every used input vertex (`vertices[i]` is that of
    /// `used[i]`): the ends of every chain and the corners of every facet.
    pub fn attach(&mut self, vertices: &[VertexId]) {
        let used = &self.used;
        let vertex_of = |i: u32| vertices[used.binary_search(&i).unwrap_or(0)];
        for e in &mut self.edges {
            e.chain = vec![(0.0, vertex_of(e.ends[0])), (1.0, vertex_of(e.ends[1]))];
        }
        for f in &mut self.facets {
            f.corners = f.input.map(vertex_of);
        }
    }

    /// The vertices along edge `k` of facet `f`, from corner `k` to corner `k + 1`, ends
    /// included.
    pub fn facet_edge(&self, f: usize, k: usize) -> impl Iterator<Item = VertexId> + '_ {
        let facet = &self.facets[f];
        let edge = &self.edges[facet.edges[k] as usize];
        let forward = edge.ends[0] == facet.input[k];
        let n = edge.chain.len();
        (0..n).map(move |j| edge.chain[if forward { j } else { n - 1 - j }].1)
    }
}

fn sorted(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

/// Whether three points are collinear, exactly: their projections on the three coordinate
/// planes all are.
fn is_degenerate([a, b, c]: [Point3; 3]) -> bool {
    let planes: [fn(Point3) -> Point2; 3] = [
        |p| Point2::new(p.x, p.y),
        |p| Point2::new(p.y, p.z),
        |p| Point2::new(p.z, p.x),
    ];
    planes
        .iter()
        .all(|proj| orient2d(proj(a), proj(b), proj(c)) == Sign::Zero)
}
