//! Insertion order for bulk construction: BRIO rounds, each sorted along a Hilbert curve.
//!
//! Consecutive points of a Hilbert order are close, so the location walk from the previously created
//! cell is short; the random rounds (Amenta–Choi–Rote's Biased Randomized Insertion Order) keep the
//! expected cavity sizes of a random order, which a purely sorted order would lose.

use crate::kernel::Point3;
use crate::kernel::perturbation::lex_cmp;

/// Bits per axis of the Hilbert grid (3 × 21 = 63-bit keys).
const BITS: u32 = 21;
/// Fraction of points kept for the earlier (coarser) rounds at each level.
const ROUND_RATIO: f64 = 0.125;
/// Below this size a round is not split further.
const MIN_ROUND: usize = 64;
/// Point sets at least this large are sorted on two threads.
const PARALLEL_SORT: usize = 1 << 16;

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
}

/// Position along the 3D Hilbert curve of a grid cell (Skilling's transpose algorithm).
fn hilbert_key(mut x: [u32; 3]) -> u64 {
    let m = 1u32 << (BITS - 1);
    // Inverse undo of the curve's reflections and exchanges.
    let mut q = m;
    while q > 1 {
        let p = q - 1;
        for i in 0..3 {
            // Branch-free form of: if bit q of x[i] is set, invert the low bits of x[0];
            // otherwise exchange the low bits of x[0] and x[i].
            let set = ((x[i] & q) != 0) as u32;
            let invert = p & set.wrapping_neg();
            let t = (x[0] ^ x[i]) & p & !invert;
            x[0] ^= t ^ invert;
            x[i] ^= t;
        }
        q >>= 1;
    }
    // Gray encode.
    x[1] ^= x[0];
    x[2] ^= x[1];
    let mut t = 0;
    let mut q = m;
    while q > 1 {
        // Branch-free form of: if bit q of x[2] is set, invert the bits below q of t.
        t ^= (q - 1) & (((x[2] & q) != 0) as u32).wrapping_neg();
        q >>= 1;
    }
    for xi in &mut x {
        *xi ^= t;
    }
    // Interleave the transposed bits, most significant first: bit b of x[0], x[1], x[2] lands
    // at 3b + 2, 3b + 1, 3b.
    (spread_bits(x[0]) << 2) | (spread_bits(x[1]) << 1) | spread_bits(x[2])
}

/// Moves bit b of a 21-bit value to bit 3b (the classic shift-and-mask bit spreading).
fn spread_bits(x: u32) -> u64 {
    let mut v = u64::from(x) & 0x1f_ffff;
    v = (v | (v << 32)) & 0x001f_0000_0000_ffff;
    v = (v | (v << 16)) & 0x001f_0000_ff00_00ff;
    v = (v | (v << 8)) & 0x100f_00f0_0f00_f00f;
    v = (v | (v << 4)) & 0x10c3_0c30_c30c_30c3;
    v = (v | (v << 2)) & 0x1249_2492_4924_9249;
    v
}

/// The Hilbert grid over the bounding box of a point set.
struct HilbertGrid {
    lo: Point3,
    scale: Point3,
}

impl HilbertGrid {
    fn new(points: &[Point3]) -> Self {
        let (mut lo, mut hi) = (
            Point3::splat(f64::INFINITY),
            Point3::splat(f64::NEG_INFINITY),
        );
        for p in points {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        let extent = (hi - lo).max(Point3::splat(f64::MIN_POSITIVE));
        HilbertGrid {
            lo,
            scale: Point3::splat(f64::from((1u32 << BITS) - 1)) / extent,
        }
    }

    fn key(&self, p: Point3) -> u64 {
        let max = f64::from((1u32 << BITS) - 1);
        let g = ((p - self.lo) * self.scale).clamp(Point3::ZERO, Point3::splat(max));
        hilbert_key([g.x as u32, g.y as u32, g.z as u32])
    }
}

/// Indices of `points` in Hilbert-curve order. Ties (points in one grid cell) are broken by the
/// lexicographic order of coordinates, then by index, so equal points end up adjacent. Large sets
/// are keyed and sorted in two halves on two threads, then merged: the order is total, so the
/// result is the same.
pub fn hilbert_order(points: &[Point3]) -> Vec<u32> {
    let grid = HilbertGrid::new(points);
    let before = |a: &(u64, u32), b: &(u64, u32)| {
        a.0.cmp(&b.0)
            .then_with(|| lex_cmp(points[a.1 as usize], points[b.1 as usize]))
            .then(a.1.cmp(&b.1))
    };
    let sorted = |range: std::ops::Range<usize>| {
        let mut keyed: Vec<(u64, u32)> = range.map(|i| (grid.key(points[i]), i as u32)).collect();
        keyed.sort_unstable_by(before);
        keyed
    };
    let n = points.len();
    // Small sets (the optimisers' star re-triangulations) skip the thread count: it reads the
    // cgroup files on every call.
    if n < PARALLEL_SORT || !two_threads() {
        return sorted(0..n).into_iter().map(|(_, i)| i).collect();
    }
    let (a, b) = std::thread::scope(|scope| {
        let upper = scope.spawn(|| sorted(n / 2..n));
        let lower = sorted(0..n / 2);
        let upper = upper
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (lower, upper)
    });
    let mut order = Vec::with_capacity(n);
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if before(&b[j], &a[i]).is_lt() {
            order.push(b[j].1);
            j += 1;
        } else {
            order.push(a[i].1);
            i += 1;
        }
    }
    order.extend(a[i..].iter().chain(&b[j..]).map(|k| k.1));
    order
}

/// Whether a second thread may help.
fn two_threads() -> bool {
    std::thread::available_parallelism().is_ok_and(|t| t.get() > 1)
}

/// `points` in the given order, gathered on two threads for large sets (the reads are scattered,
/// so each costs a cache miss).
pub fn gather(points: &[Point3], order: &[u32]) -> Vec<Point3> {
    let copy = |out: &mut [Point3], order: &[u32]| {
        for (o, &i) in out.iter_mut().zip(order) {
            *o = points[i as usize];
        }
    };
    let mut out = vec![Point3::ZERO; order.len()];
    if order.len() < PARALLEL_SORT || !two_threads() {
        copy(&mut out, order);
    } else {
        let half = order.len() / 2;
        let (lower, upper) = out.split_at_mut(half);
        std::thread::scope(|scope| {
            scope.spawn(|| copy(upper, &order[half..]));
            copy(lower, &order[..half]);
        });
    }
    out
}

/// A BRIO order of the positions `0..n` along a space-filling curve: rounds of geometrically
/// growing size, each in curve order, returned with the rounds' ranges in insertion order. Each
/// position draws its round from a seeded generator (the last round with probability 7/8, the
/// one before with 7/64, …), so rounds come out sorted from a counting sort.
pub fn brio_rounds(n: usize, seed: u64) -> (Vec<u32>, Vec<std::ops::Range<usize>>) {
    let mut levels = 1;
    let mut size = n;
    while size > MIN_ROUND {
        size = (size as f64 * ROUND_RATIO) as usize;
        levels += 1;
    }
    let mut rng = SplitMix(seed);
    // Level 0 is the last round; a level is kept with probability 1/8 per step up.
    let level: Vec<u8> = (0..n)
        .map(|_| ((rng.next().trailing_zeros() / 3) as usize).min(levels - 1) as u8)
        .collect();
    let mut start = vec![0usize; levels + 1];
    for &l in &level {
        start[levels - 1 - l as usize + 1] += 1;
    }
    for k in 0..levels {
        start[k + 1] += start[k];
    }
    let rounds: Vec<std::ops::Range<usize>> = (0..levels).map(|k| start[k]..start[k + 1]).collect();
    let mut order = vec![0u32; n];
    for (rank, &l) in level.iter().enumerate() {
        let slot = &mut start[levels - 1 - l as usize];
        order[*slot] = rank as u32;
        *slot += 1;
    }
    (order, rounds)
}

/// A BRIO insertion order of `points` (indices into it), each round in Hilbert order.
/// Points must be finite.
pub fn brio_order(points: &[Point3], seed: u64) -> Vec<u32> {
    let curve = hilbert_order(points);
    let (ranks, _) = brio_rounds(points.len(), seed);
    ranks.into_iter().map(|r| curve[r as usize]).collect()
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
    fn bit_spreading_matches_a_bit_by_bit_interleave() {
        let mut x = 0x0001_2345_u32;
        for _ in 0..1000 {
            x = x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let v = x >> 11;
            let slow = (0..BITS).fold(0u64, |acc, b| acc | (u64::from((v >> b) & 1) << (3 * b)));
            assert_eq!(spread_bits(v), slow, "{v:#x}");
        }
    }

    #[test]
    fn brio_rounds_are_sorted_and_grow_geometrically() {
        let (order, rounds) = brio_rounds(100_000, 3);
        assert_eq!(rounds.first().map(|r| r.start), Some(0));
        assert_eq!(rounds.last().map(|r| r.end), Some(100_000));
        for w in rounds.windows(2) {
            assert_eq!(w[0].end, w[1].start);
        }
        for r in &rounds {
            assert!(order[r.clone()].is_sorted());
        }
        let last = rounds.last().unwrap().len() as f64;
        assert!((last / 100_000.0 - 0.875).abs() < 0.01, "last round {last}");
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert!(sorted.iter().enumerate().all(|(i, &j)| i as u32 == j));
    }

    #[test]
    fn hilbert_order_on_two_threads_equals_one_sort() {
        let pts: Vec<Point3> = (0..PARALLEL_SORT as u32 + 999)
            .map(|i| {
                let h = i.wrapping_mul(2_654_435_761);
                Point3::new(f64::from(h % 97), f64::from(h / 97 % 89), f64::from(i % 7))
            })
            .collect();
        let grid = HilbertGrid::new(&pts);
        let mut expected: Vec<u32> = (0..pts.len() as u32).collect();
        expected.sort_by(|&a, &b| {
            grid.key(pts[a as usize])
                .cmp(&grid.key(pts[b as usize]))
                .then_with(|| lex_cmp(pts[a as usize], pts[b as usize]))
                .then(a.cmp(&b))
        });
        assert_eq!(hilbert_order(&pts), expected);
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
