use super::admissible::{Theta2, classify};
use super::conform::{Algorithm, ConformError, ConformOptions, Conformed, Conformer, conform};
use super::pslg::{Pslg, PslgError};
use super::quality::shape_measure;
use crate::triangulation::Triangulation;
use crate::triangulation::delaunay2::predicates::{dot_sign, incircle, orient2d};
use crate::triangulation::delaunay2::{Delaunay2, INFINITE, VertexId};
use glam::DVec2;
use std::cmp::Ordering;

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

fn pslg(points: &[DVec2], segments: &[[u32; 2]]) -> Pslg {
    Pslg {
        points: points.to_vec(),
        segments: segments.to_vec(),
        segment_markers: vec![0; segments.len()],
        ..Pslg::default()
    }
}

/// Deterministic pseudo-random integers in `0..n`.
fn lcg(seed: &mut u64, n: u64) -> u64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 33) % n
}

/// Independent oracle (note 000 §2): strongly admissible iff no point on the closed edge and every
/// point on one side is strictly outside the circle through the edge and any point on the other.
fn oracle(points: &[DVec2], i: usize, j: usize) -> bool {
    let (a, b) = (points[i], points[j]);
    let others = || {
        (0..points.len())
            .filter(|&k| k != i && k != j)
            .map(|k| points[k])
    };
    if others()
        .any(|p| orient2d(a, b, p) == Ordering::Equal && dot_sign(p, a, b) != Ordering::Greater)
    {
        return false;
    }
    for p in others().filter(|&p| orient2d(a, b, p) == Ordering::Greater) {
        for q in others().filter(|&q| orient2d(a, b, q) == Ordering::Less) {
            if incircle(a, b, p, q) != Ordering::Less {
                return false;
            }
        }
    }
    true
}

fn edge_in(t: &Delaunay2, a: VertexId, b: VertexId) -> bool {
    let mut around = Vec::new();
    t.incident_cells(a, &mut around);
    around.iter().any(|&c| t.cell(c).contains(&b))
}

#[test]
fn one_example_per_class() {
    let (a, b) = (v(0.0, 0.0), v(4.0, 0.0));
    // The circle through a, b and (2, 1) has centre (2, -1.5) and radius 2.5.
    let cases: [(&[DVec2], Theta2); 6] = [
        (&[v(1.0, 5.0)], Theta2::Empty),
        (&[v(2.0, 1.0), v(2.0, -10.0)], Theta2::OneSideClear),
        (&[v(2.0, 1.0), v(2.0, -3.5)], Theta2::OneSideBlocked),
        (&[v(2.0, 1.0), v(0.5, 0.5)], Theta2::CocircularOneSide),
        (&[v(2.0, 1.0), v(3.5, -3.5)], Theta2::CocircularBothSides),
        (&[v(1.0, 0.5), v(1.0, -0.5)], Theta2::BothSides),
    ];
    for (extra, expected) in cases {
        let mut pts = vec![a, b];
        pts.extend_from_slice(extra);
        assert_eq!(classify(&pts, 0, 1), expected, "{extra:?}");
        assert_eq!(classify(&pts, 1, 0), expected);
        assert_eq!(
            classify(&pts, 0, 1).is_strongly_admissible(),
            oracle(&pts, 0, 1)
        );
    }
    // A point on the diametral circle, alone on its side: class 1.0.
    assert_eq!(classify(&[a, b, v(2.0, 2.0)], 0, 1), Theta2::OneSideClear);
}

/// The images of a point set under exact rigid motions, scaling and reflection.
fn transforms(p: &[DVec2]) -> Vec<Vec<DVec2>> {
    let map = |f: &dyn Fn(DVec2) -> DVec2| p.iter().map(|&q| f(q)).collect::<Vec<_>>();
    vec![
        map(&|q| q + v(17.0, -5.0)),
        map(&|q| v(-q.y, q.x)),
        map(&|q| q * 2.0),
        map(&|q| v(-q.x, q.y)),
    ]
}

fn check_against_oracle(pts: &[DVec2]) -> usize {
    let (t, outcomes) = Delaunay2::from_points(pts).expect("finite");
    let ids: Vec<VertexId> = outcomes.iter().map(|o| o.vertex()).collect();
    let images = transforms(pts);
    let mut admissible = 0;
    for i in 0..pts.len() {
        for j in i + 1..pts.len() {
            let class = classify(pts, i, j);
            assert_eq!(
                class.is_strongly_admissible(),
                oracle(pts, i, j),
                "{:?}",
                (pts[i], pts[j])
            );
            assert_eq!(classify(pts, j, i), class);
            for img in &images {
                assert_eq!(classify(img, i, j), class);
            }
            if class.is_strongly_admissible() {
                admissible += 1;
                assert!(
                    edge_in(&t, ids[i], ids[j]),
                    "admissible edge missing from the DT"
                );
            }
        }
    }
    admissible
}

#[test]
fn classifier_agrees_with_oracle_on_random_integer_points() {
    let mut seed = 5;
    for _ in 0..40 {
        let mut pts: Vec<DVec2> = Vec::new();
        while pts.len() < 9 {
            let p = v(lcg(&mut seed, 7) as f64, lcg(&mut seed, 7) as f64);
            if !pts.contains(&p) {
                pts.push(p);
            }
        }
        check_against_oracle(&pts);
    }
}

#[test]
fn classifier_agrees_with_oracle_on_cocircular_points() {
    let mut pts = Vec::new();
    for x in -5i32..=5 {
        for y in -5i32..=5 {
            if x * x + y * y == 25 {
                pts.push(v(f64::from(x), f64::from(y)));
            }
        }
    }
    assert_eq!(pts.len(), 12);
    // Only the 12 polygon sides are in every triangulation.
    assert_eq!(check_against_oracle(&pts), 12);
    pts.push(v(0.0, 0.0));
    check_against_oracle(&pts);
}

#[test]
fn pslg_validation_rejects_bad_constraints() {
    let sq = [
        v(0.0, 0.0),
        v(2.0, 0.0),
        v(2.0, 2.0),
        v(0.0, 2.0),
        v(1.0, 0.0),
    ];
    assert_eq!(
        pslg(&sq, &[[0, 2], [1, 3]]).validate(),
        Err(PslgError::Crossing(0, 1))
    );
    assert_eq!(
        pslg(&sq, &[[0, 1]]).validate(),
        Err(PslgError::PointOnSegment(0, 4))
    );
    assert_eq!(
        pslg(&sq, &[[0, 9]]).validate(),
        Err(PslgError::BadIndex(0, 9, 5))
    );
    assert_eq!(
        pslg(&sq, &[[2, 2]]).validate(),
        Err(PslgError::Degenerate(0, 2))
    );
    assert_eq!(
        pslg(&sq, &[[2, 3], [3, 2]]).validate(),
        Err(PslgError::DuplicateSegment(0, 1))
    );
    assert!(
        pslg(&sq, &[[0, 4], [4, 1], [1, 2], [2, 3], [3, 0]])
            .validate()
            .is_ok()
    );
}

/// The vertices along the sub-segments of input segment `s` (those of origin `s`), from its first
/// vertex `a`; panics where they do not form a chain. Shared with the mesher's tests.
pub(super) fn sub_segment_chain(
    segments: &[[u32; 2]],
    origins: &[u32],
    s: usize,
    a: u32,
) -> Vec<u32> {
    let subs: Vec<[u32; 2]> = (0..segments.len())
        .filter(|&k| origins[k] == s as u32)
        .map(|k| segments[k])
        .collect();
    let mut chain = vec![a];
    for _ in 0..subs.len() {
        let at = chain[chain.len() - 1];
        let next = subs.iter().find(|e| e[0] == at).map(|e| e[1]);
        chain.push(next.expect("sub-segments form a chain"));
    }
    chain
}

/// Note 000 §7, properties 1–4 and 10, for a conformed constraint.
fn check_conformed(input: &Pslg, out: &Conformed) {
    let n = input.points.len();
    assert_eq!(&out.points[..n], &input.points[..]);
    assert_eq!(
        out.points.len() - n,
        out.segments.len() - input.segments.len()
    );
    // Each original segment is the chain of its sub-edges, all (nearly) on its line.
    for (s, &[a, b]) in input.segments.iter().enumerate() {
        let (pa, pb) = (input.points[a as usize], input.points[b as usize]);
        let chain = sub_segment_chain(&out.segments, &out.segment_origins, s, a);
        for &at in &chain[1..] {
            let p = out.points[at as usize];
            let off = (p - pa).perp_dot(pb - pa).abs() / (pb - pa).length_squared();
            assert!(off < 1e-12, "point {p} off its segment");
        }
        assert_eq!(chain.last(), Some(&b));
    }
    let result = pslg(&out.points, &out.segments);
    result.validate().expect("Def. 1.5 holds");
    let t = &out.triangulation;
    t.check_validity().expect("valid triangulation");
    for &[a, b] in &out.segments {
        let class = classify(&out.points, a as usize, b as usize);
        assert!(
            class.is_strongly_admissible(),
            "sub-edge of class {}",
            class.label()
        );
        let (va, vb) = (
            out.vertex_of_point[a as usize],
            out.vertex_of_point[b as usize],
        );
        assert!(edge_in(t, va, vb));
        // Not the diagonal of a cocircular cell.
        let mut around = Vec::new();
        t.incident_cells(va, &mut around);
        for c in around {
            let cell = t.cell(c);
            if !cell.contains(&vb) {
                continue;
            }
            let Some(i) = (0..3).find(|&i| cell[i] != va && cell[i] != vb) else {
                continue;
            };
            let n = t.neighbor(c, i);
            let other = t.cell(n)[t.mirror_index(c, i)];
            if !t.is_infinite_cell(c) && other != INFINITE {
                let [p, q, r] = cell.map(|x| t.point(x));
                assert_ne!(incircle(p, q, r, t.point(other)), Ordering::Equal);
            }
        }
    }
}

/// A closed node: `spokes` edges of length 10 from the origin with equal gaps, and one point in
/// each gap at radius about 4, encroaching both neighbouring spokes from opposite sides.
fn closed_node(spokes: usize) -> Pslg {
    let mut pts = vec![v(0.0, 0.0)];
    let mut segs = Vec::new();
    for k in 0..spokes {
        let th = std::f64::consts::TAU * k as f64 / spokes as f64;
        pts.push(v(th.cos(), th.sin()) * 10.0);
        segs.push([0, k as u32 + 1]);
    }
    for k in 0..spokes {
        let th = std::f64::consts::TAU * (k as f64 + 0.5) / spokes as f64;
        pts.push(v(th.cos(), th.sin()) * 4.0 * (1.0 + 0.1 * (k % 3) as f64));
    }
    pslg(&pts, &segs)
}

#[test]
fn all_algorithms_conform_an_acute_polygon() {
    // A polygon with acute corners, a spike inside, and isolated points crowding its edges.
    let pts = [
        v(0.0, 0.0),
        v(10.0, 0.0),
        v(10.0, 1.0),
        v(5.0, 0.4),
        v(1.0, 6.0),
        v(0.0, 6.5),
        v(3.0, 1.0),
        v(1.5, 1.5),
        v(5.0, -0.5),
        v(-0.3, 3.0),
        v(0.4, 3.2),
    ];
    let input = pslg(
        &pts,
        &[
            [0, 1],
            [1, 2],
            [2, 3],
            [3, 4],
            [4, 5],
            [5, 0],
            [3, 6],
            [6, 7],
        ],
    );
    for algorithm in [
        Algorithm::Brute,
        Algorithm::BruteLargeNodes,
        Algorithm::ClosedNodes,
    ] {
        let out = conform(
            &input,
            &ConformOptions {
                algorithm,
                ..Default::default()
            },
        )
        .expect("converges");
        assert!(out.iterations > 0);
        check_conformed(&input, &out);
    }
}

#[test]
fn random_polygons_conform() {
    let mut seed = 11;
    for _ in 0..10 {
        // A star-shaped polygon with random radii: many non-admissible edges.
        let n = 40;
        let pts: Vec<DVec2> = (0..n)
            .map(|k| {
                let th = std::f64::consts::TAU * k as f64 / n as f64;
                let r = 1.0 + lcg(&mut seed, 1000) as f64 / 250.0;
                v(th.cos(), th.sin()) * r
            })
            .collect();
        let segs: Vec<[u32; 2]> = (0..n as u32).map(|k| [k, (k + 1) % n as u32]).collect();
        let input = pslg(&pts, &segs);
        let out = conform(&input, &ConformOptions::default()).expect("converges");
        check_conformed(&input, &out);
    }
}

#[test]
fn closed_node_terminates_with_cleaning_and_spirals_with_projection_only() {
    let input = closed_node(12);
    let mut c = Conformer::new(&input, 1e-10);
    assert!(c.is_closed_node(0));
    let out = conform(&input, &ConformOptions::default()).expect("Algorithm 3.2 terminates");
    check_conformed(&input, &out);
    let projection = ConformOptions {
        algorithm: Algorithm::ProjectionOnly,
        max_iterations: 40,
        ..Default::default()
    };
    assert_eq!(
        conform(&input, &projection).err(),
        Some(ConformError::IterationCap(40))
    );
    // Without the cap, the minimum-length guard stops the spiral.
    let unbounded = ConformOptions {
        max_iterations: usize::MAX,
        ..projection
    };
    assert!(matches!(
        conform(&input, &unbounded),
        Err(ConformError::TooShort { .. })
    ));
    // Five spokes still make a closed node, four cannot.
    c = Conformer::new(&closed_node(5), 1e-10);
    assert!(c.is_closed_node(0));
    assert!(!Conformer::new(&closed_node(4), 1e-10).is_closed_node(0));
}

#[test]
fn projection_splits_inside_and_reduces_counts() {
    let pts = [
        v(0.0, 0.0),
        v(10.0, 0.0),
        v(3.0, 1.0),
        v(6.0, -2.0),
        v(8.0, 1.5),
        v(5.0, 0.2),
    ];
    let input = pslg(&pts, &[[0, 1]]);
    let mut c = Conformer::new(&input, 1e-10);
    let cls = c.classify(0);
    assert_eq!(cls.encroaching.len(), 4);
    let m = c.project(0, &cls.encroaching).expect("long enough");
    let pm = c.points()[m as usize];
    assert!(pm.x > 0.0 && pm.x < 10.0 && pm.y == 0.0);
    let children: usize = c
        .live_edges()
        .into_iter()
        .map(|(e, _)| c.classify(e).encroaching.len())
        .sum();
    // The new point M is an endpoint of both children, never counted as encroaching.
    assert!(children < cls.encroaching.len());
}

#[test]
fn cleaning_cuts_at_one_distance_below_dstar() {
    let pts = [
        v(0.0, 0.0),
        v(10.0, 0.0),
        v(8.0, 3.0),
        v(4.0, 1.0),
        v(9.0, -0.5),
    ];
    let input = pslg(&pts, &[[0, 1], [0, 2]]);
    let mut c = Conformer::new(&input, 1e-10);
    // d*: the nearest point to the centre in the edges' closed diametral disks.
    let dstar = pts[1..]
        .iter()
        .filter(|&&p| {
            dot_sign(p, pts[0], pts[1]) != Ordering::Greater
                || dot_sign(p, pts[0], pts[2]) != Ordering::Greater
        })
        .map(|p| p.length())
        .fold(f64::INFINITY, f64::min);
    let d = c.clean(0, &[0, 1]).expect("long enough");
    assert!(d > 0.0 && d < dstar);
    for (e, [a, b]) in c.live_edges() {
        let (pa, pb) = (c.points()[a as usize], c.points()[b as usize]);
        if a == 0 {
            assert!(((pb - pa).length() - d).abs() <= 1e-12 * d);
            assert_eq!(c.classify(e).class, Theta2::Empty);
        }
    }
}

#[test]
fn admissible_input_is_returned_unchanged() {
    let pts = [
        v(0.0, 0.0),
        v(4.0, 0.0),
        v(4.0, 3.0),
        v(0.0, 3.0),
        v(2.0, 1.5),
    ];
    let input = pslg(&pts, &[[0, 1], [1, 2], [2, 3], [3, 0]]);
    let out = conform(&input, &ConformOptions::default()).expect("nothing to do");
    assert_eq!(out.iterations, 0);
    assert_eq!(out.points, input.points);
    assert_eq!(out.segments, input.segments);
    check_conformed(&input, &out);
}

#[test]
fn shape_measure_is_one_for_equilateral() {
    let eq = shape_measure(v(0.0, 0.0), v(1.0, 0.0), v(0.5, 3f64.sqrt() / 2.0));
    assert!((eq - 1.0).abs() < 1e-12);
    assert!(shape_measure(v(0.0, 0.0), v(1.0, 0.0), v(0.5, 0.01)) > 10.0);
}

/// Whether segments `ab` and `cd` cross at a point interior to both (brute-force reference).
fn crosses(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let o = [
        orient2d(a, b, c),
        orient2d(a, b, d),
        orient2d(c, d, a),
        orient2d(c, d, b),
    ];
    o.iter().all(|&s| s != Ordering::Equal) && o[0] != o[1] && o[2] != o[3]
}

#[test]
fn crossing_check_agrees_with_all_pairs() {
    let mut seed = 99;
    let mut found = 0;
    for _ in 0..300 {
        let mut points: Vec<DVec2> = (0..30)
            .map(|_| v(lcg(&mut seed, 1000) as f64, lcg(&mut seed, 1000) as f64))
            .collect();
        points.sort_by(|p, q| p.x.total_cmp(&q.x).then(p.y.total_cmp(&q.y)));
        points.dedup();
        let n = points.len() as u64;
        let mut segments: Vec<[u32; 2]> = (0..1 + lcg(&mut seed, 12))
            .map(|_| [lcg(&mut seed, n) as u32, lcg(&mut seed, n) as u32])
            .filter(|[a, b]| a != b)
            .collect();
        segments.sort_by_key(|&[a, b]| (a.min(b), a.max(b)));
        segments.dedup_by_key(|&mut [a, b]| (a.min(b), a.max(b)));
        let ends = |s: &[u32; 2]| (points[s[0] as usize], points[s[1] as usize]);
        let on_segment = segments.iter().any(|s| {
            let (a, b) = ends(s);
            points.iter().any(|&p| {
                p != a && p != b && orient2d(a, b, p) == Ordering::Equal && {
                    let (lo, hi) = (a.min(b), a.max(b));
                    p.cmpge(lo).all() && p.cmple(hi).all()
                }
            })
        });
        if on_segment {
            continue;
        }
        let any_crossing = segments.iter().enumerate().any(|(i, s)| {
            segments[i + 1..].iter().any(|t| {
                let ((a, b), (c, d)) = (ends(s), ends(t));
                crosses(a, b, c, d)
            })
        });
        match pslg(&points, &segments).validate() {
            Err(PslgError::Crossing(s, t)) => {
                let ((a, b), (c, d)) = (ends(&segments[s]), ends(&segments[t]));
                assert!(crosses(a, b, c, d));
                found += 1;
            }
            Ok(()) => assert!(!any_crossing),
            Err(e) => panic!("unexpected {e:?}"),
        }
    }
    assert!(found > 0);
}

#[test]
fn duplicate_points_are_reported_in_index_order() {
    let points = [
        v(1.0, 2.0),
        v(0.0, 0.0),
        v(3.0, -1.0),
        v(-0.0, 0.0),
        v(1.0, 2.0),
    ];
    let err = pslg(&points, &[[0, 2]]).validate();
    // -0.0 and 0.0 are the same point, and the origin sorts before (1, 2): that pair is reported,
    // the negative zero (first in the total order) first.
    assert_eq!(err, Err(PslgError::DuplicatePoint(3, 1)));
}
