//! Times `delamesh mesh2d`'s meshing in-process, the way `core/benches/triangle_compare.py` times
//! Triangle: the best of repeated runs on the same input (at least 5, more until half a second has
//! passed, as Python's `timeit` does), so that both sides are measured warm. A fresh process pays
//! page faults for its code and first allocations, which Triangle's in-process runs do not.
//!
//! Usage: `mesh2d_poly FILE MIN_ANGLE [MAX_AREA]` (a `.poly` file, or polylines as `mesh2d` reads).
//! Prints one line: `best_s=… triangles=… smallest_angle=…`.

use delamesh_core::mesh2d::mesher::{MeshOptions, mesh};
use std::path::PathBuf;
use std::process::exit;
use std::time::Instant;

/// The repetition policy, the same as the script's for Triangle.
const MIN_RUNS: usize = 5;
const MAX_RUNS: usize = 2000;
const BUDGET_S: f64 = 0.5;

fn number(arg: Option<String>, what: &str) -> Option<f64> {
    let text = arg?;
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() => Some(x),
        _ => {
            eprintln!("mesh2d_poly: {what} must be a finite number, not {text:?}");
            exit(2);
        }
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next().map(PathBuf::from) else {
        eprintln!("usage: mesh2d_poly FILE MIN_ANGLE [MAX_AREA]");
        exit(2);
    };
    let options = MeshOptions {
        min_angle_deg: number(args.next(), "MIN_ANGLE").unwrap_or(20.0),
        max_area: number(args.next(), "MAX_AREA"),
        max_vertices: 10_000_000,
    };
    let pslg = delamesh_formats::pslg::read_pslg(&path).unwrap_or_else(|e| {
        eprintln!("mesh2d_poly: {e}");
        exit(1);
    });
    let mut best = f64::INFINITY;
    let mut result = None;
    let budget = Instant::now();
    for run in 0.. {
        if run >= MAX_RUNS || (run >= MIN_RUNS && budget.elapsed().as_secs_f64() > BUDGET_S) {
            break;
        }
        let start = Instant::now();
        let m = mesh(&pslg, &options).unwrap_or_else(|e| {
            eprintln!("mesh2d_poly: {}: {e}", path.display());
            exit(1);
        });
        best = best.min(start.elapsed().as_secs_f64());
        result = Some(m);
    }
    let Some(m) = result else { return };
    let smallest = m.smallest_angle_deg();
    println!(
        "best_s={best:.6} triangles={} smallest_angle={smallest:.2}",
        m.triangles.len()
    );
}
