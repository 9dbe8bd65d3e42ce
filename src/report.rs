//! The report of a meshing run: counts, timings, quality, volume per subdomain, topology of the
//! boundary and, for an input triangle surface, how closely the mesh approximates it, as plain
//! data (serialisable with the `serde` feature; the command line writes it as JSON with
//! `--report`).

use delamesh_core::complex::{MeshComplex, VertexDimension};
use delamesh_core::kernel::Point3;
use delamesh_core::optimize::{OptimizeReport, Quality};
use delamesh_core::oracle::Oracle;
use delamesh_core::quality::{self, TetQuality};
use delamesh_core::refine::RefineStats;
use delamesh_core::refine::criteria::MeshCriteria;
use delamesh_polyhedral::{PolyhedralOracle, TriangleTree};
use std::time::Duration;

#[cfg(feature = "serde")]
use serde::Serialize;

/// Everything `--report` says about a mesh.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct Report {
    /// The input file, as given.
    pub input: String,
    /// The output file, as given (empty if the mesh was not written).
    pub output: String,
    /// The criteria used, evaluated at the centre of the bounding box.
    pub criteria: CriteriaReport,
    /// Sizes of the input and of the mesh.
    pub counts: Counts,
    /// What refinement did.
    pub refinement: RefinementReport,
    /// Wall time of each phase, in seconds.
    pub times_s: TimesSeconds,
    /// Shape of the tetrahedra.
    pub quality: QualityReport,
    /// Quality before and after each optimisation step.
    pub optimization: OptimizationReport,
    /// Tets and volume of each subdomain, by label.
    pub subdomains: Vec<SubdomainReport>,
    /// How close the mesh is to the input triangle surface; absent for a domain without one (an
    /// image, a subdivision surface, a plugin's domain).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub approximation: Option<Approximation>,
    /// Topology of the mesh boundary and of the input.
    pub boundary: BoundaryReport,
    /// What was repaired or reinterpreted in the input surface (empty when nothing was).
    pub repairs: Vec<String>,
    /// Sharp features: absent for smooth domains.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub features: Option<FeaturesReport>,
}

/// Wall time of each phase of the pipeline.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Times {
    /// Reading the input.
    pub read: Duration,
    /// Building the domain's oracle (feature detection included).
    pub oracle: Duration,
    /// Protection and initial points.
    pub initial_points: Duration,
    /// The refinement levels.
    pub refinement: Duration,
    /// Collecting the complex.
    pub complex: Duration,
    /// Sliver perturbation, exudation and smoothing.
    pub optimization: Duration,
    /// Computing the report.
    pub quality: Duration,
    /// Writing the mesh.
    pub write: Duration,
    /// From the start of the pipeline to the end of the report.
    pub total: Duration,
}

/// [`Times`] in seconds, in the report's order.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
#[allow(missing_docs)]
pub struct TimesSeconds {
    pub read: f64,
    pub oracle: f64,
    pub initial_points: f64,
    pub refinement: f64,
    pub complex: f64,
    pub optimization: f64,
    pub write: f64,
    pub quality: f64,
    pub total: f64,
}

impl Times {
    /// The same times in seconds.
    pub fn seconds(&self) -> TimesSeconds {
        TimesSeconds {
            read: self.read.as_secs_f64(),
            oracle: self.oracle.as_secs_f64(),
            initial_points: self.initial_points.as_secs_f64(),
            refinement: self.refinement.as_secs_f64(),
            complex: self.complex.as_secs_f64(),
            optimization: self.optimization.as_secs_f64(),
            write: self.write.as_secs_f64(),
            quality: self.quality.as_secs_f64(),
            total: self.total.as_secs_f64(),
        }
    }
}

/// Sharp features of the domain and how well the mesh keeps them.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct FeaturesReport {
    /// The edge size at the centre of the bounding box.
    pub edge_size: f64,
    /// Feature curves of the domain.
    pub curves: usize,
    /// Corners of the domain.
    pub corners: usize,
    /// Corners without a mesh vertex.
    pub missing_corners: usize,
    /// Largest distance between an input corner and its mesh vertex.
    pub max_corner_displacement: f64,
    /// Curves with no feature edge in the mesh.
    pub lost_curves: usize,
    /// Feature edges of the mesh.
    pub feature_edges: usize,
    /// Largest per-curve Hausdorff distance between the input polyline and the feature edges.
    pub max_curve_hausdorff: Option<f64>,
    /// One entry per input curve.
    pub per_curve: Vec<CurveReport>,
}

/// How one feature curve is kept.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct CurveReport {
    /// The curve's label.
    pub curve: u32,
    /// Mesh edges along it.
    pub feature_edges: usize,
    /// Hausdorff distance between the curve and its edges; `None` when it has none.
    pub hausdorff: Option<f64>,
}

impl FeaturesReport {
    /// `None` when the oracle has no sharp feature.
    fn new(oracle: &dyn Oracle, criteria: &MeshCriteria, c: &MeshComplex) -> Option<Self> {
        let curves = oracle.feature_curves();
        if curves.is_empty() && c.corners.is_empty() {
            return None;
        }
        let bbox = oracle.bounding_box();
        let f = quality::feature_fidelity(
            &curves,
            &c.points,
            &c.feature_edges,
            &c.feature_edge_curve,
            &c.corners,
            bbox.diagonal() / 2000.0,
        );
        let max_curve_hausdorff = f
            .curves
            .iter()
            .map(|c| c.hausdorff)
            .try_fold(0.0f64, |m, h| h.map(|h| m.max(h)));
        Some(FeaturesReport {
            edge_size: criteria.edge_size.at(bbox.center(), 1),
            curves: curves.len(),
            corners: f.corners,
            missing_corners: f.missing_corners,
            max_corner_displacement: f.max_corner_displacement,
            lost_curves: f.curves.iter().filter(|c| c.hausdorff.is_none()).count(),
            feature_edges: c.feature_edges.len(),
            max_curve_hausdorff,
            per_curve: f
                .curves
                .iter()
                .map(|c| CurveReport {
                    curve: c.curve.0,
                    feature_edges: c.edges,
                    hausdorff: c.hausdorff,
                })
                .collect(),
        })
    }
}

/// The criteria, evaluated at the centre of the bounding box.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
#[allow(missing_docs)]
pub struct CriteriaReport {
    pub facet_angle_deg: f64,
    pub facet_size: f64,
    pub facet_distance: f64,
    pub cell_radius_edge_ratio: f64,
    pub cell_size: f64,
}

/// Sizes of the input and of the mesh (the input's are 0 for a domain without an input triangle
/// surface).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
#[allow(missing_docs)]
pub struct Counts {
    pub input_vertices: usize,
    pub input_triangles: usize,
    pub vertices: usize,
    pub surface_vertices: usize,
    pub tets: usize,
    pub boundary_facets: usize,
    pub subdomains: usize,
}

/// What refinement did.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct RefinementReport {
    /// Insertions per level, in priority order.
    pub insertions_per_level: Vec<usize>,
    /// Points rejected because they encroached a higher-priority element.
    pub rejections: usize,
    /// Elements dropped without refinement.
    pub dropped: usize,
    /// Rounds of validity repairs after the criteria were met.
    pub repair_rounds: usize,
    /// Times the sharp features were protected again with smaller balls before the attempt kept
    /// (the other counts are those of that attempt).
    pub reprotections: usize,
}

/// Shape of the tetrahedra.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct QualityReport {
    /// Smallest dihedral angle, in degrees.
    pub min_dihedral_deg: f64,
    /// Largest dihedral angle, in degrees.
    pub max_dihedral_deg: f64,
    /// Largest circumradius / shortest edge.
    pub max_radius_edge: f64,
    /// Mean circumradius / shortest edge.
    pub mean_radius_edge: f64,
    /// Tets of non-positive volume.
    pub inverted_tets: usize,
    /// Tets per 10° bin of their smallest dihedral angle, from 0° to 180°.
    pub min_dihedral_histogram: Vec<u64>,
}

/// One subdomain of the mesh.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct SubdomainReport {
    /// Its label (an image's label value).
    pub subdomain: u32,
    /// Its tetrahedra.
    pub tets: usize,
    /// Their volume.
    pub volume: f64,
}

/// How close the mesh is to the input.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct Approximation {
    /// Largest distance from the mesh boundary to the input surface (sampled).
    pub hausdorff_mesh_to_input: f64,
    /// Largest distance from the input surface to the mesh boundary (sampled).
    pub hausdorff_input_to_mesh: f64,
    /// The larger of the two.
    pub hausdorff: f64,
    /// Volume of the mesh.
    pub volume: f64,
    /// Volume inside the input surface.
    pub input_volume: f64,
    /// `volume / input_volume`.
    pub volume_ratio: f64,
}

/// Topology of the mesh boundary and of the input.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct BoundaryReport {
    /// No border edge.
    pub closed: bool,
    /// No non-manifold edge nor vertex.
    pub manifold: bool,
    /// V - E + F of the boundary.
    pub euler_characteristic: i64,
    /// Connected components of the boundary.
    pub components: usize,
    /// V - E + F of the input surface (of the control mesh for a subdivision surface); absent
    /// for a domain without one.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub input_euler_characteristic: Option<i64>,
    /// Connected components of the input surface; absent for a domain without one.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub input_components: Option<usize>,
    /// Boundary facets whose dual Voronoi edge the surface level did not find crossing the input.
    pub unrestricted_facets: usize,
}

/// The input triangle surface and its oracle, which the approximation is measured against.
pub(crate) struct InputSurface<'a> {
    pub points: &'a [Point3],
    pub triangles: &'a [[u32; 3]],
    pub polyhedral: &'a PolyhedralOracle,
}

/// What the report is computed from.
pub(crate) struct ReportInput<'a> {
    pub input: &'a str,
    pub output: &'a str,
    pub surface: Option<InputSurface<'a>>,
    /// Euler characteristic of each closed component of the input, when it has a topology.
    pub input_euler: Option<&'a [i64]>,
    pub domain: &'a dyn Oracle,
    pub criteria: &'a MeshCriteria,
    pub complex: &'a MeshComplex,
    pub stats: &'a RefineStats,
    pub optimization: &'a OptimizeReport,
}

/// The optimisation phase: quality of the refined mesh, then after each step.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct OptimizationReport {
    /// The refined mesh.
    pub before: StepQuality,
    /// The steps run, in order.
    pub steps: Vec<StepOutcome>,
    /// Why the optimisers did not run, if they could not.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub skipped: Option<String>,
}

/// Dihedral-angle quality at one point of the optimisation phase.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct StepQuality {
    /// Number of tetrahedra.
    pub tets: usize,
    /// Smallest dihedral angle (degrees).
    pub min_dihedral_deg: f64,
    /// Tetrahedra whose smallest dihedral angle is below 10°.
    pub below_10_deg: usize,
}

/// What one optimisation step did.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct StepOutcome {
    /// `lloyd`, `odt`, `perturb` or `exude`.
    pub step: &'static str,
    /// Moves or weight changes kept.
    pub changes: usize,
    /// Sweeps run (smoothing only).
    pub sweeps: usize,
    /// Wall time of the step.
    pub seconds: f64,
    /// Quality after the step.
    pub after: StepQuality,
}

impl StepQuality {
    fn new(q: &Quality) -> Self {
        StepQuality {
            tets: q.tets,
            min_dihedral_deg: q.min_dihedral_deg,
            below_10_deg: q.below_10_deg,
        }
    }
}

impl OptimizationReport {
    /// The report section of the optimisation phase `r`.
    pub fn new(r: &OptimizeReport) -> Self {
        OptimizationReport {
            before: StepQuality::new(&r.before),
            steps: r
                .steps
                .iter()
                .map(|s| StepOutcome {
                    step: s.step.name(),
                    changes: s.changes,
                    sweeps: s.sweeps,
                    seconds: s.time.as_secs_f64(),
                    after: StepQuality::new(&s.quality),
                })
                .collect(),
            skipped: r.skipped.map(|e| e.to_string()),
        }
    }
}

impl Report {
    /// The report of a mesh; `times_s` is left to the caller, which knows when the run ended.
    pub(crate) fn new(r: &ReportInput<'_>) -> Report {
        let c = r.complex;
        let criteria = r.criteria;
        let center = r.domain.bounding_box().center();
        let q: TetQuality = quality::tet_quality((0..c.tets.len()).map(|t| c.tet_points(t)));
        let topology = quality::surface_topology(&c.facets);
        let subdomains = subdomain_volumes(c);
        let input_topology = r
            .surface
            .as_ref()
            .map(|s| quality::surface_topology(s.triangles));
        let (input_euler, input_components) = match (&input_topology, r.input_euler) {
            (Some(t), _) => (Some(t.euler_characteristic), Some(t.components)),
            (None, Some(e)) => (Some(e.iter().sum()), Some(e.len())),
            (None, None) => (None, None),
        };
        Report {
            input: r.input.to_string(),
            output: r.output.to_string(),
            criteria: CriteriaReport {
                facet_angle_deg: criteria.facet.angle_deg,
                facet_size: criteria.facet.size.at(center, 1),
                facet_distance: criteria.facet.distance.at(center, 1),
                cell_radius_edge_ratio: criteria.cell.radius_edge_ratio,
                cell_size: criteria.cell.size.at(center, 1),
            },
            counts: Counts {
                input_vertices: r.surface.as_ref().map_or(0, |s| s.points.len()),
                input_triangles: r.surface.as_ref().map_or(0, |s| s.triangles.len()),
                vertices: c.num_vertices(),
                surface_vertices: c
                    .vertex_dimension
                    .iter()
                    .filter(|d| **d == VertexDimension::Surface)
                    .count(),
                tets: c.tets.len(),
                boundary_facets: c.facets.len(),
                subdomains: subdomains.len(),
            },
            refinement: RefinementReport {
                insertions_per_level: r.stats.insertions.clone(),
                rejections: r.stats.rejections,
                dropped: r.stats.dropped,
                repair_rounds: r.stats.repair_rounds,
                reprotections: r.stats.reprotections,
            },
            times_s: TimesSeconds::default(),
            quality: QualityReport {
                min_dihedral_deg: q.min_dihedral_deg,
                max_dihedral_deg: q.max_dihedral_deg,
                max_radius_edge: q.max_radius_edge,
                mean_radius_edge: q.mean_radius_edge,
                inverted_tets: q.inverted,
                min_dihedral_histogram: q.min_dihedral_histogram.counts.clone(),
            },
            optimization: OptimizationReport::new(r.optimization),
            subdomains,
            approximation: r.surface.as_ref().map(|s| {
                let (to_input, to_mesh) = hausdorff(c, s.polyhedral);
                Approximation {
                    hausdorff_mesh_to_input: to_input,
                    hausdorff_input_to_mesh: to_mesh,
                    hausdorff: to_input.max(to_mesh),
                    volume: q.volume,
                    input_volume: s.polyhedral.domain_volume(),
                    volume_ratio: q.volume / s.polyhedral.domain_volume(),
                }
            }),
            boundary: BoundaryReport {
                closed: topology.border_edges == 0,
                manifold: topology.non_manifold_edges == 0 && topology.non_manifold_vertices == 0,
                euler_characteristic: topology.euler_characteristic,
                components: topology.components,
                input_euler_characteristic: input_euler,
                input_components,
                unrestricted_facets: c.facet_patch.iter().filter(|&&p| p.0 == 0).count(),
            },
            repairs: r
                .surface
                .as_ref()
                .map(|s| s.polyhedral.repairs().describe())
                .unwrap_or_default(),
            features: FeaturesReport::new(r.domain, criteria, c),
        }
    }
}

/// Tets and volume of each subdomain, by increasing label.
fn subdomain_volumes(c: &MeshComplex) -> Vec<SubdomainReport> {
    let mut by_label: std::collections::BTreeMap<u32, (usize, f64)> = Default::default();
    for (t, s) in c.tet_subdomain.iter().enumerate() {
        let entry = by_label.entry(s.0).or_default();
        entry.0 += 1;
        entry.1 += quality::tet_volume(&c.tet_points(t));
    }
    by_label
        .into_iter()
        .map(|(subdomain, (tets, volume))| SubdomainReport {
            subdomain,
            tets,
            volume,
        })
        .collect()
}

/// The two sides of the sampled Hausdorff distance between the mesh boundary and the input.
fn hausdorff(c: &MeshComplex, oracle: &PolyhedralOracle) -> (f64, f64) {
    let spacing = oracle.bounding_box().diagonal() / 300.0;
    let boundary: Vec<[Point3; 3]> = (0..c.facets.len()).map(|f| c.facet_points(f)).collect();
    let mesh_samples = quality::sample_triangles(boundary.iter().copied(), spacing);
    let to_input = quality::one_sided_distance(&mesh_samples, |p| oracle.distance_to_surface(p));
    let tree = TriangleTree::new(&boundary);
    let input_samples = quality::sample_triangles(oracle.triangles().iter().copied(), spacing);
    let to_mesh = quality::one_sided_distance(&input_samples, |p| tree.distance(p, &boundary));
    (to_input, to_mesh)
}
