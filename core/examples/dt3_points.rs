//! Builds a 3D Delaunay triangulation and prints the construction time, to compare with CGAL's
//! `cgal_delaunay_points` anchor (which also times the construction only).
//!
//! Usage: `dt3_points [N]` — N uniform random points in the unit cube, seed 42 (default 10⁶);
//!        `dt3_points grid S` — the S×S×S integer grid;
//!        `dt3_points file P` — the points of `x y z` lines in file P (as the anchor's second form).

use delamesh_core::kernel::Point3;
use delamesh_core::triangulation::{Delaunay3, Triangulation};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::time::Instant;

fn count(arg: Option<String>, default: usize) -> usize {
    match arg.map(|s| s.parse::<usize>()) {
        None => default,
        Some(Ok(n)) => n,
        Some(Err(e)) => {
            eprintln!("dt3_points: expected a non-negative integer ({e})");
            std::process::exit(2);
        }
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let first = args.next();
    let points: Vec<Point3> = if first.as_deref() == Some("file") {
        let path = args.next().unwrap_or_default();
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
            eprintln!("dt3_points: cannot read {path}: {e}");
            std::process::exit(1);
        });
        let values: Vec<f64> = text
            .split_ascii_whitespace()
            .map(|w| w.parse::<f64>())
            .collect::<Result<_, _>>()
            .unwrap_or_else(|e| {
                eprintln!("dt3_points: {path}: not a list of numbers ({e})");
                std::process::exit(1);
            });
        values
            .chunks_exact(3)
            .map(|c| Point3::new(c[0], c[1], c[2]))
            .collect()
    } else if first.as_deref() == Some("grid") {
        let s = count(args.next(), 100);
        (0..s * s * s)
            .map(|i| Point3::new((i % s) as f64, (i / s % s) as f64, (i / (s * s)) as f64))
            .collect()
    } else {
        let n = count(first, 1_000_000);
        let mut rng = StdRng::seed_from_u64(42);
        (0..n)
            .map(|_| Point3::new(rng.random(), rng.random(), rng.random()))
            .collect()
    };
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
