//! Insertion order for bulk construction: BRIO rounds, each sorted along a Hilbert curve.
//!
//! Consecutive points of a Hilbert order are close, so the location walk from the previously created
//! cell is short; the random rounds (Amenta–Choi–Rote's Biased Randomized Insertion Order) keep the
//! expected cavity sizes of a random order, which a purely sorted order would lose.

use crate::kernel::Point3;

/// Bits per axis of the Hilbert grid (3 × 21 = 63-bit keys).
const BITS: u32 = 21;
/// Fraction of points kept for the earlier (coarser) rounds at each level.
const ROUND_RATIO: f64 = 0.125;
/// Below this size a round is not split further.
const MIN_ROUND: usize = 64;

/// A seeded permutation source (SplitMix64): deterministic across runs and platforms.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (((self.next() >> 32) * n as u64) >> 32) as usize
    }
}

/// Position along the 3D Hilbert curve of a grid cell (Skilling's transpose algorithm).
fn hilbert_key(mut x: [u32; 3]) -> u64 {
    let m = 1u32 << (BITS - 1);
    // Inverse undo of the curve's reflections and exchanges.
    let mut q = m;
    while q > 1 {
        let p = q - 1;
        for i in 0..3 {
            if x[i] & q != 0 {
                x[0] ^= p;
            } else {
                let t = (x[0] ^ x[i]) & p;
                x[0] ^= t;
                x[i] ^= t;
            }
        }
        q >>= 1;
    }
    // Gray encode.
    x[1] ^= x[0];
    x[2] ^= x[1];
    let mut t = 0;
    let mut q = m;
    while q > 1 {
        if x[2] & q != 0 {
            t ^= q - 1;
        }
        q >>= 1;
    }
    for xi in &mut x {
        *xi ^= t;
    }
    // Interleave the transposed bits, most significant first.
    let mut key = 0u64;
    for b in (0..BITS).rev() {
        for xi in x {
            key = (key << 1) | u64::from((xi >> b) & 1);
        }
    }
    key
}

/// Sorts `indices` along the Hilbert curve of the grid over `[lo, lo + extent]`.
fn hilbert_sort(points: &[Point3], indices: &mut [u32], lo: Point3, scale: Point3) {
    let max = f64::from((1u32 << BITS) - 1);
    let mut keyed: Vec<(u64, u32)> = indices
        .iter()
        .map(|&i| {
            let g = ((points[i as usize] - lo) * scale).clamp(Point3::ZERO, Point3::splat(max));
            (hilbert_key([g.x as u32, g.y as u32, g.z as u32]), i)
        })
        .collect();
    keyed.sort_unstable();
    for (slot, (_, i)) in indices.iter_mut().zip(keyed) {
        *slot = i;
    }
}

/// A BRIO insertion order of `points` (indices into it): a seeded shuffle split into rounds of
/// geometrically growing size, each round Hilbert-sorted. Points must be finite.
pub fn brio_order(points: &[Point3], seed: u64) -> Vec<u32> {
    let n = points.len();
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut rng = SplitMix(seed);
    for i in (1..n).rev() {
        order.swap(i, rng.below(i + 1));
    }
    let (mut lo, mut hi) = (
        Point3::splat(f64::INFINITY),
        Point3::splat(f64::NEG_INFINITY),
    );
    for p in points {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let extent = (hi - lo).max(Point3::splat(f64::MIN_POSITIVE));
    let scale = Point3::splat(f64::from((1u32 << BITS) - 1)) / extent;
    let mut end = n;
    while end > 0 {
        let start = if end <= MIN_ROUND {
            0
        } else {
            (end as f64 * ROUND_RATIO) as usize
        };
        hilbert_sort(points, &mut order[start..end], lo, scale);
        end = start;
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hilbert_keys_of_a_small_grid_are_a_path_of_unit_steps() {
        // Along the curve, consecutive cells of the grid are face neighbours.
        let side = 1u32 << BITS;
        let step = side / 8;
        let mut cells = Vec::new();
        for x in 0..8 {
            for y in 0..8 {
                for z in 0..8 {
                    let k = hilbert_key([x * step, y * step, z * step]);
                    cells.push((k, [x as i32, y as i32, z as i32]));
                }
            }
        }
        cells.sort_unstable();
        for w in cells.windows(2) {
            let d: i32 = (0..3).map(|i| (w[0].1[i] - w[1].1[i]).abs()).sum();
            assert_eq!(d, 1, "{:?} -> {:?}", w[0].1, w[1].1);
        }
    }

    #[test]
    fn brio_order_is_a_permutation() {
        let pts: Vec<Point3> = (0..1000)
            .map(|i| Point3::new((i % 10) as f64, (i / 10 % 10) as f64, (i / 100) as f64))
            .collect();
        let mut order = brio_order(&pts, 7);
        order.sort_unstable();
        assert!(order.iter().enumerate().all(|(i, &j)| i as u32 == j));
    }
}
