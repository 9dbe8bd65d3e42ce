//! An oracle may find one surface point twice, a few ulps apart (two probes crossing the surface
//! at the same spot): the mesher must take it once. Two vertices that close make every cell
//! around them flat, and refining those cells packs more vertices into the gap.

use delamesh_core::complex::MeshComplex;
use delamesh_core::kernel::Point3;
use delamesh_core::oracle::{
    Aabb, CurveId, FeatureCurve, Oracle, SubdomainId, SurfaceHit, SurfacePoint, UnitBall,
    UnitBallWithEquator,
};
use delamesh_core::refine::criteria::MeshCriteria;
use delamesh_core::refine::{MeshOptions, mesh_domain};

/// `inner` with each initial point given twice, the copy moved by a few ulps.
struct Twice<O>(O);

impl<O: Oracle> Oracle for Twice<O> {
    fn bounding_box(&self) -> Aabb {
        self.0.bounding_box()
    }
    fn subdomain(&self, p: Point3) -> SubdomainId {
        self.0.subdomain(p)
    }
    fn segment_hits(&self, a: Point3, b: Point3, out: &mut Vec<SurfaceHit>) {
        self.0.segment_hits(a, b, out)
    }
    fn ray_hits(&self, origin: Point3, dir: Point3, out: &mut Vec<SurfaceHit>) {
        self.0.ray_hits(origin, dir, out)
    }
    fn initial_points(&self) -> Vec<SurfacePoint> {
        self.0
            .initial_points()
            .into_iter()
            .flat_map(|p| {
                let moved = p.point + p.point.abs().max(Point3::splat(1.0)) * 4.0 * f64::EPSILON;
                [p, SurfacePoint { point: moved, ..p }]
            })
            .collect()
    }
    fn feature_curves(&self) -> Vec<FeatureCurve> {
        self.0.feature_curves()
    }
    fn project_to_curve(&self, curve: CurveId, p: Point3) -> Point3 {
        self.0.project_to_curve(curve, p)
    }
    fn corners(&self) -> Vec<Point3> {
        self.0.corners()
    }
}

/// The shortest edge of any tet, over the bounding box's diagonal.
fn shortest_edge_ratio(m: &MeshComplex, diagonal: f64) -> f64 {
    (0..m.tets.len())
        .flat_map(|t| {
            let p = m.tet_points(t);
            (0..4).flat_map(move |i| (i + 1..4).map(move |j| p[i].distance(p[j])))
        })
        .fold(f64::INFINITY, f64::min)
        / diagonal
}

fn assert_meshes_as_once(oracle: &dyn Oracle, twice: &dyn Oracle) {
    let options = MeshOptions::new(MeshCriteria::uniform(0.2, 0.02));
    let diagonal = oracle.bounding_box().diagonal();
    let once = mesh_domain(oracle, &options, &mut |_| {}).expect("meshing succeeds");
    let doubled = mesh_domain(twice, &options, &mut |_| {}).expect("meshing succeeds");
    let ratio = shortest_edge_ratio(&doubled.complex, diagonal);
    assert!(ratio > 1e-3, "an edge of {ratio:e} diagonals: a cluster");
    assert_eq!(doubled.validity.flat_cells, 0);
    assert_eq!(doubled.complex.points, once.complex.points);
}

#[test]
fn smooth_domain_takes_a_point_found_twice_once() {
    assert_meshes_as_once(&UnitBall, &Twice(UnitBall));
}

#[test]
fn protected_domain_takes_a_point_found_twice_once() {
    assert_meshes_as_once(&UnitBallWithEquator, &Twice(UnitBallWithEquator));
}
