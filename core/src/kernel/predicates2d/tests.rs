//! The adaptive in-circle against an exact rational evaluation, on inputs built to reach each of
//! its stages: random (first filter), exactly cocircular on integer grids (exact differences),
//! and nearly cocircular far from the origin (inexact differences, the double-double stage, the
//! first-order correction and the complete fallback).

use super::{INCIRCLE_ERROR_DD, dot_sign, exact_differences, incircle, incircle_double_double};
use crate::kernel::exact::{dyadic, scaled};
use glam::DVec2;
use num_bigint::BigInt;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::cmp::Ordering;

/// The smallest binary exponent of the coordinates of `points`: every coordinate is a whole
/// multiple of that power of two, so [`scaled`] by it they are all integers.
fn common_unit(points: &[DVec2]) -> i32 {
    points
        .iter()
        .flat_map(|p| [p.x, p.y])
        .filter(|&x| x != 0.0)
        .map(|x| dyadic(x).1)
        .min()
        .unwrap_or(0)
}

/// The in-circle sign in exact integer arithmetic: every coordinate scaled by the same power of
/// two, then the 3×3 lifted determinant of the differences to `d`.
fn incircle_oracle(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> Ordering {
    let unit = common_unit(&[a, b, c, d]);
    let big = |p: DVec2| [scaled(p.x, unit), scaled(p.y, unit)];
    let dd = big(d);
    let row = |p: DVec2| {
        let [x, y] = big(p);
        let (x, y) = (x - &dd[0], y - &dd[1]);
        let lift = &x * &x + &y * &y;
        [x, y, lift]
    };
    let [ra, rb, rc] = [row(a), row(b), row(c)];
    let minor = |u: &[BigInt; 3], v: &[BigInt; 3]| &u[0] * &v[1] - &u[1] * &v[0];
    let det: BigInt =
        &ra[2] * minor(&rb, &rc) + &rb[2] * minor(&rc, &ra) + &rc[2] * minor(&ra, &rb);
    det.sign().cmp(&num_bigint::Sign::NoSign)
}

fn check(a: DVec2, b: DVec2, c: DVec2, d: DVec2) {
    assert_eq!(
        incircle(a, b, c, d),
        incircle_oracle(a, b, c, d),
        "incircle({a}, {b}, {c}, {d})"
    );
}

#[test]
fn random_points_agree_with_oracle() {
    let mut rng = StdRng::seed_from_u64(7);
    for _ in 0..2000 {
        let scale = 2f64.powi(rng.random_range(-20..20));
        let mut p = || DVec2::new(rng.random::<f64>(), rng.random::<f64>()) * scale;
        check(p(), p(), p(), p());
    }
}

#[test]
fn cocircular_grid_points_agree_with_oracle() {
    // Lattice points on x² + y² = 65² (twelve per octant family), shifted and scaled exactly.
    let r = 65;
    let circle: Vec<DVec2> = (-r..=r)
        .flat_map(|x: i32| (-r..=r).map(move |y: i32| (x, y)))
        .filter(|&(x, y)| x * x + y * y == r * r)
        .map(|(x, y)| DVec2::new(f64::from(x), f64::from(y)))
        .collect();
    assert!(circle.len() > 20);
    let mut rng = StdRng::seed_from_u64(11);
    let mut zeros = 0;
    for _ in 0..2000 {
        let shift = DVec2::new(
            f64::from(rng.random_range(-1000..1000)),
            f64::from(rng.random_range(-1000..1000)),
        );
        let scale = 2f64.powi(rng.random_range(-30..30));
        let mut p = || (circle[rng.random_range(0..circle.len())] + shift) * scale;
        let (a, b, c, d) = (p(), p(), p(), p());
        zeros += usize::from(incircle(a, b, c, d) == Ordering::Equal);
        check(a, b, c, d);
    }
    assert_eq!(
        zeros, 2000,
        "exactly cocircular points must test on the circle"
    );
}

#[test]
fn nearly_cocircular_points_agree_with_oracle() {
    // Points on a rounded circle, the fourth moved by a few ulps: only the first filter cannot
    // decide these, so the later stages are exercised.
    let mut rng = StdRng::seed_from_u64(13);
    let (mut inside, mut outside) = (0, 0);
    for _ in 0..3000 {
        // Coordinates of both signs (inexact differences) or clustered far away (exact ones).
        let (spread, radius) = if rng.random_bool(0.5) {
            (0.5, rng.random_range(1.0..4.0))
        } else {
            (1e3, 2f64.powi(rng.random_range(-12..4)))
        };
        let centre = DVec2::new(
            rng.random_range(-spread..spread),
            rng.random_range(-spread..spread),
        );
        let mut on_circle = || {
            let t: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            centre + radius * DVec2::new(t.cos(), t.sin())
        };
        let (a, b, c, mut d) = (on_circle(), on_circle(), on_circle(), on_circle());
        for _ in 0..rng.random_range(0..4) {
            d.x = d.x.next_up();
        }
        match incircle(a, b, c, d) {
            Ordering::Greater => inside += 1,
            Ordering::Less => outside += 1,
            Ordering::Equal => {}
        }
        check(a, b, c, d);
        check(d, b, c, a);
    }
    assert!(
        inside > 0 && outside > 0,
        "{inside} inside, {outside} outside"
    );
}

#[test]
fn the_double_double_stage_decides_nearly_cocircular_points_rightly() {
    let mut rng = StdRng::seed_from_u64(17);
    let mut decided = 0;
    let samples = 2000;
    for _ in 0..samples {
        let centre = DVec2::new(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5));
        let radius = rng.random_range(1.0..4.0);
        let mut on_circle = || {
            let t: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            centre + radius * DVec2::new(t.cos(), t.sin())
        };
        let (a, b, c, d) = (on_circle(), on_circle(), on_circle(), on_circle());
        let diffs = exact_differences(a, b, c, d);
        let [ax, ay, bx, by, cx, cy] = diffs.map(|(hi, _)| hi);
        let permanent = (ax * ax + ay * ay) * ((bx * cy).abs() + (cx * by).abs())
            + (bx * bx + by * by) * ((cx * ay).abs() + (ax * cy).abs())
            + (cx * cx + cy * cy) * ((ax * by).abs() + (bx * ay).abs());
        let det = incircle_double_double(diffs);
        if det.abs() > INCIRCLE_ERROR_DD * permanent {
            decided += 1;
            let sign = det.partial_cmp(&0.0).unwrap_or(Ordering::Equal);
            assert_eq!(sign, incircle_oracle(a, b, c, d), "{a} {b} {c} {d}");
        }
    }
    assert!(decided > samples / 2, "only {decided} of {samples} decided");
}

/// `(a - p) · (b - p)` in exact integer arithmetic.
fn dot_oracle(p: DVec2, a: DVec2, b: DVec2) -> Ordering {
    let unit = common_unit(&[p, a, b]);
    let s = |x: f64| scaled(x, unit);
    let dot = (s(a.x) - s(p.x)) * (s(b.x) - s(p.x)) + (s(a.y) - s(p.y)) * (s(b.y) - s(p.y));
    dot.sign().cmp(&num_bigint::Sign::NoSign)
}

#[test]
fn dot_sign_agrees_with_oracle_on_random_and_right_angles() {
    let mut rng = StdRng::seed_from_u64(17);
    let mut right = 0;
    for _ in 0..2000 {
        let centre = DVec2::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
        let t: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        let u = DVec2::new(t.cos(), t.sin());
        // p on the circle with diameter ab (up to rounding), or exactly at a right angle on the
        // integer grid: a = (0, 0), b = (2k, 0), p = (k, k).
        let (p, a, b) = if rng.random_bool(0.5) {
            let s: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            (
                centre + DVec2::new(s.cos(), s.sin()),
                centre + u,
                centre - u,
            )
        } else {
            let k = f64::from(rng.random_range(1..1000));
            let shift = DVec2::new(f64::from(rng.random_range(-50..50)), 3.0);
            (
                DVec2::splat(k) + shift,
                shift,
                DVec2::new(2.0 * k, 0.0) + shift,
            )
        };
        right += usize::from(dot_sign(p, a, b) == Ordering::Equal);
        assert_eq!(
            dot_sign(p, a, b),
            dot_oracle(p, a, b),
            "dot_sign({p}, {a}, {b})"
        );
    }
    assert!(right > 0);
}
