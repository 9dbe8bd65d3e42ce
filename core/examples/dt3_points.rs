//! Builds the Delaunay triangulation of N uniform random points in the unit cube (seed 42) and
//! prints the construction time, to compare with CGAL's `cgal_delaunay_points` anchor (which also
//! times the construction only). Usage: `dt3_points [N]` (default 1,000,000).

use delamesh_core::kernel::Point3;
use delamesh_core::triangulation::{Delaunay3, Triangulation};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::time::Instant;

fn main() {
    let n = match std::env::args().nth(1).map(|s| s.parse::<usize>()) {
        None => 1_000_000,
        Some(Ok(n)) => n,
        Some(Err(e)) => {
            eprintln!("dt3_points: N must be a non-negative integer ({e})");
            std::process::exit(2);
        }
    };
    let mut rng = StdRng::seed_from_u64(42);
    let points: Vec<Point3> = (0..n)
        .map(|_| Point3::new(rng.random(), rng.random(), rng.random()))
        .collect();
    let start = Instant::now();
    let dt = match Delaunay3::from_points(&points) {
        Ok(dt) => dt,
        Err(e) => {
            eprintln!("dt3_points: {e}");
            std::process::exit(1);
        }
    };
    let elapsed = start.elapsed().as_secs_f64();
    println!(
        "delamesh_dt3 points={} time_s={elapsed:.3} tets={}",
        dt.num_vertices(),
        dt.num_finite_cells()
    );
}
