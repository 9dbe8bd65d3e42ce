//! The whole mesher over a polyhedral surface: the icosphere of CGAL's `sphere.off` (162
//! vertices, 320 triangles, radius 0.5), with the criteria of the side-by-side comparison
//! with CGAL Mesh_3 (facet angle 25°, facet size 0.05, facet distance 0.002, radius-edge 3,
//! cell size 0.05). Its planar faces make many nearly flat cells, the hard case for the
//! surface level. Run: `cargo bench -p delamesh-polyhedral --bench mesh`.

use criterion::{Criterion, criterion_group, criterion_main};
use delamesh_core::refine::criteria::{CellCriteria, FacetCriteria, MeshCriteria, Sizing};
use delamesh_core::refine::{Limits, MeshOptions, mesh_domain};
use delamesh_polyhedral::PolyhedralOracle;
use glam::DVec3;
use std::collections::BTreeMap;
use std::hint::black_box;

/// An icosahedron subdivided `levels` times (each triangle into four), projected on a sphere.
fn icosphere(radius: f64, levels: usize) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut points: Vec<DVec3> = [
        (-1.0, g, 0.0),
        (1.0, g, 0.0),
        (-1.0, -g, 0.0),
        (1.0, -g, 0.0),
        (0.0, -1.0, g),
        (0.0, 1.0, g),
        (0.0, -1.0, -g),
        (0.0, 1.0, -g),
        (g, 0.0, -1.0),
        (g, 0.0, 1.0),
        (-g, 0.0, -1.0),
        (-g, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize() * radius)
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut middle = BTreeMap::new();
        let mut mid = |a: u32, b: u32, points: &mut Vec<DVec3>| {
            *middle.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let p = (points[a as usize] + points[b as usize]).normalize() * radius;
                points.push(p);
                points.len() as u32 - 1
            })
        };
        triangles = triangles
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (
                    mid(a, b, &mut points),
                    mid(b, c, &mut points),
                    mid(c, a, &mut points),
                );
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    (points, triangles)
}

fn sphere_off(c: &mut Criterion) {
    let (points, triangles) = icosphere(0.5, 2);
    assert_eq!((points.len(), triangles.len()), (162, 320));
    let oracle = PolyhedralOracle::new(&points, &triangles, None).expect("a closed icosphere");
    let options = MeshOptions {
        criteria: MeshCriteria {
            facet: FacetCriteria {
                angle_deg: 25.0,
                size: Sizing::Constant(0.05),
                distance: Sizing::Constant(0.002),
            },
            cell: CellCriteria {
                radius_edge_ratio: 3.0,
                size: Sizing::Constant(0.05),
            },
            // No sharp features on a sphere: nothing to protect.
            edge_size: Sizing::Unbounded,
        },
        limits: Limits::default(),
        keep_partial: false,
    };
    let mut group = c.benchmark_group("mesh");
    group.sample_size(10);
    group.bench_function("icosphere 162 (CGAL sphere.off), CGAL criteria", |b| {
        b.iter(|| {
            mesh_domain(black_box(&oracle), &options, &mut |_| {}).map(|o| o.complex.tets.len())
        })
    });
    group.finish();
}

criterion_group!(benches, sphere_off);
criterion_main!(benches);
