//! Piecewise-smooth meshing with protecting balls, on analytic domains whose sharp features are
//! known exactly: a cube, wedges with 20° and 5° edges, a cylinder with two circular rims.

use delamesh_core::complex::{MeshComplex, VertexDimension, signed_volume};
use delamesh_core::kernel::Point3;
use delamesh_core::oracle::{
    Aabb, CurveId, FeatureCurve, Oracle, PatchId, SubdomainId, SurfaceHit, SurfacePoint,
};
use delamesh_core::quality;
use delamesh_core::refine::criteria::MeshCriteria;
use delamesh_core::refine::curves::Polyline;
use delamesh_core::refine::{Limits, MeshOptions, mesh_domain};
use std::collections::{BTreeMap, BTreeSet};

/// A convex polyhedron: faces are convex polygons (vertex indices, counterclockwise seen from
/// outside); patch `i + 1` is face `i`, every polyhedron edge is a curve, every vertex a corner.
struct Polyhedron {
    vertices: Vec<Point3>,
    faces: Vec<Vec<usize>>,
    /// Outward unit normal and offset of each face plane: inside is `n·x ≤ d`.
    planes: Vec<(Point3, f64)>,
}

impl Polyhedron {
    fn new(vertices: Vec<Point3>, faces: Vec<Vec<usize>>) -> Self {
        let planes = faces
            .iter()
            .map(|f| {
                let (a, b, c) = (vertices[f[0]], vertices[f[1]], vertices[f[2]]);
                let n = (b - a).cross(c - a).normalize();
                (n, n.dot(a))
            })
            .collect();
        Polyhedron {
            vertices,
            faces,
            planes,
        }
    }

    fn cube() -> Self {
        let v = (0..8)
            .map(|i| Point3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64))
            .collect();
        let faces = vec![
            vec![0, 2, 3, 1],
            vec![4, 5, 7, 6],
            vec![0, 1, 5, 4],
            vec![2, 6, 7, 3],
            vec![0, 4, 6, 2],
            vec![1, 3, 7, 5],
        ];
        Polyhedron::new(v, faces)
    }

    /// A triangular prism whose edge along z has dihedral angle `degrees`.
    fn wedge(degrees: f64) -> Self {
        let t = degrees.to_radians();
        let tri = [(0.0, 0.0), (1.0, 0.0), (t.cos(), t.sin())];
        let v = [0.0, 0.5]
            .iter()
            .flat_map(|&z| tri.iter().map(move |&(x, y)| Point3::new(x, y, z)))
            .collect();
        let faces = vec![
            vec![0, 2, 1],
            vec![3, 4, 5],
            vec![0, 1, 4, 3],
            vec![1, 2, 5, 4],
            vec![2, 0, 3, 5],
        ];
        Polyhedron::new(v, faces)
    }

    fn edges(&self) -> Vec<[usize; 2]> {
        let mut edges = BTreeSet::new();
        for f in &self.faces {
            for k in 0..f.len() {
                let (a, b) = (f[k], f[(k + 1) % f.len()]);
                edges.insert([a.min(b), a.max(b)]);
            }
        }
        edges.into_iter().collect()
    }

    fn inside_except(&self, p: Point3, face: usize) -> bool {
        self.planes
            .iter()
            .enumerate()
            .all(|(j, &(n, d))| j == face || n.dot(p) <= d + 1e-12)
    }

    fn hits(&self, o: Point3, dir: Point3, t_max: f64, out: &mut Vec<SurfaceHit>) {
        let start = out.len();
        for (i, &(n, d)) in self.planes.iter().enumerate() {
            let denom = n.dot(dir);
            if denom == 0.0 {
                continue;
            }
            let t = (d - n.dot(o)) / denom;
            if !(0.0..=t_max).contains(&t) {
                continue;
            }
            let p = o + t * dir;
            if self.inside_except(p, i) {
                out.push(SurfaceHit {
                    point: p,
                    t,
                    patch: PatchId(i as u32 + 1),
                });
            }
        }
        out[start..].sort_by(|a, b| a.t.total_cmp(&b.t).then(a.patch.cmp(&b.patch)));
    }
}

/// The segment and ray queries of a test oracle, both answered by its own `hits` walk along
/// `o + t dir` for `t` up to a bound (a macro: they are methods of the `Oracle` impls).
macro_rules! hits_by_walk {
    () => {
        fn segment_hits(&self, a: Point3, b: Point3, out: &mut Vec<SurfaceHit>) {
            self.hits(a, b - a, 1.0, out);
        }
        fn ray_hits(&self, origin: Point3, dir: Point3, out: &mut Vec<SurfaceHit>) {
            self.hits(origin, dir, f64::INFINITY, out);
        }
    };
}

impl Oracle for Polyhedron {
    fn bounding_box(&self) -> Aabb {
        Aabb::of(&self.vertices).expect("vertices")
    }
    fn subdomain(&self, p: Point3) -> SubdomainId {
        SubdomainId(self.planes.iter().all(|&(n, d)| n.dot(p) < d) as u32)
    }
    hits_by_walk!();
    fn initial_points(&self) -> Vec<SurfacePoint> {
        let mut out = Vec::new();
        for (i, f) in self.faces.iter().enumerate() {
            let c = f.iter().map(|&v| self.vertices[v]).sum::<Point3>() / f.len() as f64;
            for &v in f {
                out.push(SurfacePoint {
                    point: c + 0.5 * (self.vertices[v] - c),
                    patch: PatchId(i as u32 + 1),
                });
            }
        }
        out
    }
    fn feature_curves(&self) -> Vec<FeatureCurve> {
        self.edges()
            .iter()
            .enumerate()
            .map(|(i, e)| FeatureCurve {
                id: CurveId(i as u32 + 1),
                points: vec![self.vertices[e[0]], self.vertices[e[1]]],
                closed: false,
            })
            .collect()
    }
    fn corners(&self) -> Vec<Point3> {
        self.vertices.clone()
    }
}

/// The cylinder x² + y² ≤ 1, 0 ≤ z ≤ 1: patch 1 the side, 2 the bottom, 3 the top; its rims are
/// closed curves given as fine polygons.
struct Cylinder;

const RIM_SEGMENTS: usize = 512;

impl Cylinder {
    fn rim(z: f64) -> Vec<Point3> {
        (0..RIM_SEGMENTS)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / RIM_SEGMENTS as f64;
                Point3::new(t.cos(), t.sin(), z)
            })
            .collect()
    }

    fn hits(&self, o: Point3, dir: Point3, t_max: f64, out: &mut Vec<SurfaceHit>) {
        let start = out.len();
        let (a, b, c) = (
            dir.x * dir.x + dir.y * dir.y,
            o.x * dir.x + o.y * dir.y,
            o.x * o.x + o.y * o.y - 1.0,
        );
        if a > 0.0 && b * b - a * c > 0.0 {
            let root = (b * b - a * c).sqrt();
            for t in [(-b - root) / a, (-b + root) / a] {
                let p = o + t * dir;
                if (0.0..=t_max).contains(&t) && (0.0..=1.0).contains(&p.z) {
                    out.push(SurfaceHit {
                        point: p,
                        t,
                        patch: PatchId(1),
                    });
                }
            }
        }
        for (z, patch) in [(0.0, PatchId(2)), (1.0, PatchId(3))] {
            if dir.z != 0.0 {
                let t = (z - o.z) / dir.z;
                let p = o + t * dir;
                if (0.0..=t_max).contains(&t) && p.x * p.x + p.y * p.y <= 1.0 {
                    out.push(SurfaceHit {
                        point: Point3::new(p.x, p.y, z),
                        t,
                        patch,
                    });
                }
            }
        }
        out[start..].sort_by(|a, b| a.t.total_cmp(&b.t).then(a.patch.cmp(&b.patch)));
    }
}

impl Oracle for Cylinder {
    fn bounding_box(&self) -> Aabb {
        Aabb::of(&[Point3::new(-1.0, -1.0, 0.0), Point3::new(1.0, 1.0, 1.0)]).expect("box")
    }
    fn subdomain(&self, p: Point3) -> SubdomainId {
        SubdomainId((p.x * p.x + p.y * p.y < 1.0 && p.z > 0.0 && p.z < 1.0) as u32)
    }
    hits_by_walk!();
    fn initial_points(&self) -> Vec<SurfacePoint> {
        let mut out = Vec::new();
        for k in 0..6 {
            let t = std::f64::consts::TAU * k as f64 / 6.0;
            let (x, y) = (t.cos(), t.sin());
            out.push(SurfacePoint {
                point: Point3::new(x, y, 0.5),
                patch: PatchId(1),
            });
            out.push(SurfacePoint {
                point: Point3::new(0.5 * x, 0.5 * y, 0.0),
                patch: PatchId(2),
            });
            out.push(SurfacePoint {
                point: Point3::new(0.5 * x, 0.5 * y, 1.0),
                patch: PatchId(3),
            });
        }
        out
    }
    fn feature_curves(&self) -> Vec<FeatureCurve> {
        [0.0, 1.0]
            .iter()
            .enumerate()
            .map(|(i, &z)| FeatureCurve {
                id: CurveId(i as u32 + 1),
                points: Cylinder::rim(z),
                closed: true,
            })
            .collect()
    }
}

fn options(size: f64) -> MeshOptions {
    MeshOptions {
        limits: Limits {
            max_vertices: 30_000,
            ..Limits::default()
        },
        ..MeshOptions::new(MeshCriteria::uniform(size, size / 10.0))
    }
}

fn mesh(oracle: &dyn Oracle, size: f64) -> MeshComplex {
    mesh_domain(oracle, &options(size), &mut |_| {})
        .expect("meshing succeeds")
        .complex
}

fn assert_positive_tets(m: &MeshComplex) {
    assert!(!m.tets.is_empty());
    for t in 0..m.tets.len() {
        assert!(
            signed_volume(&m.tet_points(t)) > 0.0,
            "tet {t} is not positive"
        );
    }
}

fn volume(m: &MeshComplex) -> f64 {
    (0..m.tets.len())
        .map(|t| quality::tet_volume(&m.tet_points(t)))
        .sum()
}

/// Every corner is a vertex of dimension 0 at exactly its input position.
fn assert_exact_corners(m: &MeshComplex, corners: &[Point3]) {
    for &c in corners {
        let (_, v) = m
            .corners
            .iter()
            .find(|(p, _)| *p == c)
            .expect("corner protected");
        let v = v.expect("corner vertex in the mesh") as usize;
        assert_eq!(m.points[v], c);
        assert_eq!(m.vertex_dimension[v], VertexDimension::Corner);
    }
}

/// The feature edges of each straight curve `[a, b]` form one path from `a` to `b` along it.
fn assert_straight_curves(m: &MeshComplex, curves: &[FeatureCurve]) {
    for c in curves {
        let (a, b) = (c.points[0], c.points[1]);
        let edges: Vec<[u32; 2]> = m
            .feature_edges
            .iter()
            .zip(&m.feature_edge_curve)
            .filter(|(_, id)| **id == c.id)
            .map(|(e, _)| *e)
            .collect();
        assert!(!edges.is_empty(), "curve {} has no feature edge", c.id);
        let mut degree: BTreeMap<u32, usize> = BTreeMap::new();
        let mut length = 0.0;
        for e in &edges {
            let [p, q] = e.map(|v| m.points[v as usize]);
            for x in [p, q] {
                let off = (x - a).cross(b - a).length() / (b - a).length();
                assert!(off < 1e-12, "feature vertex {x} off curve {}", c.id);
            }
            length += p.distance(q);
            for v in e {
                *degree.entry(*v).or_default() += 1;
            }
        }
        let ends: Vec<Point3> = degree
            .iter()
            .filter(|(_, d)| **d == 1)
            .map(|(v, _)| m.points[*v as usize])
            .collect();
        assert!(degree.values().all(|&d| d <= 2));
        assert_eq!(ends.len(), 2, "curve {} is not one path", c.id);
        assert!(ends.contains(&a) && ends.contains(&b));
        assert!((length - a.distance(b)).abs() < 1e-9 * a.distance(b));
    }
}

#[test]
fn cube_keeps_its_corners_edges_and_faces() {
    let cube = Polyhedron::cube();
    let m = mesh(&cube, 0.3);
    assert_positive_tets(&m);
    assert!((volume(&m) - 1.0).abs() < 1e-9, "volume {}", volume(&m));
    assert_exact_corners(&m, &cube.vertices);
    assert_straight_curves(&m, &cube.feature_curves());
    let topology = quality::surface_topology(&m.facets);
    assert!(topology.is_closed_manifold());
    // No boundary facet crosses an edge: its three vertices lie on one face plane; each face's
    // facets form a disk.
    let mut by_face: BTreeMap<usize, Vec<[u32; 3]>> = BTreeMap::new();
    for (f, t) in m.facets.iter().enumerate() {
        let p = m.facet_points(f);
        let face = cube
            .planes
            .iter()
            .position(|&(n, d)| p.iter().all(|&x| (n.dot(x) - d).abs() < 1e-12))
            .unwrap_or_else(|| panic!("facet {f} {p:?} crosses a cube edge"));
        assert_eq!(m.facet_patch[f], PatchId(face as u32 + 1));
        by_face.entry(face).or_default().push(*t);
    }
    assert_eq!(by_face.len(), 6);
    for facets in by_face.values() {
        let t = quality::surface_topology(facets);
        assert_eq!(t.components, 1);
        assert_eq!(t.euler_characteristic, 1, "a face is not a disk");
        assert_eq!(t.non_manifold_edges, 0);
    }
}

#[test]
fn meshing_with_features_is_deterministic() {
    let cube = Polyhedron::cube();
    assert_eq!(mesh(&cube, 0.4), mesh(&cube, 0.4));
}

#[test]
fn sharp_wedges_terminate_with_their_curves_and_corners() {
    for degrees in [20.0, 5.0] {
        let wedge = Polyhedron::wedge(degrees);
        // Refinement alone keeps planar faces exactly; the optimisers move surface vertices
        // within the facet distance (checked below).
        let mut plain = options(0.2);
        plain.optimize = delamesh_core::optimize::OptimizeOptions::none();
        let m = mesh_domain(&wedge, &plain, &mut |_| {})
            .expect("meshing succeeds")
            .complex;
        let optimised = mesh(&wedge, 0.2);
        assert_positive_tets(&optimised);
        let area: f64 = (0..optimised.facets.len())
            .map(|f| {
                let [a, b, c] = optimised.facet_points(f);
                (b - a).cross(c - a).length() / 2.0
            })
            .sum();
        assert!((volume(&optimised) - volume(&m)).abs() <= area * 0.02);
        assert_positive_tets(&m);
        assert_exact_corners(&m, &wedge.vertices);
        assert_straight_curves(&m, &wedge.feature_curves());
        let exact = 0.5 * 0.5 * degrees.to_radians().sin();
        assert!(
            (volume(&m) - exact).abs() < 1e-9 * exact.max(1.0),
            "{degrees}°: volume {} instead of {exact}",
            volume(&m)
        );
    }
}

#[test]
fn cylinder_rims_are_closed_chains_on_the_circles() {
    let m = mesh(&Cylinder, 0.25);
    assert_positive_tets(&m);
    for id in [1, 2] {
        let z = (id - 1) as f64;
        let mut degree: BTreeMap<u32, usize> = BTreeMap::new();
        let mut length = 0.0;
        for (e, _) in m
            .feature_edges
            .iter()
            .zip(&m.feature_edge_curve)
            .filter(|(_, c)| c.0 == id)
        {
            let [p, q] = e.map(|v| m.points[v as usize]);
            for x in [p, q] {
                assert_eq!(x.z, z);
                assert!((x.truncate().length() - 1.0).abs() < 1e-4);
            }
            length += p.distance(q);
            for v in e {
                *degree.entry(*v).or_default() += 1;
            }
        }
        assert!(
            degree.len() >= 3 && degree.values().all(|&d| d == 2),
            "rim {id} is not a cycle"
        );
        assert!((length - std::f64::consts::TAU).abs() < 0.02 * std::f64::consts::TAU);
    }
    assert!(
        m.vertex_dimension
            .iter()
            .all(|&d| d != VertexDimension::Corner)
    );
}

#[test]
fn optimisation_keeps_corners_and_curve_vertices_on_their_curves_and_lifts_the_smallest_angle() {
    for (oracle, size) in [(&Polyhedron::cube() as &dyn Oracle, 0.3), (&Cylinder, 0.25)] {
        let mut plain = options(size);
        plain.optimize = delamesh_core::optimize::OptimizeOptions::none();
        let refined = mesh_domain(oracle, &plain, &mut |_| {}).expect("meshing succeeds");
        let optimised = mesh_domain(oracle, &options(size), &mut |_| {}).expect("meshing succeeds");
        let (r, o) = (&refined.complex, &optimised.complex);
        assert_positive_tets(o);
        assert_eq!(r.vertex_dimension, o.vertex_dimension);
        for (v, d) in o.vertex_dimension.iter().enumerate() {
            if *d == VertexDimension::Corner {
                assert_eq!(r.points[v], o.points[v], "corner {v} moved");
            }
        }
        // Curve vertices may slide along their curve, never off it.
        let curves = oracle.feature_curves();
        for (e, id) in o.feature_edges.iter().zip(&o.feature_edge_curve) {
            let c = curves
                .iter()
                .find(|c| c.id == *id)
                .expect("a curve of the domain");
            let line = Polyline::new(&c.points, c.closed).expect("a polyline");
            for &v in e {
                let d = line.project(o.points[v as usize]).distance;
                assert!(d <= 1e-9, "curve vertex {v} at {d} from curve {id}");
            }
        }
        assert_eq!(r.feature_edges, o.feature_edges);
        assert_eq!(r.corners, o.corners);
        let report = &optimised.optimization;
        assert!(report.skipped.is_none());
        assert!(report.after().min_dihedral_deg >= report.before.min_dihedral_deg);
        assert!(quality::surface_topology(&o.facets).is_closed_manifold());
    }
}
