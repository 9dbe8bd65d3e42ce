use super::predicates::{circumcenter, incircle, incircle_perturbed, lex_cmp, orient2d};
use super::*;
use crate::random::XorShift;
use glam::DVec2;
use std::cmp::Ordering;

fn random_points(n: usize, seed: u64) -> Vec<DVec2> {
    let mut rng = XorShift::new(seed);
    (0..n)
        .map(|_| {
            let x = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
            let y = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
            DVec2::new(x, y)
        })
        .collect()
}

fn grid(n: i32) -> Vec<DVec2> {
    (0..n)
        .flat_map(|i| (0..n).map(move |j| DVec2::new(f64::from(i), f64::from(j))))
        .collect()
}

/// Integer points on the circle x² + y² = r² (all exactly cocircular).
fn circle_points(r: i32) -> Vec<DVec2> {
    let mut pts = Vec::new();
    for x in -r..=r {
        for y in -r..=r {
            if x * x + y * y == r * r {
                pts.push(DVec2::new(f64::from(x), f64::from(y)));
            }
        }
    }
    pts
}

/// Triangles as point triples, each rotated to start at its lexicographically smallest corner,
/// sorted: a vertex-id-free fingerprint of the triangulation.
fn triangle_set(t: &Delaunay2) -> Vec<[(u64, u64); 3]> {
    let mut out: Vec<[(u64, u64); 3]> = t
        .finite_cells()
        .map(|c| {
            let p = t.cell(c).map(|v| t.point(v));
            let k = (0..3).min_by(|&i, &j| lex_cmp(p[i], p[j])).unwrap_or(0);
            let q = [p[k], p[(k + 1) % 3], p[(k + 2) % 3]];
            q.map(|p| (p.x.to_bits(), p.y.to_bits()))
        })
        .collect();
    out.sort_unstable();
    out
}

/// Brute force: no input point strictly inside any triangle's circumcircle.
fn assert_empty_circles(t: &Delaunay2, pts: &[DVec2]) {
    for c in t.finite_cells() {
        let [a, b, d] = t.cell(c).map(|v| t.point(v));
        for &p in pts {
            assert_ne!(
                incircle(a, b, d, p),
                Ordering::Greater,
                "{p} inside circle of {c:?}"
            );
        }
    }
}

fn build(pts: &[DVec2]) -> Delaunay2 {
    let (t, _) = Delaunay2::from_points(pts).expect("finite input");
    t.check_validity().expect("valid triangulation");
    t
}

#[test]
fn seed004_circumcentre() {
    let c = circumcenter(
        DVec2::new(1.0, 3.0),
        DVec2::new(4.0, 1.0),
        DVec2::new(-2.0, 0.0),
    );
    assert!((c - DVec2::new(1.1, -0.1)).length() < 1e-12, "{c}");
}

#[test]
fn seed004_incircle_cases() {
    let (a, b, c) = (DVec2::ZERO, DVec2::X, DVec2::Y);
    assert_eq!(incircle(a, b, c, DVec2::new(0.3, 0.3)), Ordering::Greater);
    assert_eq!(incircle(a, b, c, DVec2::new(2.0, 2.0)), Ordering::Less);
    assert_eq!(incircle(a, b, c, DVec2::new(1.0, 1.0)), Ordering::Equal);
    // The perturbation breaks the tie and the answer is a property of the four points only.
    let s = incircle_perturbed(a, b, c, DVec2::ONE);
    assert_ne!(s, Ordering::Equal);
    assert_eq!(incircle_perturbed(b, c, a, DVec2::ONE), s);
    assert_eq!(incircle_perturbed(b, a, c, DVec2::ONE), s.reverse());
}

#[test]
fn perturbed_incircle_is_antisymmetric_on_cocircular_points() {
    let p = circle_points(5);
    let mut rng = XorShift::new(7);
    for _ in 0..500 {
        let q: Vec<DVec2> = (0..4).map(|_| p[rng.below(p.len())]).collect();
        if (0..4).any(|i| (i + 1..4).any(|j| q[i] == q[j])) {
            continue;
        }
        let s = incircle_perturbed(q[0], q[1], q[2], q[3]);
        if orient2d(q[0], q[1], q[2]) != Ordering::Equal {
            assert_ne!(s, Ordering::Equal);
        }
        assert_eq!(incircle_perturbed(q[1], q[0], q[2], q[3]), s.reverse());
        assert_eq!(incircle_perturbed(q[0], q[1], q[3], q[2]), s.reverse());
        assert_eq!(incircle_perturbed(q[3], q[1], q[2], q[0]), s.reverse());
    }
}

#[test]
fn random_sets_are_delaunay() {
    for (n, seed) in [(3, 1), (10, 2), (100, 3), (500, 4)] {
        let pts = random_points(n, seed);
        let t = build(&pts);
        assert_eq!(t.num_vertices(), n);
        assert_empty_circles(&t, &pts);
    }
    let t = build(&random_points(20_000, 5));
    assert_eq!(t.num_vertices(), 20_000);
}

#[test]
fn one_at_a_time_insertion_matches_bulk() {
    let pts = random_points(300, 11);
    let mut t = Delaunay2::new();
    for &p in &pts {
        t.insert(p).expect("finite");
    }
    t.check_validity().expect("valid");
    assert_eq!(triangle_set(&t), triangle_set(&build(&pts)));
}

#[test]
fn integer_grid_is_unique_under_three_orders() {
    let pts = grid(25);
    let t = build(&pts);
    assert_empty_circles(&t, &pts);
    assert_eq!(t.num_finite_cells(), 2 * 24 * 24);
    let mut rev = pts.clone();
    rev.reverse();
    let mut shuffled = pts.clone();
    let mut rng = XorShift::new(3);
    for i in (1..shuffled.len()).rev() {
        shuffled.swap(i, rng.below(i + 1));
    }
    let mut seq = Delaunay2::new();
    for &p in &shuffled {
        seq.insert(p).expect("finite");
    }
    seq.check_validity().expect("valid");
    let reference = triangle_set(&t);
    assert_eq!(triangle_set(&build(&rev)), reference);
    assert_eq!(triangle_set(&seq), reference);
}

#[test]
fn cocircular_points_are_order_independent() {
    let mut pts = circle_points(25);
    let t = build(&pts);
    assert_eq!(t.num_finite_cells(), pts.len() - 2);
    let reference = triangle_set(&t);
    for k in 1..4 {
        pts.rotate_left(k * 5);
        let mut seq = Delaunay2::new();
        for &p in &pts {
            seq.insert(p).expect("finite");
        }
        seq.check_validity().expect("valid");
        assert_eq!(triangle_set(&seq), reference);
    }
}

#[test]
fn collinear_points_then_one_off_the_line() {
    let line: Vec<DVec2> = (0..50)
        .map(|i| DVec2::new(f64::from(i), 2.0 * f64::from(i)))
        .collect();
    let mut t = build(&line);
    assert_eq!(t.num_vertices(), 50);
    assert_eq!(t.num_finite_cells(), 0);
    assert!(t.locate(DVec2::ZERO, None).is_none());
    let mut report = InsertReport::default();
    let outcome = t
        .insert_reporting(DVec2::new(10.0, 0.0), None, &mut report)
        .expect("finite");
    assert!(matches!(outcome, InsertOutcome::Inserted(_)));
    t.check_validity().expect("valid");
    assert_eq!(t.num_finite_cells(), 49);
    assert_eq!(report.created.len(), t.cells().count());
    // A point on the hull line, inside a hull edge, and one beyond the line's end.
    t.insert(DVec2::new(0.5, 1.0)).expect("finite");
    t.insert(DVec2::new(60.0, 120.0)).expect("finite");
    t.check_validity().expect("valid");
}

#[test]
fn duplicates_are_reported_not_inserted() {
    let mut pts = random_points(100, 9);
    pts.extend_from_within(0..30);
    let (t, outcomes) = Delaunay2::from_points(&pts).expect("finite");
    t.check_validity().expect("valid");
    assert_eq!(t.num_vertices(), 100);
    // Bulk insertion order is spatial, so either copy may be the one inserted.
    let mut inserted = 0;
    for (i, o) in outcomes.iter().enumerate() {
        match *o {
            InsertOutcome::Inserted(v) => {
                inserted += 1;
                assert_eq!(t.point(v), pts[i]);
            }
            InsertOutcome::Duplicate(v) => assert_eq!(t.point(v), pts[i]),
            InsertOutcome::Hidden(v) => panic!("a Delaunay triangulation hid vertex {v:?}"),
        }
    }
    assert_eq!(inserted, 100);
    let equal = vec![DVec2::new(1.5, -2.0); 40];
    let (t, outcomes) = Delaunay2::from_points(&equal).expect("finite");
    assert_eq!(t.num_vertices(), 1);
    assert_eq!(
        outcomes
            .iter()
            .filter(|o| matches!(o, InsertOutcome::Duplicate(_)))
            .count(),
        39
    );
}

#[test]
fn non_finite_points_are_errors() {
    let mut t = Delaunay2::new();
    assert!(matches!(
        t.insert(DVec2::new(f64::NAN, 0.0)),
        Err(TriangulationError::NonFinite { .. })
    ));
    assert!(matches!(
        t.insert(DVec2::new(1e300, 0.0)),
        Err(TriangulationError::TooLarge { .. })
    ));
    assert!(Delaunay2::from_points(&[DVec2::ZERO, DVec2::INFINITY]).is_err());
}

#[test]
fn large_offsets_nearly_cocircular() {
    let off = DVec2::splat(1e8);
    let mut pts: Vec<DVec2> = circle_points(65).into_iter().map(|p| p + off).collect();
    let mut rng = XorShift::new(4);
    for p in pts.iter_mut().step_by(3) {
        let ulp = (rng.next_u64() % 3) as f64 - 1.0;
        p.x = f64::from_bits((p.x.to_bits() as i64 + ulp as i64) as u64);
    }
    let t = build(&pts);
    assert_empty_circles(&t, &pts);
}

#[test]
fn conflict_zone_matches_brute_force_and_report() {
    let pts = random_points(400, 21);
    let mut t = build(&pts);
    for q in random_points(50, 22) {
        let mut zone = ConflictZone::default();
        t.conflict_zone(q, None, &mut zone);
        let mut brute: Vec<CellId> = t.cells().filter(|&c| t.in_conflict(c, q)).collect();
        let mut found = zone.cells.clone();
        brute.sort();
        found.sort();
        assert_eq!(found, brute);
        let mut report = InsertReport::default();
        t.insert_reporting(q, None, &mut report).expect("finite");
        let mut removed = report.removed.clone();
        removed.sort();
        assert_eq!(removed, brute);
        assert_eq!(report.created.len(), zone.boundary_facets.len());
        assert!(report.created.iter().all(|&c| t.is_live(c)));
    }
    t.check_validity().expect("valid");
}

#[test]
fn incident_cells_surround_each_vertex() {
    let t = build(&random_points(200, 31));
    for v in t.vertices() {
        let mut around = Vec::new();
        t.incident_cells(v, &mut around);
        assert!(around.len() >= 2);
        assert!(around.iter().all(|&c| t.cell(c).contains(&v)));
    }
}

#[test]
fn a_vertical_line_at_signed_zeros_starts_a_delaunay_triangulation() {
    // Points of the line x = 0 with both signs of zero, inserted first (while the triangulation
    // is one-dimensional), then points off the line.
    let line: Vec<DVec2> = (0..8)
        .map(|i| {
            let x = if i % 3 == 0 { 0.0 } else { -0.0 };
            DVec2::new(x, f64::from(i) * 0.37 - f64::from(i * i) * 0.01)
        })
        .collect();
    let off = [
        DVec2::new(1.0, 0.2),
        DVec2::new(0.5, 1.1),
        DVec2::new(0.8, 2.4),
        DVec2::new(0.4, 0.5),
    ];
    for k in 2..=line.len() {
        let mut t = Delaunay2::new();
        t.insert_points(&line[..k]).unwrap();
        for &p in line[k..].iter().chain(&off) {
            t.insert(p).unwrap();
        }
        t.check_validity().expect("valid triangulation");
        let all: Vec<DVec2> = line.iter().chain(&off).copied().collect();
        assert_empty_circles(&t, &all);
    }
}
