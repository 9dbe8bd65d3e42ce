//! The one pseudo-random sequence of the workspace: Marsaglia's xorshift64, fixed by its seed so
//! that every run (insertion orders, perturbation directions, randomized tests) repeats exactly.

/// Deterministic xorshift64 generator: the same seed always gives the same sequence.
#[derive(Clone, Copy, Debug)]
pub struct XorShift(u64);

impl XorShift {
    /// The sequence of `seed` (0, which xorshift cannot leave, is taken as 1).
    pub fn new(seed: u64) -> Self {
        Self(seed.max(1))
    }

    /// The next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }

    /// Uniform in [0, 1), from the top 53 bits.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `0..n` (n > 0); the tiny modulo bias is irrelevant for shuffling.
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sequence_is_fixed_by_the_seed_and_stays_in_range() {
        let (mut a, mut b) = (XorShift::new(42), XorShift::new(42));
        let first: Vec<u64> = (0..100).map(|_| a.next_u64()).collect();
        assert!(first.iter().all(|&x| x == b.next_u64() && x != 0));
        assert_ne!(XorShift::new(43).next_u64(), first[0]);
        assert!((0..1000).all(|_| (0.0..1.0).contains(&a.next_f64()) && a.below(7) < 7));
        assert_eq!(XorShift::new(0).next_u64(), XorShift::new(1).next_u64());
    }
}
