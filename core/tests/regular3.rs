//! Regular3 on random and degenerate weighted point sets: validity (exact), brute-force empty
//! orthogonal spheres and hidden points, weight 0 = Delaunay, uniqueness across insertion orders,
//! hiding, coincident points, bad weights.

use delamesh_core::kernel::{Point3, Sign, orient3d, power_test};
use delamesh_core::triangulation::validity::{check_delaunay3, check_regular3};
use delamesh_core::triangulation::{
    ConflictZone, Delaunay3, InsertOutcome, InsertReport, Regular3, Triangulation,
    TriangulationError, VertexId,
};
use rand::rngs::StdRng;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use std::collections::BTreeSet;

/// `n` uniform points in the unit cube with weights uniform in `[0, fraction · spacing²)`, where
/// the spacing `n^(-1/3)` is the typical distance between neighbours.
fn weighted_uniform(n: usize, fraction: f64, seed: u64) -> Vec<(Point3, f64)> {
    let mut rng = StdRng::seed_from_u64(seed);
    let spacing = (n as f64).powf(-1.0 / 3.0);
    (0..n)
        .map(|_| {
            let p = Point3::new(rng.random(), rng.random(), rng.random());
            (p, rng.random::<f64>() * fraction * spacing * spacing)
        })
        .collect()
}

fn grid(side: i32, weight: impl Fn(i32, i32, i32) -> f64) -> Vec<(Point3, f64)> {
    let mut pts = Vec::new();
    for x in 0..side {
        for y in 0..side {
            for z in 0..side {
                pts.push((Point3::new(x as f64, y as f64, z as f64), weight(x, y, z)));
            }
        }
    }
    pts
}

type Key = [u64; 3];

fn key(p: Point3) -> Key {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

/// The finite cells as sorted quadruples of point keys: comparable across triangulations.
fn tet_set<T: Triangulation<Point = Point3, Cell = [VertexId; 4]>>(t: &T) -> BTreeSet<[Key; 4]> {
    t.finite_cells()
        .map(|c| {
            let mut q = t.cell(c).map(|v| key(t.point(v)));
            q.sort_unstable();
            q
        })
        .collect()
}

fn hidden_keys(rt: &Regular3) -> BTreeSet<Key> {
    rt.hidden_vertices().map(|v| key(rt.point(v))).collect()
}

fn assert_valid(rt: &Regular3) {
    if let Err(e) = check_regular3(rt) {
        panic!("invalid regular triangulation: {e}");
    }
}

/// Whether `p` lies in the closed tetrahedron `t` (positively oriented).
fn in_closed_tet(t: [Point3; 4], p: Point3) -> bool {
    (0..4).all(|i| {
        let mut q = t;
        q[i] = p;
        orient3d(q[0], q[1], q[2], q[3]) != Sign::Negative
    })
}

/// Brute force with the raw exact power test (no perturbation, no triangulation predicates):
/// no vertex in the triangulation has a negative power distance to a finite cell's orthogonal
/// sphere, and every hidden vertex lies in a finite cell whose orthogonal sphere it does not reach.
fn assert_regular_by_brute_force(rt: &Regular3) {
    let cells: Vec<[VertexId; 4]> = rt.finite_cells().map(|c| rt.cell(c)).collect();
    let wp = |v: VertexId| rt.weighted_point(v);
    for cell in &cells {
        let q = cell.map(wp);
        for v in rt.vertices() {
            if rt.is_hidden(v) || cell.contains(&v) {
                continue;
            }
            assert_ne!(
                power_test(q[0], q[1], q[2], q[3], wp(v)),
                Sign::Positive,
                "vertex {v:?} conflicts with cell {cell:?}"
            );
        }
    }
    for h in rt.hidden_vertices() {
        let covered = cells.iter().any(|cell| {
            let q = cell.map(wp);
            in_closed_tet(q.map(|x| x.point), rt.point(h))
                && power_test(q[0], q[1], q[2], q[3], wp(h)) != Sign::Positive
        });
        assert!(covered, "hidden vertex {h:?} is not covered by a cell");
    }
}

#[test]
fn random_weighted_sets_are_regular() {
    for (n, seed) in [(10, 1), (60, 2), (400, 3), (10_000, 4)] {
        let pts = weighted_uniform(n, 1.0, seed);
        let (rt, vertex_of) = Regular3::from_weighted_points(&pts).expect("valid input");
        assert_valid(&rt);
        assert_eq!(rt.num_vertices(), n);
        for (i, &(p, w)) in pts.iter().enumerate() {
            assert_eq!(rt.point(vertex_of[i]), p);
            assert_eq!(rt.weight(vertex_of[i]), w);
        }
        if n <= 400 {
            assert_regular_by_brute_force(&rt);
        }
    }
}

#[test]
fn one_by_one_insertion_reports_hidden_vertices_consistently() {
    let pts = weighted_uniform(300, 2.0, 9);
    let mut rt = Regular3::new();
    let mut report = InsertReport::default();
    let mut hidden = BTreeSet::new();
    for &(p, w) in &pts {
        match rt.insert_weighted(p, w, None, &mut report).expect("valid") {
            InsertOutcome::Inserted(_) => {}
            InsertOutcome::Hidden(v) => assert!(hidden.insert(v)),
            InsertOutcome::Duplicate(v) => panic!("no duplicates in the input, got {v:?}"),
        }
        for &h in &report.hidden {
            assert!(rt.is_hidden(h));
            assert!(hidden.insert(h), "{h:?} hidden twice");
        }
    }
    assert!(
        !hidden.is_empty(),
        "weights this large must hide some points"
    );
    assert_eq!(hidden, rt.hidden_vertices().collect());
    assert_valid(&rt);
    assert_regular_by_brute_force(&rt);
    // The bulk build of the same points is the same triangulation.
    let (bulk, _) = Regular3::from_weighted_points(&pts).expect("valid");
    assert_eq!(tet_set(&bulk), tet_set(&rt));
    assert_eq!(hidden_keys(&bulk), hidden_keys(&rt));
}

#[test]
fn zero_weights_give_the_delaunay_triangulation() {
    let uniform = weighted_uniform(2000, 0.0, 5);
    let cube = grid(5, |_, _, _| 0.0);
    for pts in [uniform, cube] {
        let positions: Vec<Point3> = pts.iter().map(|&(p, _)| p).collect();
        let dt = Delaunay3::from_points(&positions).expect("finite");
        assert_eq!(check_delaunay3(&dt), Ok(()));
        let (rt, _) = Regular3::from_weighted_points(&pts).expect("valid");
        assert_valid(&rt);
        assert_eq!(rt.hidden_vertices().count(), 0);
        assert_eq!(tet_set(&rt), tet_set(&dt));
        // `Triangulation::insert` inserts with weight 0.
        let mut one_by_one = Regular3::new();
        for &p in &positions {
            one_by_one.insert(p).expect("finite");
        }
        assert_eq!(tet_set(&one_by_one), tet_set(&dt));
    }
}

/// The triangulation after inserting `pts` one by one in `order`.
fn insert_in_order(pts: &[(Point3, f64)], order: &[usize]) -> Regular3 {
    let mut rt = Regular3::new();
    let mut report = InsertReport::default();
    for &i in order {
        let (p, w) = pts[i];
        rt.insert_weighted(p, w, None, &mut report).expect("valid");
    }
    rt
}

#[test]
fn insertion_order_does_not_matter() {
    let sets = [
        // Small weights: nothing hidden.
        weighted_uniform(500, 0.05, 6),
        // Equal weights on a grid: massively degenerate power tests.
        grid(5, |_, _, _| 0.3),
        // Two weight classes on a grid: degenerate in a different way.
        grid(5, |x, y, z| if (x + y + z) % 2 == 0 { 0.25 } else { 0.0 }),
        // Large weights: some points hidden.
        weighted_uniform(300, 2.0, 7),
    ];
    let mut rng = StdRng::seed_from_u64(8);
    for pts in sets {
        let forward: Vec<usize> = (0..pts.len()).collect();
        let backward: Vec<usize> = forward.iter().rev().copied().collect();
        let mut shuffled = forward.clone();
        shuffled.shuffle(&mut rng);
        let (bulk, _) = Regular3::from_weighted_points(&pts).expect("valid");
        assert_valid(&bulk);
        let expected = tet_set(&bulk);
        for order in [forward, backward, shuffled] {
            let rt = insert_in_order(&pts, &order);
            assert_valid(&rt);
            assert_eq!(tet_set(&rt), expected);
            assert_eq!(hidden_keys(&rt), hidden_keys(&bulk));
        }
    }
}

#[test]
fn equal_weights_on_a_grid_give_the_delaunay_triangulation() {
    let pts = grid(6, |_, _, _| 0.2);
    let (rt, _) = Regular3::from_weighted_points(&pts).expect("valid");
    assert_valid(&rt);
    assert_regular_by_brute_force(&rt);
    assert_eq!(rt.hidden_vertices().count(), 0);
    let positions: Vec<Point3> = pts.iter().map(|&(p, _)| p).collect();
    let dt = Delaunay3::from_points(&positions).expect("finite");
    assert_eq!(tet_set(&rt), tet_set(&dt));
}

#[test]
fn a_heavy_point_hides_the_light_points_around_it() {
    let mut rt = Regular3::new();
    let mut report = InsertReport::default();
    for x in [-1.0, 1.0] {
        for y in [-1.0, 1.0] {
            for z in [-1.0, 1.0] {
                let outcome = rt.insert_weighted(Point3::new(x, y, z), 0.0, None, &mut report);
                assert!(matches!(outcome, Ok(InsertOutcome::Inserted(_))));
            }
        }
    }
    let mut light = BTreeSet::new();
    for d in [-0.1, 0.1] {
        for axis in 0..3 {
            let mut p = Point3::ZERO;
            p[axis] = d;
            match rt.insert_weighted(p, 0.0, None, &mut report) {
                Ok(InsertOutcome::Inserted(v)) => assert!(light.insert(v)),
                other => panic!("light point not inserted: {other:?}"),
            }
        }
    }
    assert_valid(&rt);
    // Lifted, the light points sit at height 0.01, far above the cone from (0, -1) to the
    // corners at height 3 (about 0.3 − 0.9 = −0.6 at distance 0.1): all six are hidden.
    let heavy = rt
        .insert_weighted(Point3::ZERO, 1.0, None, &mut report)
        .expect("valid");
    assert!(matches!(heavy, InsertOutcome::Inserted(_)));
    let reported: BTreeSet<VertexId> = report.hidden.iter().copied().collect();
    assert_eq!(reported, light);
    assert!(light.iter().all(|&v| rt.is_hidden(v)));
    let mut around = Vec::new();
    for &v in &light {
        rt.incident_cells(v, &mut around);
        assert!(around.is_empty());
    }
    assert_valid(&rt);
    assert_regular_by_brute_force(&rt);
    // Eight corners and the heavy centre remain: the 12 tetrahedra of the cube's 6 faces
    // (two triangles each) coned to the centre.
    assert_eq!(rt.num_finite_cells(), 12);
    // A further light point nearby is hidden at once, and changes nothing.
    let before = tet_set(&rt);
    let late = rt.insert_weighted(Point3::new(0.05, 0.05, 0.0), 0.0, None, &mut report);
    let Ok(InsertOutcome::Hidden(v)) = late else {
        panic!("expected a hidden point, got {late:?}");
    };
    assert!(report.created.is_empty() && report.removed.is_empty());
    assert_eq!(rt.point(v), Point3::new(0.05, 0.05, 0.0));
    assert_eq!(tet_set(&rt), before);
    assert_valid(&rt);
}

#[test]
fn at_the_same_position_the_heavier_point_wins() {
    // Once in the lower-dimensional phase (fewer than four independent points), once with cells.
    for prefix in [0, 6] {
        let mut rt = Regular3::new();
        let mut report = InsertReport::default();
        for &(p, w) in &weighted_uniform(prefix, 0.01, 10) {
            rt.insert_weighted(p, w, None, &mut report).expect("valid");
        }
        let p = Point3::new(0.3, 0.4, 0.5);
        let first = rt
            .insert_weighted(p, 0.001, None, &mut report)
            .expect("valid");
        let InsertOutcome::Inserted(a) = first else {
            panic!("expected an insertion, got {first:?}");
        };
        let second = rt
            .insert_weighted(p, 0.002, None, &mut report)
            .expect("valid");
        let InsertOutcome::Inserted(b) = second else {
            panic!("expected an insertion, got {second:?}");
        };
        assert_eq!(report.hidden, vec![a]);
        assert!(rt.is_hidden(a) && !rt.is_hidden(b));
        let lighter = rt.insert_weighted(p, 0.0015, None, &mut report);
        assert!(matches!(lighter, Ok(InsertOutcome::Hidden(_))));
        let same = rt.insert_weighted(p, 0.002, None, &mut report);
        assert_eq!(same, Ok(InsertOutcome::Duplicate(b)));
        for &(q, w) in &weighted_uniform(20, 0.01, 11) {
            rt.insert_weighted(q, w, None, &mut report).expect("valid");
        }
        assert!(rt.is_hidden(a) && !rt.is_hidden(b));
        assert_valid(&rt);
        assert_regular_by_brute_force(&rt);
    }
}

#[test]
fn orthocentres_have_equal_power_distance_to_their_vertices() {
    let pts = weighted_uniform(200, 1.0, 12);
    let (rt, _) = Regular3::from_weighted_points(&pts).expect("valid");
    for c in rt.finite_cells() {
        let centre = rt.circumcenter(c);
        let d = rt.cell(c).map(|v| rt.power_distance(v, centre));
        let scale = d.iter().fold(1e-3_f64, |m, x| m.max(x.abs()));
        for x in &d[1..] {
            assert!(
                (x - d[0]).abs() <= 1e-6 * scale,
                "cell {c:?}: power distances {d:?} from its orthocentre differ"
            );
        }
    }
}

#[test]
fn the_conflict_zone_of_a_weight_zero_point_is_what_its_insertion_removes() {
    let pts = weighted_uniform(500, 1.0, 13);
    let (mut rt, _) = Regular3::from_weighted_points(&pts).expect("valid");
    let mut zone = ConflictZone::default();
    let mut report = InsertReport::default();
    let mut rng = StdRng::seed_from_u64(14);
    for _ in 0..20 {
        let p = Point3::new(rng.random(), rng.random(), rng.random());
        rt.conflict_zone(p, None, &mut zone);
        let expected: BTreeSet<_> = rt
            .cells()
            .filter(|&c| rt.is_in_conflict_weighted(c, p, 0.0))
            .collect();
        let found: BTreeSet<_> = zone.cells.iter().copied().collect();
        assert_eq!(found, expected);
        let outcome = rt.insert_reporting(p, None, &mut report).expect("finite");
        let removed: BTreeSet<_> = report.removed.iter().copied().collect();
        match outcome {
            InsertOutcome::Inserted(_) => assert_eq!(removed, expected),
            InsertOutcome::Hidden(_) => assert!(expected.is_empty() && removed.is_empty()),
            InsertOutcome::Duplicate(v) => panic!("random point equals vertex {v:?}"),
        }
    }
    assert_valid(&rt);
}

#[test]
fn bad_weights_are_errors() {
    let p = Point3::new(0.1, 0.2, 0.3);
    for w in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1e-9, 1e120] {
        let mut pts = weighted_uniform(10, 0.1, 15);
        pts.push((p, w));
        assert!(matches!(
            Regular3::from_weighted_points(&pts),
            Err(TriangulationError::InvalidWeight { index: 10, .. })
        ));
        let (mut rt, _) = Regular3::from_weighted_points(&pts[..10]).expect("valid");
        let mut report = InsertReport::default();
        assert!(matches!(
            rt.insert_weighted(p, w, None, &mut report),
            Err(TriangulationError::InvalidWeight { .. })
        ));
        assert_eq!(rt.num_vertices(), 10);
        assert_valid(&rt);
    }
    let mut rt = Regular3::new();
    let mut report = InsertReport::default();
    assert!(matches!(
        rt.insert_weighted(Point3::new(f64::NAN, 0.0, 0.0), 0.0, None, &mut report),
        Err(TriangulationError::NonFinite { .. })
    ));
}

#[test]
fn coplanar_weighted_points_before_the_first_cell() {
    // A planar grid with random weights (some hidden once cells exist), then one point off the
    // plane: every planar point waits in the lower-dimensional phase, and the hull facets on the
    // plane exercise the coplanar power test of infinite cells.
    let mut rng = StdRng::seed_from_u64(16);
    let mut pts: Vec<(Point3, f64)> = (0..49)
        .map(|i| {
            let p = Point3::new((i % 7) as f64, (i / 7) as f64, 0.0);
            (p, rng.random::<f64>() * 3.0)
        })
        .collect();
    pts.push((Point3::new(3.0, 3.0, 2.5), 0.0));
    let forward: Vec<usize> = (0..pts.len()).collect();
    let mut report = InsertReport::default();
    let mut rt = Regular3::new();
    let mut hidden = BTreeSet::new();
    for &(p, w) in &pts {
        if let InsertOutcome::Hidden(v) =
            rt.insert_weighted(p, w, None, &mut report).expect("valid")
        {
            hidden.insert(v);
        }
        hidden.extend(report.hidden.iter().copied());
    }
    // A point lighter by more than 1 than both its grid neighbours on a line is hidden.
    assert!(!hidden.is_empty());
    assert_eq!(hidden, rt.hidden_vertices().collect());
    assert_valid(&rt);
    assert_regular_by_brute_force(&rt);
    let apex_first: Vec<usize> = forward.iter().rev().copied().collect();
    let other = insert_in_order(&pts, &apex_first);
    assert_valid(&other);
    assert_eq!(tet_set(&other), tet_set(&rt));
    assert_eq!(hidden_keys(&other), hidden_keys(&rt));
}
