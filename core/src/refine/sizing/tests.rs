use super::*;
use crate::oracle::Aabb;
use crate::refine::criteria::Sizing;
use glam::{DAffine3, DMat3};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

fn linear(p: Point3) -> f64 {
    1.0 + 0.3 * p.x - 0.2 * p.y + 0.1 * p.z
}

fn random_points(n: usize, lo: f64, hi: f64, seed: u64) -> Vec<Point3> {
    let mut rng = StdRng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            Point3::new(
                rng.random_range(lo..hi),
                rng.random_range(lo..hi),
                rng.random_range(lo..hi),
            )
        })
        .collect()
}

/// Six tets filling the unit cube (Kuhn's subdivision along the main diagonal): one per order
/// of the axes, walking from corner 0 to corner 7 along the first axis, then the second.
fn cube_tets() -> (Vec<Point3>, Vec<[u32; 4]>) {
    let corner = |i: u32| Point3::new(f64::from(i & 1), f64::from((i >> 1) & 1), f64::from(i >> 2));
    let positions = (0..8).map(corner).collect();
    let axes = [1, 2, 4];
    let tets = axes
        .iter()
        .flat_map(|&a| {
            axes.iter()
                .filter(move |&&b| b != a)
                .map(move |&b| [0, a, a | b, 7])
        })
        .collect();
    (positions, tets)
}

#[test]
fn grid_reproduces_linear_fields_and_clamps_outside() {
    let dims = [4, 5, 3];
    let spacing = Point3::new(0.5, 0.25, 1.0);
    let origin = Point3::new(-1.0, 0.0, 2.0);
    let map = DAffine3::from_mat3_translation(DMat3::from_diagonal(spacing), origin);
    let mut values = Vec::new();
    for k in 0..3 {
        for j in 0..5 {
            for i in 0..4 {
                values.push(linear(
                    map.transform_point3(Point3::new(i as f64, j as f64, k as f64)),
                ));
            }
        }
    }
    let grid = SizeGrid::new(dims, map, values).expect("valid grid");
    let hi = map.transform_point3(Point3::new(3.0, 4.0, 2.0));
    for p in random_points(200, 0.0, 1.0, 1) {
        let q = origin + p * (hi - origin);
        assert!((grid.at(q) - linear(q)).abs() < 1e-12);
    }
    // Beyond the last node along x: the border's value.
    let out = Point3::new(hi.x + 5.0, 0.5, 2.5);
    assert!((grid.at(out) - linear(Point3::new(hi.x, 0.5, 2.5))).abs() < 1e-12);
}

#[test]
fn grid_refuses_bad_values_naming_the_node() {
    let map = DAffine3::IDENTITY;
    let mut values = vec![1.0; 8];
    values[5] = -2.0;
    let e = SizeGrid::new([2, 2, 2], map, values).expect_err("refused");
    assert!(e.0.contains("node (1, 0, 1)") && e.0.contains("-2"), "{e}");
    assert!(SizeGrid::new([2, 2, 2], map, vec![f64::NAN; 8]).is_err());
    assert!(SizeGrid::new([2, 2, 3], map, vec![1.0; 8]).is_err());
    assert!(SizeGrid::new([2, 2, 2], DAffine3::ZERO, vec![1.0; 8]).is_err());
}

#[test]
fn background_mesh_interpolates_linearly_and_takes_the_nearest_node_outside() {
    let (positions, tets) = cube_tets();
    let values = positions.iter().map(|&p| linear(p)).collect();
    let bg = BackgroundMesh::new(positions.clone(), tets, values).expect("valid mesh");
    for p in random_points(300, 0.0, 1.0, 2) {
        assert!(bg.covers(p));
        assert!((bg.at(p) - linear(p)).abs() < 1e-12, "at {p}");
    }
    let out = Point3::new(1.4, 1.3, -0.2);
    assert!(!bg.covers(out));
    assert!(bg.near(out, 0.55) && !bg.near(out, 0.5));
    assert_eq!(bg.at(out), linear(Point3::new(1.0, 1.0, 0.0)));
}

#[test]
fn background_mesh_refuses_bad_input() {
    let (positions, tets) = cube_tets();
    let mut values = vec![1.0; 8];
    values[3] = 0.0;
    let e = BackgroundMesh::new(positions.clone(), tets.clone(), values).err();
    assert!(e.is_some_and(|e| e.0.contains("node 3")));
    let mut values = vec![1.0; 8];
    values[2] = f64::NAN;
    assert!(BackgroundMesh::new(positions.clone(), tets.clone(), values).is_err());
    assert!(BackgroundMesh::new(positions.clone(), tets.clone(), vec![1.0; 7]).is_err());
    assert!(BackgroundMesh::new(positions.clone(), vec![], vec![1.0; 8]).is_err());
    assert!(BackgroundMesh::new(positions, vec![[0, 1, 2, 9]], vec![1.0; 8]).is_err());
}

#[test]
fn point_sizes_interpolate_between_the_samples() {
    let points = random_points(50, 0.0, 1.0, 3);
    let values: Vec<f64> = points.iter().map(|&p| linear(p)).collect();
    let cloud = PointSizes::new(&points, &values).expect("valid samples");
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
    for (p, v) in points.iter().zip(&values) {
        assert_eq!(cloud.at(*p), *v);
    }
    for p in random_points(200, -0.5, 1.5, 4) {
        let h = cloud.at(p);
        assert!((lo..=hi).contains(&h), "{h} outside [{lo}, {hi}]");
    }
    assert!(PointSizes::new(&points[..1], &[-1.0]).is_err());
    assert!(PointSizes::new(&[], &[]).is_err());
    assert!(PointSizes::new(&points[..2], &values[..1]).is_err());
}

#[test]
fn gradation_bounds_the_growth_and_never_exceeds_the_field() {
    let bbox = Aabb {
        min: Point3::ZERO,
        max: Point3::new(2.0, 1.0, 1.0),
    };
    let c = Point3::new(0.3, 0.2, 0.7);
    // Grows ten times faster than allowed away from c, and jumps to 1 at x > 1.5.
    let field = move |p: Point3| {
        if p.x > 1.5 {
            1.0
        } else {
            0.01 + 5.0 * p.distance(c)
        }
    };
    let g = 0.4;
    let grid = graded(&field, &[], &bbox, g, 20_000)
        .expect("valid")
        .expect("bounded");
    let n = grid.dims();
    assert!(n[0] * n[1] * n[2] <= 20_000);
    let graded_field = Graded::new(Sizing::function(move |p, _| field(p)), grid.clone());
    let nodes: Vec<(Point3, f64)> = (0..grid.len()).filter_map(|i| grid.node(i)).collect();
    let spacing = nodes[1].0.x - nodes[0].0.x;
    let points = random_points(200, 0.0, 1.0, 5);
    for (i, &a) in points.iter().enumerate() {
        let a = a * bbox.max;
        let ha = graded_field.size_at(a, 1);
        assert!(ha <= field(a) + 1e-12);
        // The cones from the field's values at the nodes, with the 26-neighbour paths' 8 % and
        // the trilinear interpolation across one cell.
        let cones = nodes
            .iter()
            .map(|&(x, _)| field(x) + 1.09 * g * a.distance(x))
            .fold(f64::INFINITY, f64::min);
        assert!(
            ha <= cones + 3f64.sqrt() * g * spacing,
            "at {a}: {ha} > {cones}"
        );
        // ... and no lower than the exact cones.
        let exact = nodes
            .iter()
            .map(|&(x, _)| field(x) + g * a.distance(x))
            .fold(f64::INFINITY, f64::min);
        assert!(grid.at(a) >= exact - 3f64.sqrt() * g * spacing, "at {a}");
        let b = points[(i + 1) % points.len()] * bbox.max;
        let hb = grid.at(b);
        let l1 = (a - b).abs().element_sum();
        assert!((grid.at(a) - hb).abs() <= g * l1 * (1.0 + 1e-9) + 1e-12);
    }
    assert!(
        graded(&field, &[], &bbox, 0.0, 1000)
            .expect("valid")
            .is_none()
    );
    assert!(
        graded(&|_| f64::INFINITY, &[], &bbox, 0.5, 1000)
            .expect("valid")
            .is_none()
    );
}

#[test]
fn checked_fields_remember_the_first_bad_value() {
    let checked = Checked::new(std::sync::Arc::new(
        |p: Point3, _: u32| {
            if p.x < 0.0 { -1.0 } else { 0.5 }
        },
    ));
    assert_eq!(checked.size_at(Point3::X, 1), 0.5);
    assert!(checked.first_bad().is_none());
    assert_eq!(checked.size_at(-Point3::X, 1), f64::INFINITY);
    assert_eq!(checked.size_at(-Point3::Y - Point3::X, 1), f64::INFINITY);
    assert_eq!(checked.first_bad(), Some((-Point3::X, -1.0)));
}

#[test]
fn seeds_grow_by_the_gradation_too() {
    let bbox = Aabb {
        min: Point3::ZERO,
        max: Point3::ONE,
    };
    let seed = Point3::new(0.31, 0.52, 0.47);
    let (g, small) = (0.5, 0.01);
    let grid = graded(&|_| 1.0, &[(seed, small)], &bbox, g, 20_000)
        .expect("valid")
        .expect("bounded");
    let spacing =
        grid.node(1).map(|n| n.0.x).unwrap_or(0.0) - grid.node(0).map(|n| n.0.x).unwrap_or(0.0);
    assert!(spacing > 0.0);
    for p in random_points(200, 0.0, 1.0, 9) {
        let d = p.distance(seed);
        let h = grid.at(p);
        // The cone from the seed (8 % longer paths, a cell's diagonal of interpolation), the
        // field's value beyond it.
        let cone = small + g * (1.09 * d + 2.0 * 3f64.sqrt() * spacing);
        assert!(h <= cone.min(1.0) + 1e-12, "at {p}: {h} > {cone}");
        assert!(
            h >= (small + g * (d - 3f64.sqrt() * spacing)).min(1.0) - 1e-12,
            "at {p}: {h}"
        );
    }
}
