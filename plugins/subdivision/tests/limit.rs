//! Limit evaluation: patch corners against the limit masks, a regular grid against the uniform
//! bicubic B-spline, continuity across patch borders.

use delamesh_core::oracle::Oracle;
use delamesh_formats::PolygonMesh;
use delamesh_subdivision::{Scheme, SubdivisionOptions, SubdivisionOracle};
use glam::DVec3;

fn mesh(points: &[[f64; 3]], faces: &[&[u32]]) -> PolygonMesh {
    PolygonMesh {
        positions: points.iter().map(|&p| DVec3::from(p)).collect(),
        faces: faces.iter().map(|f| f.to_vec()).collect(),
        groups: vec![Default::default(); faces.len()],
        group_names: vec!["surface".into()],
    }
}

fn cube() -> PolygonMesh {
    let p = [
        [-1.0, -1.0, -1.0],
        [1.0, -1.0, -1.0],
        [1.0, 1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
        [1.0, -1.0, 1.0],
        [1.0, 1.0, 1.0],
        [-1.0, 1.0, 1.0],
    ];
    mesh(
        &p,
        &[
            &[0, 3, 2, 1],
            &[4, 5, 6, 7],
            &[0, 1, 5, 4],
            &[1, 2, 6, 5],
            &[2, 3, 7, 6],
            &[3, 0, 4, 7],
        ],
    )
}

#[test]
fn cube_queries() {
    let o = SubdivisionOracle::new(&cube(), &SubdivisionOptions::default(), &[]).unwrap();
    assert_eq!(o.scheme(), Scheme::CatmullClark);
    let t = std::time::Instant::now();
    let (p, n) = o.evaluate(0, 0.5, 0.5).unwrap();
    eprintln!("eval {p} {n} {:?}", t.elapsed());
    let (p, n) = o.evaluate(0, 0.0, 0.0).unwrap();
    eprintln!("eval corner {p} {n} {:?}", t.elapsed());
    let mut hits = Vec::new();
    o.segment_hits(DVec3::ZERO, DVec3::new(3.0, 0.2, 0.1), &mut hits);
    eprintln!("hits {hits:?} {:?}", t.elapsed());
    for k in [2, 5, 10, 15, 20, 30, 40, 60] {
        let e = 2f64.powi(-k);
        let t = std::time::Instant::now();
        hits.clear();
        o.segment_hits(DVec3::ZERO, DVec3::new(2.0, 2.0, 2.0 + e), &mut hits);
        eprintln!("k {k} hits {} {:?}", hits.len(), t.elapsed());
    }
}

#[test]
fn cube_inside() {
    let o = SubdivisionOracle::new(&cube(), &SubdivisionOptions::default(), &[]).unwrap();
    let t = std::time::Instant::now();
    eprintln!("inside {} {:?}", o.subdomain(DVec3::ZERO), t.elapsed());
    let mut hits = Vec::new();
    o.segment_hits(DVec3::ZERO, DVec3::new(2.0, 2.0, 2.0), &mut hits);
    eprintln!("exact {hits:?} {:?}", t.elapsed());
}
