//! Quality measures of tetrahedral meshes and of their boundaries: dihedral angles, radius-edge
//! ratio, volumes, histograms, sampled Hausdorff distance, surface topology, and how well sharp
//! features are kept.

use crate::kernel::Point3;
use crate::oracle::{CurveId, FeatureCurve};
use crate::refine::curves::{Polyline, point_segment_distance};
use crate::union_find::UnionFind;
use rayon::prelude::*;
use std::collections::BTreeMap;

/// The six dihedral angles of a tetrahedron, in degrees (edge order 01, 02, 03, 12, 13, 23).
pub fn dihedral_angles_deg(p: &[Point3; 4]) -> [f64; 6] {
    // The dihedral angle at edge (i, j) is π minus the angle between the outward normals of the
    // two faces containing the edge, which are the faces opposite k and l.
    const EDGES: [(usize, usize, usize, usize); 6] = [
        (0, 1, 2, 3),
        (0, 2, 1, 3),
        (0, 3, 1, 2),
        (1, 2, 0, 3),
        (1, 3, 0, 2),
        (2, 3, 0, 1),
    ];
    let normal_opposite = |k: usize| {
        let f: Vec<Point3> = (0..4).filter(|&m| m != k).map(|m| p[m]).collect();
        let mut n = (f[1] - f[0]).cross(f[2] - f[0]);
        if n.dot(p[k] - f[0]) > 0.0 {
            n = -n;
        }
        n
    };
    EDGES.map(|(_, _, k, l)| {
        let (nk, nl) = (normal_opposite(k), normal_opposite(l));
        180.0 - nk.angle_between(nl).to_degrees()
    })
}

/// Circumcentre of a tetrahedron (`None` when it is flat).
pub fn tet_circumcenter(p: &[Point3; 4]) -> Option<Point3> {
    let (a, b, c) = (p[1] - p[0], p[2] - p[0], p[3] - p[0]);
    let det = 2.0 * a.dot(b.cross(c));
    if det == 0.0 {
        return None;
    }
    let num = a.length_squared() * b.cross(c)
        + b.length_squared() * c.cross(a)
        + c.length_squared() * a.cross(b);
    Some(p[0] + num / det)
}

/// Circumradius over shortest edge (√6/4 ≈ 0.612 for the regular tetrahedron; ∞ when flat).
pub fn radius_edge_ratio(p: &[Point3; 4]) -> f64 {
    let Some(c) = tet_circumcenter(p) else {
        return f64::INFINITY;
    };
    let mut shortest = f64::INFINITY;
    for i in 0..4 {
        for j in i + 1..4 {
            shortest = shortest.min(p[i].distance(p[j]));
        }
    }
    c.distance(p[0]) / shortest
}

/// Signed volume (positive for positively oriented tetrahedra).
pub fn tet_volume(p: &[Point3; 4]) -> f64 {
    (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0
}

/// Volume enclosed by a closed, outward-oriented triangle surface (divergence theorem).
pub fn enclosed_volume(points: &[Point3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| points[v as usize]);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// Counts of values in equal-width bins over `[lo, hi]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    /// Lower end of the first bin.
    pub lo: f64,
    /// Upper end of the last bin.
    pub hi: f64,
    /// Values per bin; a value outside `[lo, hi]` counts in the nearest end bin.
    pub counts: Vec<u64>,
}

impl Histogram {
    /// An empty histogram of `bins` bins over `[lo, hi]`.
    pub fn new(lo: f64, hi: f64, bins: usize) -> Self {
        Histogram {
            lo,
            hi,
            counts: vec![0; bins.max(1)],
        }
    }

    /// Values outside the range go to the first or last bin.
    pub fn add(&mut self, x: f64) {
        let n = self.counts.len();
        let t = ((x - self.lo) / (self.hi - self.lo) * n as f64).floor();
        let i = if t.is_nan() {
            0
        } else {
            (t.max(0.0) as usize).min(n - 1)
        };
        self.counts[i] += 1;
    }
}

/// Quality figures of a set of tetrahedra.
#[derive(Clone, Debug, PartialEq)]
pub struct TetQuality {
    /// Smallest dihedral angle of all tetrahedra, in degrees.
    pub min_dihedral_deg: f64,
    /// Largest dihedral angle of all tetrahedra, in degrees.
    pub max_dihedral_deg: f64,
    /// Largest circumradius-to-shortest-edge ratio.
    pub max_radius_edge: f64,
    /// Mean circumradius-to-shortest-edge ratio.
    pub mean_radius_edge: f64,
    /// Smallest dihedral angle of each tetrahedron, 18 bins of 10°.
    pub min_dihedral_histogram: Histogram,
    /// Sum of the signed volumes.
    pub volume: f64,
    /// Tetrahedra with non-positive volume.
    pub inverted: usize,
}

/// The quality figures of `tets` (each given by its four corners).
pub fn tet_quality(tets: impl IntoIterator<Item = [Point3; 4]>) -> TetQuality {
    let mut q = TetQuality {
        min_dihedral_deg: 180.0,
        max_dihedral_deg: 0.0,
        max_radius_edge: 0.0,
        mean_radius_edge: 0.0,
        min_dihedral_histogram: Histogram::new(0.0, 180.0, 18),
        volume: 0.0,
        inverted: 0,
    };
    let mut n = 0usize;
    for p in tets {
        let angles = dihedral_angles_deg(&p);
        let lo = angles.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = angles.iter().copied().fold(0.0, f64::max);
        q.min_dihedral_deg = q.min_dihedral_deg.min(lo);
        q.max_dihedral_deg = q.max_dihedral_deg.max(hi);
        q.min_dihedral_histogram.add(lo);
        let re = radius_edge_ratio(&p);
        q.max_radius_edge = q.max_radius_edge.max(re);
        q.mean_radius_edge += re;
        let v = tet_volume(&p);
        q.volume += v;
        if v <= 0.0 {
            q.inverted += 1;
        }
        n += 1;
    }
    if n > 0 {
        q.mean_radius_edge /= n as f64;
    }
    q
}

/// Topology of a triangle surface.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SurfaceTopology {
    /// Vertices used by a triangle.
    pub vertices: usize,
    /// Distinct edges.
    pub edges: usize,
    /// Triangles.
    pub faces: usize,
    /// Edges with one incident triangle.
    pub border_edges: usize,
    /// Edges with more than two incident triangles.
    pub non_manifold_edges: usize,
    /// Vertices whose incident triangles do not form a single fan.
    pub non_manifold_vertices: usize,
    /// Connected components (through shared edges).
    pub components: usize,
    /// `vertices - edges + faces`.
    pub euler_characteristic: i64,
}

impl SurfaceTopology {
    /// A closed 2-manifold: every edge in exactly two triangles, every vertex link one cycle.
    pub fn is_closed_manifold(&self) -> bool {
        self.border_edges == 0 && self.non_manifold_edges == 0 && self.non_manifold_vertices == 0
    }
}

/// Topology of the surface made of `triangles` (only the vertices they use count).
pub fn surface_topology(triangles: &[[u32; 3]]) -> SurfaceTopology {
    let mut edges: BTreeMap<(u32, u32), Vec<usize>> = BTreeMap::new();
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let mut vertices: Vec<u32> = triangles.iter().flatten().copied().collect();
    vertices.sort_unstable();
    vertices.dedup();
    let slot = |v: u32| vertices.binary_search(&v).unwrap_or(0);

    let mut faces_uf = UnionFind::new(triangles.len());
    for fs in edges.values() {
        for w in fs.windows(2) {
            faces_uf.union(w[0] as u32, w[1] as u32);
        }
    }
    let components = (0..triangles.len() as u32)
        .filter(|&f| faces_uf.find(f) == f)
        .count();

    // A vertex is manifold when its incident triangles are connected through edges at the vertex
    // (a single fan), counted with a union-find over the triangles of each vertex.
    let mut incident: Vec<Vec<usize>> = vec![Vec::new(); vertices.len()];
    for (f, t) in triangles.iter().enumerate() {
        for &v in t {
            incident[slot(v)].push(f);
        }
    }
    let mut non_manifold_vertices = 0;
    let mut local = UnionFind::new(0);
    for (s, fs) in incident.iter().enumerate() {
        let v = vertices[s];
        local.reset(fs.len());
        for (x, &f) in fs.iter().enumerate() {
            for (y, &g) in fs.iter().enumerate().skip(x + 1) {
                let shares_edge_at_v = triangles[f]
                    .iter()
                    .filter(|&&w| w != v && triangles[g].contains(&w))
                    .count()
                    > 0;
                if shares_edge_at_v {
                    local.union(x as u32, y as u32);
                }
            }
        }
        if (0..fs.len() as u32).filter(|&x| local.find(x) == x).count() > 1 {
            non_manifold_vertices += 1;
        }
    }

    SurfaceTopology {
        vertices: vertices.len(),
        edges: edges.len(),
        faces: triangles.len(),
        border_edges: edges.values().filter(|f| f.len() == 1).count(),
        non_manifold_edges: edges.values().filter(|f| f.len() > 2).count(),
        non_manifold_vertices,
        components,
        euler_characteristic: vertices.len() as i64 - edges.len() as i64 + triangles.len() as i64,
    }
}

/// Points spread over triangles about `spacing` apart (at least the centroid of each), for
/// sampled distance measurements. Deterministic. Rows run parallel to each triangle's longest
/// edge, as many as its height needs, so a long thin triangle (a fan cap's spoke) gets samples in
/// proportion to its area rather than to its length squared.
pub fn sample_triangles(
    triangles: impl IntoIterator<Item = [Point3; 3]>,
    spacing: f64,
) -> Vec<Point3> {
    /// Most samples along one direction of a triangle.
    const MAX_STEPS: usize = 64;
    let steps = |length: f64| ((length / spacing).ceil() as usize).clamp(1, MAX_STEPS);
    let mut out = Vec::new();
    for t in triangles {
        // The longest edge p → q, the apex r.
        let k = (0..3)
            .max_by(|&i, &j| {
                let l = |i: usize| t[i].distance_squared(t[(i + 1) % 3]);
                l(i).total_cmp(&l(j))
            })
            .unwrap_or(0);
        let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        let base = p.distance(q);
        let height = (q - p).cross(r - p).length() / base.max(f64::MIN_POSITIVE);
        let rows = steps(height);
        for i in 0..rows {
            // Row i at height fraction h; its cross-section is (1 - h) of the base.
            let h = (i as f64 + 1.0 / 3.0) / rows as f64;
            let (from, to) = (p.lerp(r, h), q.lerp(r, h));
            let columns = steps((1.0 - h) * base);
            for j in 0..columns {
                out.push(from.lerp(to, (j as f64 + 0.5) / columns as f64));
            }
        }
    }
    out
}

/// The largest distance from `samples` to a set measured by `distance_to_set`: one side of a
/// Hausdorff distance. The samples are measured on all cores; the maximum does not depend on
/// the order.
pub fn one_sided_distance(
    samples: &[Point3],
    distance_to_set: impl Fn(Point3) -> f64 + Sync,
) -> f64 {
    samples
        .par_iter()
        .map(|&p| distance_to_set(p))
        .reduce(|| 0.0, f64::max)
}

/// How one input feature curve is followed by the mesh's feature edges.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveFidelity {
    /// The input curve.
    pub curve: CurveId,
    /// Feature edges of the mesh on this curve.
    pub edges: usize,
    /// Sampled Hausdorff distance between the input polyline and the feature edges; `None` when
    /// the curve has no feature edge (it was lost).
    pub hausdorff: Option<f64>,
}

/// How the sharp features of the input survive in a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct FeatureFidelity {
    /// One entry per input curve.
    pub curves: Vec<CurveFidelity>,
    /// Input corners.
    pub corners: usize,
    /// Corners without a mesh vertex.
    pub missing_corners: usize,
    /// Largest distance between an input corner and its mesh vertex (0 when corners are kept
    /// exactly).
    pub max_corner_displacement: f64,
}

/// Measure `curves` against the feature edges `edges` (vertex pairs into `points`, curve
/// `edge_curve[i]` for edge `i`) and corners `(input position, mesh vertex)`. Distances are
/// sampled about `spacing` apart along both sides (plus every polyline vertex).
pub fn feature_fidelity(
    curves: &[FeatureCurve],
    points: &[Point3],
    edges: &[[u32; 2]],
    edge_curve: &[CurveId],
    corners: &[(Point3, Option<u32>)],
    spacing: f64,
) -> FeatureFidelity {
    let segment_samples = |a: Point3, b: Point3, out: &mut Vec<Point3>| {
        let n = ((a.distance(b) / spacing).ceil() as usize).clamp(1, 1024);
        out.extend((0..=n).map(|k| a + (k as f64 / n as f64) * (b - a)));
    };
    let curves = curves
        .iter()
        .map(|c| {
            let segments: Vec<(Point3, Point3)> = edges
                .iter()
                .zip(edge_curve)
                .filter(|(_, id)| **id == c.id)
                .map(|(e, _)| (points[e[0] as usize], points[e[1] as usize]))
                .collect();
            let line = Polyline::new(&c.points, c.closed);
            let hausdorff = match (&line, segments.is_empty()) {
                (Some(line), false) => {
                    let mut on_input = Vec::new();
                    let pts = line.points();
                    let count = if c.closed { pts.len() } else { pts.len() - 1 };
                    for i in 0..count {
                        segment_samples(pts[i], pts[(i + 1) % pts.len()], &mut on_input);
                    }
                    let mut on_mesh = Vec::new();
                    for &(a, b) in &segments {
                        segment_samples(a, b, &mut on_mesh);
                    }
                    let to_mesh = one_sided_distance(&on_input, |p| {
                        segments
                            .iter()
                            .map(|&(a, b)| point_segment_distance(p, a, b))
                            .fold(f64::INFINITY, f64::min)
                    });
                    let to_input = one_sided_distance(&on_mesh, |p| line.project(p).distance);
                    Some(to_mesh.max(to_input))
                }
                _ => None,
            };
            CurveFidelity {
                curve: c.id,
                edges: segments.len(),
                hausdorff,
            }
        })
        .collect();
    FeatureFidelity {
        curves,
        corners: corners.len(),
        missing_corners: corners.iter().filter(|(_, v)| v.is_none()).count(),
        max_corner_displacement: corners
            .iter()
            .filter_map(|&(p, v)| v.map(|v| p.distance(points[v as usize])))
            .fold(0.0, f64::max),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feature_fidelity_measures_chords_and_lost_curves() {
        let curves = [
            FeatureCurve {
                id: CurveId(1),
                points: vec![
                    Point3::ZERO,
                    Point3::new(1.0, 1.0, 0.0),
                    Point3::new(2.0, 0.0, 0.0),
                ],
                closed: false,
            },
            FeatureCurve {
                id: CurveId(2),
                points: vec![Point3::ZERO, Point3::Z],
                closed: false,
            },
        ];
        let points = [Point3::ZERO, Point3::new(2.0, 0.0, 0.0)];
        let f = feature_fidelity(
            &curves,
            &points,
            &[[0, 1]],
            &[CurveId(1)],
            &[(Point3::ZERO, Some(0))],
            0.01,
        );
        // The chord misses the polyline's apex by 1.
        assert!((f.curves[0].hausdorff.expect("kept") - 1.0).abs() < 1e-12);
        assert_eq!(f.curves[1].hausdorff, None);
        assert_eq!(f.max_corner_displacement, 0.0);
        assert_eq!(f.missing_corners, 0);
    }

    fn regular() -> [Point3; 4] {
        [
            Point3::new(1.0, 1.0, 1.0),
            Point3::new(1.0, -1.0, -1.0),
            Point3::new(-1.0, 1.0, -1.0),
            Point3::new(-1.0, -1.0, 1.0),
        ]
    }

    #[test]
    fn regular_tet_measures() {
        let p = regular();
        for a in dihedral_angles_deg(&p) {
            assert!((a - (1.0f64 / 3.0).acos().to_degrees()).abs() < 1e-9);
        }
        assert!((radius_edge_ratio(&p) - 6f64.sqrt() / 4.0).abs() < 1e-12);
        let v = tet_volume(&p).abs();
        assert!((v - 8.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn corner_tet_has_right_dihedrals() {
        let p = [Point3::ZERO, Point3::X, Point3::Y, Point3::Z];
        let a = dihedral_angles_deg(&p);
        // Edges along the axes have right dihedral angles.
        assert!(
            (a[0] - 90.0).abs() < 1e-9 && (a[1] - 90.0).abs() < 1e-9 && (a[2] - 90.0).abs() < 1e-9
        );
        assert!(tet_volume(&p) > 0.0);
    }

    #[test]
    fn tetrahedron_surface_topology() {
        let tris = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        let t = surface_topology(&tris);
        assert!(t.is_closed_manifold());
        assert_eq!(t.euler_characteristic, 2);
        assert_eq!(t.components, 1);
        let open = surface_topology(&tris[..3]);
        assert_eq!(open.border_edges, 3);
        // Two tetrahedra sharing only a vertex: a non-manifold vertex.
        let mut two: Vec<[u32; 3]> = tris.to_vec();
        two.extend(
            tris.iter()
                .map(|t| t.map(|v| if v == 0 { 0 } else { v + 3 })),
        );
        let t2 = surface_topology(&two);
        assert_eq!(t2.non_manifold_vertices, 1);
        assert_eq!(t2.non_manifold_edges, 0);
        let p = [Point3::ZERO, Point3::X, Point3::Y, Point3::Z];
        let tris_oriented = [[0u32, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        assert!((enclosed_volume(&p, &tris_oriented) - 1.0 / 6.0).abs() < 1e-12);
    }

    #[test]
    fn histogram_clamps() {
        let mut h = Histogram::new(0.0, 10.0, 5);
        for x in [-1.0, 0.0, 1.9, 2.0, 9.99, 10.0, 50.0] {
            h.add(x);
        }
        assert_eq!(h.counts, [3, 1, 0, 0, 3]);
    }

    #[test]
    fn samples_lie_on_the_triangle() {
        let t = [Point3::ZERO, Point3::X, Point3::Y];
        let s = sample_triangles([t], 0.1);
        assert!(s.len() > 10);
        assert!(
            s.iter()
                .all(|p| p.z == 0.0 && p.x >= 0.0 && p.y >= 0.0 && p.x + p.y <= 1.0)
        );
        // Every point of the triangle is near a sample.
        for i in 0..=20 {
            for j in 0..=20 - i {
                let q = Point3::new(i as f64 / 20.0, j as f64 / 20.0, 0.0);
                let d = s
                    .iter()
                    .map(|p| p.distance(q))
                    .fold(f64::INFINITY, f64::min);
                assert!(d < 0.1, "{q} is {d} from the samples");
            }
        }
    }

    /// A spoke of a fan (length 1, width 0.003) gets samples in proportion to its area.
    #[test]
    fn a_thin_triangle_gets_few_samples() {
        let t = [Point3::ZERO, Point3::X, Point3::new(1.0, 0.003, 0.0)];
        let s = sample_triangles([t], 0.01);
        assert!(s.len() <= 100, "{} samples", s.len());
        let q = Point3::new(0.5, 0.001, 0.0);
        assert!(s.iter().any(|p| p.distance(q) < 0.01));
    }
}
