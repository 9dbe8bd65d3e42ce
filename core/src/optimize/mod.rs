//! Mesh optimisation after refinement: Lloyd and ODT smoothing (off by default), then sliver
//! perturbation and sliver exudation (on by default), as CGAL Mesh_3 orders them, then flips
//! of the slivers those two leave (on by default; see [`Flips`]).
//!
//! Delaunay refinement bounds the radius-edge ratio but not the dihedral angles, so refined
//! meshes keep slivers. The optimisers work on the regular triangulation of the mesh vertices
//! ([`state::Workspace`]): every step moves vertices or changes weights through one primitive
//! that keeps the triangulation regular and the boundary facets exactly as refinement left them
//! (same triangles, patches and subdomains; only peeling a flat cell off the surface flips a
//! surface edge), so the optimised mesh has its surface vertices on the surface, its curve
//! vertices on their curves and its corners in place. The flip step comes last and works on
//! the complex itself: it keeps the boundary facets and adds vertices only inside.
//! It depends only on the complex, the weights of its vertices and the oracle, not on how
//! refinement built them. Every step is deterministic (fixed sweep orders and pseudo-random
//! sequences); only a time limit can make two runs differ.

mod exude;
mod flip;
mod perturb;
mod smooth;
mod state;
#[cfg(test)]
mod tests;

pub use state::WorkspaceError;

use crate::complex::MeshComplex;
use crate::oracle::Oracle;
use crate::quality::Histogram;
use crate::refine::criteria::MeshCriteria;
use crate::refine::{Cancel, Deadline};
use smooth::Smoother;
use state::Workspace;
use std::time::{Duration, Instant};

/// Which optimisers run, and their bounds.
#[derive(Clone, Debug, PartialEq)]
pub struct OptimizeOptions {
    /// Lloyd smoothing (centroidal Voronoi) of the interior vertices.
    pub lloyd: bool,
    /// ODT smoothing of the interior vertices.
    pub odt: bool,
    /// Sliver perturbation.
    pub perturb: bool,
    /// Sliver exudation.
    pub exude: bool,
    /// Which cells the last step replaces by edge removals, 2-3 flips, interior vertex moves
    /// and interior edge splits (see [`flip`]); boundary facets are kept. The cells it
    /// changes are no longer those of a regular triangulation.
    pub flip: Flips,
    /// Wall-time bound of the whole phase (`None`: the steps stop by themselves). A bound makes
    /// the result depend on the machine's speed.
    pub time_limit: Option<Duration>,
    /// Perturbation and exudation work on the cells whose smallest dihedral angle is below
    /// this (degrees). The default, 18°, is where the perturbation's cost stops paying: on
    /// CGAL's sphere, going on to 20° took the smallest angle from 18.0° to 20.0° for a third of
    /// the whole run's time, and CAD parts stop far below 18° anyway.
    pub sliver_bound_deg: f64,
    /// Smoothing sweeps at most (each of Lloyd and ODT).
    pub max_smoothing_sweeps: usize,
    /// The phase stops, keeping the moves made, once this flag is raised (the caller was
    /// interrupted; see [`Limits::cancel`](crate::refine::Limits::cancel)).
    pub cancel: Option<Cancel>,
}

impl Default for OptimizeOptions {
    /// CGAL's defaults: perturbation and exudation, no smoothing, no time limit.
    fn default() -> Self {
        OptimizeOptions {
            lloyd: false,
            odt: false,
            perturb: true,
            exude: true,
            flip: Flips::Slivers,
            time_limit: None,
            sliver_bound_deg: 18.0,
            max_smoothing_sweeps: 20,
            cancel: None,
        }
    }
}

impl OptimizeOptions {
    /// No optimiser at all.
    pub fn none() -> Self {
        OptimizeOptions {
            perturb: false,
            exude: false,
            flip: Flips::Off,
            ..OptimizeOptions::default()
        }
    }

    /// Whether any optimiser runs.
    pub fn any(&self) -> bool {
        self.lloyd || self.odt || self.perturb || self.exude || self.flip == Flips::All
    }

    /// The bound (degrees) below which the flip step replaces cells, if it runs.
    fn flip_bound(&self) -> Option<f64> {
        match self.flip {
            Flips::Off => None,
            Flips::Slivers => {
                (self.perturb || self.exude).then_some(STUCK_FLIP_DEG.min(self.sliver_bound_deg))
            }
            Flips::All => Some(self.sliver_bound_deg),
        }
    }
}

/// Which cells the flip step works on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Flips {
    /// None: the mesh is the regular triangulation the other steps leave.
    Off,
    /// The slivers perturbation and exudation leave (the cells below [`STUCK_FLIP_DEG`] after
    /// them); none when neither runs. Moves and weights cannot mend a sliver whose vertices
    /// are all on curves or on the surface, flips can.
    #[default]
    Slivers,
    /// Every cell below the sliver bound, whichever steps ran before.
    All,
}

/// The flip step after perturbation and exudation works on the cells below this (degrees):
/// the slivers they left (below [`SLIVER_DEG`]) and the cells up to 6° above, whose
/// replacement can free a sliver that no change of its own mends. On liver.inr.gz with CGAL's
/// criteria a bound of 12° left six cells below 10°, 16° one (at 9.2°, which no change mends
/// within the cell size) in 0.04 s of a 0.6 s run; 20° did no better in twice the time.
pub const STUCK_FLIP_DEG: f64 = 16.0;

/// An optimisation step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Lloyd smoothing.
    Lloyd,
    /// ODT smoothing.
    Odt,
    /// Sliver perturbation.
    Perturb,
    /// Sliver exudation.
    Exude,
    /// Edge removals, 2-3 flips, interior vertex moves and edge splits.
    Flip,
}

impl Step {
    /// Lower-case name, as in the options.
    pub fn name(self) -> &'static str {
        match self {
            Step::Lloyd => "lloyd",
            Step::Odt => "odt",
            Step::Perturb => "perturb",
            Step::Exude => "exude",
            Step::Flip => "flip",
        }
    }
}

/// Below this smallest dihedral angle (degrees) a cell is a sliver proper: the share
/// [`Quality::below_10_deg`] counts, and the cells the last perturbation bound still works on once
/// the smallest angle is stuck.
pub(crate) const SLIVER_DEG: f64 = 10.0;

/// Dihedral-angle quality of the mesh at one point of the phase.
#[derive(Clone, Debug, PartialEq)]
pub struct Quality {
    /// Number of tetrahedra.
    pub tets: usize,
    /// Smallest dihedral angle of the mesh (degrees).
    pub min_dihedral_deg: f64,
    /// Tetrahedra whose smallest dihedral angle is below 10°.
    pub below_10_deg: usize,
    /// Smallest dihedral angle of each tetrahedron, in 1° bins over [0°, 90°].
    pub histogram: Histogram,
}

impl Quality {
    fn of(angles: &[f64]) -> Self {
        let mut histogram = Histogram::new(0.0, 90.0, 90);
        for &a in angles {
            histogram.add(a);
        }
        Quality {
            tets: angles.len(),
            min_dihedral_deg: angles.iter().copied().fold(180.0, f64::min),
            below_10_deg: angles.iter().filter(|&&a| a < SLIVER_DEG).count(),
            histogram,
        }
    }
}

/// What one step did.
#[derive(Clone, Debug, PartialEq)]
pub struct StepReport {
    /// The step.
    pub step: Step,
    /// Moves or weight changes kept.
    pub changes: usize,
    /// Sweeps run (smoothing only; 0 otherwise).
    pub sweeps: usize,
    /// Wall time of the step.
    pub time: Duration,
    /// Quality after the step.
    pub quality: Quality,
}

/// Quality before and after each step.
#[derive(Clone, Debug, PartialEq)]
pub struct OptimizeReport {
    /// Quality of the refined mesh.
    pub before: Quality,
    /// The steps run, in order.
    pub steps: Vec<StepReport>,
    /// Why no step ran, if the mesh could not be taken over.
    pub skipped: Option<WorkspaceError>,
}

impl OptimizeReport {
    /// Quality at the end of the phase.
    pub fn after(&self) -> &Quality {
        self.steps.last().map_or(&self.before, |s| &s.quality)
    }
}

/// Optimises `complex`, whose vertex `i` had weight `weights[i]` in the triangulation refinement
/// built (missing weights are 0), over the domain `oracle`; boundary facets the optimisers change
/// meet the facet-distance and facet-size criteria of `criteria`, and no cell gets larger
/// than its cell-size criterion allows. Returns the optimised complex (the
/// input unchanged when it could not be taken over; the report says why).
pub fn optimize(
    complex: MeshComplex,
    weights: &[f64],
    oracle: &dyn Oracle,
    criteria: &MeshCriteria,
    options: &OptimizeOptions,
) -> (MeshComplex, OptimizeReport) {
    let deadline = Deadline::new(options.time_limit, options.cancel.clone());
    let mut report = OptimizeReport {
        before: Quality::of(&angles_of(&complex)),
        steps: Vec::new(),
        skipped: None,
    };
    if !options.any() || complex.tets.is_empty() {
        return (complex, report);
    }
    type Run = fn(&mut Workspace<'_>, &OptimizeOptions, &Deadline) -> (usize, usize);
    let steps: [(Step, bool, Run); 4] = [
        (Step::Lloyd, options.lloyd, |ws, o, d| {
            smooth::smooth(ws, Smoother::Lloyd, o.max_smoothing_sweeps, d)
        }),
        (Step::Odt, options.odt, |ws, o, d| {
            smooth::smooth(ws, Smoother::Odt, o.max_smoothing_sweeps, d)
        }),
        (Step::Perturb, options.perturb, |ws, o, d| {
            (perturb::perturb(ws, o.sliver_bound_deg, d), 0)
        }),
        (Step::Exude, options.exude, |ws, o, d| {
            (exude::exude(ws, o.sliver_bound_deg, d), 0)
        }),
    ];
    let mut complex = complex;
    if steps.iter().any(|s| s.1) {
        match Workspace::new(&complex, weights, oracle, criteria) {
            Ok(mut ws) => {
                for (step, on, run) in steps {
                    if !on || deadline.passed() {
                        continue;
                    }
                    let t = Instant::now();
                    let (changes, sweeps) = run(&mut ws, options, &deadline);
                    report.steps.push(StepReport {
                        step,
                        changes,
                        sweeps,
                        time: t.elapsed(),
                        quality: Quality::of(&ws.min_dihedrals()),
                    });
                }
                complex = ws.into_complex(complex);
            }
            Err(e) => report.skipped = Some(e),
        }
    }
    // Flips need no regular triangulation: they run on the complex, even one the workspace
    // could not take over.
    if let Some(bound) = options.flip_bound()
        && !deadline.passed()
    {
        let t = Instant::now();
        let changes = flip::flip(&mut complex, bound, &criteria.cell.size, &deadline);
        report.steps.push(StepReport {
            step: Step::Flip,
            changes,
            sweeps: 0,
            time: t.elapsed(),
            quality: Quality::of(&angles_of(&complex)),
        });
    }
    (complex, report)
}

/// The smallest dihedral angle of each tetrahedron of `complex` (degrees).
fn angles_of(complex: &MeshComplex) -> Vec<f64> {
    (0..complex.tets.len())
        .map(|t| state::min_dihedral(&complex.tet_points(t)))
        .collect()
}
