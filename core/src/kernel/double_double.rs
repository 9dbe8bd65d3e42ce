//! Error-free transformations and double-double arithmetic: the building blocks of the exact
//! predicates' middle stages, which settle nearly every sign the first floating-point filter
//! leaves open for a fraction of the cost of exact expansions.

/// `a * b` as an exact unevaluated sum `hi + lo`.
#[inline(always)]
pub(crate) fn two_product(a: f64, b: f64) -> (f64, f64) {
    let hi = a * b;
    (hi, a.mul_add(b, -hi))
}

/// `a - b` as an exact unevaluated sum `hi + lo` (Knuth's two-difference).
#[inline(always)]
pub(crate) fn two_diff(a: f64, b: f64) -> (f64, f64) {
    let x = a - b;
    let bv = a - x;
    let av = x + bv;
    (x, (a - av) + (bv - b))
}

/// `a + b` as an exact unevaluated sum `hi + lo` (Knuth's two-sum).
#[inline(always)]
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    (x, (a - av) + (b - bv))
}

/// `a + b` exactly when `|a| ≥ |b|` or `a` is zero (Dekker's fast two-sum).
#[inline(always)]
pub(crate) fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    (x, b - (x - a))
}

/// Double-double sum (the accurate algorithm: relative error at most 3u², u = 2⁻⁵³).
#[inline(always)]
pub(crate) fn dd_add(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let (s, e) = two_sum(a.0, b.0);
    let (t, f) = two_sum(a.1, b.1);
    let (s, e) = fast_two_sum(s, e + t);
    fast_two_sum(s, e + f)
}

/// Double-double product (relative error at most 7u²).
#[inline(always)]
pub(crate) fn dd_mul(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let (p, e) = two_product(a.0, b.0);
    fast_two_sum(p, e + (a.0 * b.1 + a.1 * b.0))
}

#[inline(always)]
pub(crate) fn dd_neg(a: (f64, f64)) -> (f64, f64) {
    (-a.0, -a.1)
}

/// Double-double difference.
#[inline(always)]
pub(crate) fn dd_sub(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    dd_add(a, dd_neg(b))
}
