//! Fuzzes the filtered predicates against the exact oracle: any finite doubles (subnormal, huge,
//! nearly degenerate) must give the sign of the exact determinant, computed on big integers.
#![no_main]

use delamesh_core::kernel::exact_oracle;
use delamesh_core::kernel::{Point2, Point3, incircle, insphere, orient2d, orient3d};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut words = data.chunks_exact(8).map(|c| {
        let x = f64::from_le_bytes(c.try_into().unwrap_or_default());
        if x.is_finite() { x } else { 0.0 }
    });
    let mut next = || words.next().unwrap_or(0.0);
    let p3: [Point3; 5] = std::array::from_fn(|_| Point3::new(next(), next(), next()));
    let [a, b, c, d, e] = p3;
    assert_eq!(orient3d(a, b, c, d), exact_oracle::orient3d(a, b, c, d));
    assert_eq!(insphere(a, b, c, d, e), exact_oracle::insphere(a, b, c, d, e));
    let q = p3.map(|p| Point2::new(p.x, p.y));
    assert_eq!(orient2d(q[0], q[1], q[2]), exact_oracle::orient2d(q[0], q[1], q[2]));
    assert_eq!(
        incircle(q[0], q[1], q[2], q[3]),
        exact_oracle::incircle(q[0], q[1], q[2], q[3])
    );
});
