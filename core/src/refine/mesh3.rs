//! The 3D mesher of the thesis (ch. 3): initial surface points, then the level stack
//! [surface facets, cells] over a Delaunay triangulation, then the complex.

use super::cells::CellLevel;
use super::criteria::MeshCriteria;
use super::engine::{Engine, Limits, Progress, RefineError, RefineStats};
use super::facets::SurfaceLevel;
use crate::complex::MeshComplex;
use crate::oracle::Oracle;
use crate::triangulation::{Delaunay3, Triangulation, TriangulationError};
use std::time::{Duration, Instant};

#[derive(Clone, Debug)]
pub struct MeshOptions {
    pub criteria: MeshCriteria,
    pub limits: Limits,
    /// On a tripped guard, return the mesh reached so far inside the error.
    pub keep_partial: bool,
}

/// Wall time of each phase.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhaseTimes {
    pub initial_points: Duration,
    pub refinement: Duration,
    pub complex: Duration,
}

#[derive(Debug)]
pub struct MeshOutcome {
    pub complex: MeshComplex,
    pub stats: RefineStats,
    pub times: PhaseTimes,
}

#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("the domain gave no initial surface points (is the boundary empty?)")]
    NoInitialPoints,
    #[error("an initial surface point was refused by the triangulation: {0}")]
    InitialPoint(TriangulationError),
    #[error("{source}")]
    Refinement {
        source: RefineError,
        /// The mesh reached when the guard tripped, if it was asked for.
        partial: Option<Box<MeshComplex>>,
    },
}

/// Mesh the domain described by `oracle`.
pub fn mesh_domain(
    oracle: &dyn Oracle,
    options: &MeshOptions,
    progress: &mut dyn FnMut(&Progress),
) -> Result<MeshOutcome, MeshError> {
    let start = Instant::now();
    let mut tr = Delaunay3::new();
    let mut surface = SurfaceLevel::new(oracle, options.criteria.facet.clone());
    let mut cells = CellLevel::new(oracle, options.criteria.cell.clone());
    let initial = oracle.initial_points();
    if initial.is_empty() {
        return Err(MeshError::NoInitialPoints);
    }
    for p in initial {
        let v = tr
            .insert(p.point)
            .map_err(MeshError::InitialPoint)?
            .vertex();
        surface.mark_on_surface(v);
    }
    let mut times = PhaseTimes {
        initial_points: start.elapsed(),
        ..PhaseTimes::default()
    };

    let start = Instant::now();
    let result = {
        let mut engine = Engine::new(options.limits);
        engine.push_level(&mut surface).push_level(&mut cells);
        engine.refine(&mut tr, progress)
    };
    times.refinement = start.elapsed();

    let start = Instant::now();
    match result {
        Ok(stats) => {
            let complex = MeshComplex::from_refinement(&tr, &surface, &cells);
            times.complex = start.elapsed();
            Ok(MeshOutcome {
                complex,
                stats,
                times,
            })
        }
        Err(source) => {
            let partial = options
                .keep_partial
                .then(|| Box::new(MeshComplex::from_refinement(&tr, &surface, &cells)));
            Err(MeshError::Refinement { source, partial })
        }
    }
}
