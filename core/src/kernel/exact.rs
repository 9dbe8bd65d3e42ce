//! Exact signs for any finite doubles, including subnormal and huge ones.
//!
//! Shewchuk's expansion arithmetic (the `robust` crate) is exact only while no product underflows
//! or overflows: the rounding error of `a · b` is lost once it falls below 2⁻¹⁰⁷⁴. A unit cube with
//! one vertex at x = 1e-320 is enough to make `robust` call a non-degenerate orientation zero.
//! Every exact stage of the kernel therefore asks [`expansions_are_exact`] first and, when the
//! inputs' bits span too wide a range, evaluates the determinant on big integers instead (each
//! double is an integer times a power of two, so scaling a column by a power of two makes every
//! entry an integer and keeps the sign).

use super::Sign;
use num_bigint::BigInt;

/// Smallest exponent of a product's lowest bit that expansion arithmetic keeps: the last bit of a
/// subnormal, with a margin for the sums of products.
const LOWEST_KEPT_BIT: i32 = -1000;
/// Largest exponent of a product's highest bit that stays clear of overflow, with a margin for
/// the sums of up to a few hundred products.
const HIGHEST_SAFE_BIT: i32 = 1000;

/// Whether the expansion arithmetic of a polynomial of `degree` in differences of `values` is
/// exact: every product of `degree` of them keeps its lowest bit and does not overflow.
pub(crate) fn expansions_are_exact(values: &[f64], degree: i32) -> bool {
    let (mut low, mut high) = (i32::MAX, i32::MIN);
    for &x in values {
        if x == 0.0 {
            continue;
        }
        let (m, e) = dyadic(x);
        let m = m.unsigned_abs();
        low = low.min(e + m.trailing_zeros() as i32);
        high = high.max(e + 64 - m.leading_zeros() as i32);
    }
    // Differences keep their lowest bit above the inputs' lowest and gain one bit on top.
    low == i32::MAX || (degree * low >= LOWEST_KEPT_BIT && degree * (high + 1) <= HIGHEST_SAFE_BIT)
}

/// `x = mantissa · 2^exponent` exactly (zero has mantissa 0).
pub(crate) fn dyadic(x: f64) -> (i64, i32) {
    let bits = x.to_bits();
    let sign = if bits >> 63 == 1 { -1 } else { 1 };
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let frac = (bits & ((1u64 << 52) - 1)) as i64;
    let (m, e) = if biased == 0 {
        (frac, -1074)
    } else {
        (frac | (1i64 << 52), biased - 1075)
    };
    (sign * m, e)
}

/// `x · 2^-unit` as an exact integer; `unit` must not exceed the exponent of `x`.
pub(crate) fn scaled(x: f64, unit: i32) -> BigInt {
    let (m, e) = dyadic(x);
    BigInt::from(m) << ((e - unit) as usize)
}

/// The smallest exponent of the non-zero values (0 when all are zero), capped at 0.
pub(crate) fn common_unit(values: impl IntoIterator<Item = f64>) -> i32 {
    values
        .into_iter()
        .filter(|&x| x != 0.0)
        .map(|x| dyadic(x).1)
        .min()
        .unwrap_or(0)
        .min(0)
}

/// The sign of a big integer.
pub(crate) fn sign_of(x: &BigInt) -> Sign {
    match x.sign() {
        num_bigint::Sign::Plus => Sign::Positive,
        num_bigint::Sign::Minus => Sign::Negative,
        num_bigint::Sign::NoSign => Sign::Zero,
    }
}

/// Rows of points (given as coordinate slices) relative to the last one, as exact integers in a
/// common power-of-two unit, each row followed by its squared length when `lifted`.
fn relative_rows<const D: usize>(points: &[[f64; D]], lifted: bool) -> Vec<Vec<BigInt>> {
    let unit = common_unit(points.iter().flatten().copied());
    let ints: Vec<Vec<BigInt>> = points
        .iter()
        .map(|p| p.iter().map(|&x| scaled(x, unit)).collect())
        .collect();
    let (last, rows) = ints.split_last().expect("at least one point");
    rows.iter()
        .map(|r| {
            let mut row: Vec<BigInt> = r.iter().zip(last).map(|(a, b)| a - b).collect();
            if lifted {
                let square = row.iter().map(|v| v * v).sum();
                row.push(square);
            }
            row
        })
        .collect()
}

/// Determinant of a small square matrix by cofactor expansion along the first row.
pub(crate) fn det(m: &[Vec<&BigInt>]) -> BigInt {
    match m.len() {
        0 => BigInt::from(1),
        1 => m[0][0].clone(),
        2 => m[0][0] * m[1][1] - m[0][1] * m[1][0],
        n => {
            let mut total = BigInt::from(0);
            for col in 0..n {
                let minor: Vec<Vec<&BigInt>> = m[1..]
                    .iter()
                    .map(|row| {
                        row.iter()
                            .enumerate()
                            .filter(|&(c, _)| c != col)
                            .map(|(_, v)| *v)
                            .collect()
                    })
                    .collect();
                let term = m[0][col] * det(&minor);
                if col % 2 == 0 {
                    total += term;
                } else {
                    total -= term;
                }
            }
            total
        }
    }
}

fn det_of(rows: &[Vec<BigInt>]) -> Sign {
    let refs: Vec<Vec<&BigInt>> = rows.iter().map(|r| r.iter().collect()).collect();
    sign_of(&det(&refs))
}

/// Exact sign of `det[a−c; b−c]` (the orientation of three planar points).
pub(crate) fn orient2d_big(p: [[f64; 2]; 3]) -> Sign {
    det_of(&relative_rows(&p, false))
}

/// Exact sign of `det[a−d; b−d; c−d]`.
pub(crate) fn orient3d_big(p: [[f64; 3]; 4]) -> Sign {
    det_of(&relative_rows(&p, false))
}

/// Exact sign of the lifted in-circle determinant `det[q−d, |q−d|²]` for `q = a, b, c`.
pub(crate) fn incircle_big(p: [[f64; 2]; 4]) -> Sign {
    det_of(&relative_rows(&p, true))
}

/// Exact sign of the lifted in-sphere determinant `det[q−e, |q−e|²]` for `q = a, b, c, d`.
pub(crate) fn insphere_big(p: [[f64; 3]; 5]) -> Sign {
    det_of(&relative_rows(&p, true))
}

/// The four predicates on big integers only: slow, exact for any finite doubles. The oracle the
/// tests and the fuzz target compare the filtered predicates with.
pub mod exact_oracle {
    use super::super::{Point2, Point3, Sign};

    /// Exact [`orient2d`](crate::kernel::orient2d).
    pub fn orient2d(a: Point2, b: Point2, c: Point2) -> Sign {
        super::orient2d_big([a, b, c].map(|p| p.to_array()))
    }

    /// Exact [`orient3d`](crate::kernel::orient3d).
    pub fn orient3d(a: Point3, b: Point3, c: Point3, d: Point3) -> Sign {
        super::orient3d_big([a, b, c, d].map(|p| p.to_array()))
    }

    /// Exact [`incircle`](crate::kernel::incircle).
    pub fn incircle(a: Point2, b: Point2, c: Point2, d: Point2) -> Sign {
        super::incircle_big([a, b, c, d].map(|p| p.to_array()))
    }

    /// Exact [`insphere`](crate::kernel::insphere).
    pub fn insphere(a: Point3, b: Point3, c: Point3, d: Point3, e: Point3) -> Sign {
        super::insphere_big([a, b, c, d, e].map(|p| p.to_array()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::XorShift;

    /// Points mixing unit, subnormal and tiny coordinates, nudged by ulps: the filtered
    /// predicates must agree with the big-integer oracle everywhere.
    #[test]
    fn filtered_predicates_match_the_oracle_across_magnitudes() {
        use super::super::{Point2, Point3, incircle, insphere, orient2d, orient3d};
        let mut rng = XorShift::new(0x51a7_e5c0_ffee_1234);
        let mut next = move || rng.next_u64();
        let scales = [1.0, 1e-320, 1e-200, 1e-30, 1e150, 0.0];
        for _ in 0..4000 {
            let mut coord = || {
                let r = next();
                let base = (r % 3) as f64 * scales[(r >> 8) as usize % scales.len()];
                f64::from_bits(base.to_bits() + (r >> 40 & 1))
            };
            let p: [Point3; 5] = std::array::from_fn(|_| Point3::new(coord(), coord(), coord()));
            let [a, b, c, d, e] = p;
            assert_eq!(
                orient3d(a, b, c, d),
                exact_oracle::orient3d(a, b, c, d),
                "{p:?}"
            );
            assert_eq!(
                insphere(a, b, c, d, e),
                exact_oracle::insphere(a, b, c, d, e),
                "{p:?}"
            );
            let q = p.map(|p| Point2::new(p.x, p.y));
            assert_eq!(
                orient2d(q[0], q[1], q[2]),
                exact_oracle::orient2d(q[0], q[1], q[2])
            );
            assert_eq!(
                incircle(q[0], q[1], q[2], q[3]),
                exact_oracle::incircle(q[0], q[1], q[2], q[3]),
                "{q:?}"
            );
        }
    }

    /// Coordinates near the overflow threshold of each determinant: the filters' error bounds
    /// stay finite while a term overflows to infinity, which must not decide a sign.
    #[test]
    fn an_overflowing_term_does_not_decide_a_sign() {
        use super::super::{Point3, StaticFilter, insphere, orient3d};
        let mut rng = XorShift::new(0x2545_f491_4f6c_dd1d);
        let mut unit = move || rng.next_f64() * 2.0 - 1.0;
        for (scale, five) in [(1e61, true), (3e61, true), (1e62, true), (3e102, false)] {
            for _ in 0..500 {
                let p: [Point3; 5] = std::array::from_fn(|_| {
                    Point3::new(unit() * scale, unit() * scale, unit() * scale)
                });
                let [a, b, c, d, e] = p;
                let mut filter = StaticFilter::default();
                p.iter().for_each(|&q| filter.include(q));
                let expected = exact_oracle::orient3d(a, b, c, d);
                assert_eq!(orient3d(a, b, c, d), expected, "{p:?}");
                assert_eq!(filter.orient3d(a, b, c, d), expected, "{p:?}");
                if five {
                    let expected = exact_oracle::insphere(a, b, c, d, e);
                    assert_eq!(insphere(a, b, c, d, e), expected, "{p:?}");
                    assert_eq!(filter.insphere(a, b, c, d, e), expected, "{p:?}");
                }
            }
        }
    }

    #[test]
    fn subnormal_and_huge_values_leave_the_expansion_range() {
        assert!(expansions_are_exact(&[0.0, 1.0, 0.1, -3.5, 1e-20], 5));
        assert!(!expansions_are_exact(&[1.0, 1e-320], 3));
        assert!(!expansions_are_exact(&[1.0, 1e-200], 5));
        assert!(!expansions_are_exact(&[1e250, 1.0], 3));
        assert!(expansions_are_exact(&[0.0, 0.0], 5));
    }

    #[test]
    fn big_integer_signs_see_a_subnormal_offset() {
        let t = 1e-320;
        // The triangle (t, 0), (1, 0), (0, 0.3): area t·0.3-ish, positive, but every product
        // involving t underflows in floating point.
        assert_eq!(
            orient2d_big([[0.0, 0.3], [t, 0.0], [1.0, 0.0]]),
            Sign::Positive
        );
        assert_eq!(
            orient2d_big([[t, 0.0], [2.0 * t, 0.0], [0.0, 0.0]]),
            Sign::Zero
        );
        // A corner tet with its legs `t`, `y` and `z` long along the axes.
        let tet = |y: f64, z: f64| [[t, 0.0, 0.0], [0.0, y, 0.0], [0.0, 0.0, z], [0.0; 3]];
        assert_eq!(orient3d_big(tet(0.3, 0.7)), Sign::Positive);
        // The centre of the unit square's circumcircle is inside; a point beyond it is not.
        let sq = |x: f64, y: f64| [x, y];
        let c = [sq(t, 0.0), sq(1.0, 0.0), sq(1.0, 1.0)];
        assert_eq!(
            incircle_big([c[0], c[1], c[2], sq(0.5, 0.5)]),
            Sign::Positive
        );
        assert_eq!(
            incircle_big([c[0], c[1], c[2], sq(3.0, 3.0)]),
            Sign::Negative
        );
        let s = tet(1.0, 1.0);
        assert_eq!(
            insphere_big([s[0], s[1], s[2], s[3], [0.2, 0.2, 0.2]]),
            Sign::Positive
        );
        assert_eq!(
            insphere_big([s[0], s[1], s[2], s[3], [2.0, 2.0, 2.0]]),
            Sign::Negative
        );
    }
}
