//! Insertion order for bulk input: a biased randomized insertion order (BRIO) whose rounds are
//! sorted along a Hilbert curve, so consecutive points are close (short walks, warm caches) while the
//! rounds keep the randomized expected-case bounds.

use crate::random::XorShift;
use glam::DVec2;

/// Position of the grid cell `(x, y)` along the Hilbert curve of order 16.
fn hilbert_index(mut x: u32, mut y: u32) -> u64 {
    const N: u32 = 1 << 16;
    let mut d = 0u64;
    let mut s = N / 2;
    while s > 0 {
        let rx = u32::from(x & s > 0);
        let ry = u32::from(y & s > 0);
        d += u64::from(s) * u64::from(s) * u64::from((3 * rx) ^ ry);
        if ry == 0 {
            if rx == 1 {
                x = N - 1 - x;
                y = N - 1 - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        s /= 2;
    }
    d
}

/// Indices of `points` in BRIO order with Hilbert-sorted rounds.
pub fn brio_order(points: &[DVec2]) -> Vec<usize> {
    let n = points.len();
    let mut idx: Vec<usize> = (0..n).collect();
    if n < 2 {
        return idx;
    }
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in points {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let ext = (hi - lo).max(DVec2::splat(f64::MIN_POSITIVE));
    let scale = DVec2::splat(f64::from((1u32 << 16) - 1)) / ext;
    let key = |i: usize| {
        let g = ((points[i] - lo) * scale).clamp(DVec2::ZERO, DVec2::splat(65535.0));
        hilbert_index(g.x as u32, g.y as u32)
    };
    let mut rng = XorShift::new(0x9E37_79B9_7F4A_7C15);
    for i in (1..n).rev() {
        idx.swap(i, rng.below(i + 1));
    }
    // Rounds: the last round is the second half, the one before it the previous quarter, ...
    let mut end = n;
    let mut bounds = Vec::new();
    while end > 64 {
        let start = end / 2;
        bounds.push((start, end));
        end = start;
    }
    bounds.push((0, end));
    for (start, end) in bounds {
        idx[start..end].sort_by_cached_key(|&i| key(i));
    }
    idx
}
