//! Mesh criteria as CGAL Mesh_3 users know them, and sizing fields.

use crate::kernel::Point3;
use crate::oracle::Aabb;
use crate::refine::sizing::SizingField;
use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

/// A bound that may vary in space: a mesh size, an approximation distance.
///
/// `label` is the subdomain for cell criteria, the surface patch for facet criteria and the curve
/// for edge sizes.
#[derive(Clone)]
pub enum Sizing {
    /// No bound.
    Unbounded,
    /// The same bound everywhere.
    Constant(f64),
    /// A value per label, `default` elsewhere.
    PerLabel {
        /// The value of labels not in `values`.
        default: f64,
        /// The value of each label given.
        values: BTreeMap<u32, f64>,
    },
    /// A sizing field: a background mesh, a size image, sizes at points, a closure (see
    /// [`sizing`](super::sizing)).
    Field(Arc<dyn SizingField>),
}

impl Sizing {
    /// A field from a closure of the point and the label.
    pub fn function(f: impl Fn(Point3, u32) -> f64 + Send + Sync + 'static) -> Self {
        Sizing::Field(Arc::new(f))
    }

    /// The bound at `p` in `label`.
    pub fn at(&self, p: Point3, label: u32) -> f64 {
        match self {
            Sizing::Unbounded => f64::INFINITY,
            Sizing::Constant(v) => *v,
            Sizing::PerLabel { default, values } => values.get(&label).copied().unwrap_or(*default),
            Sizing::Field(f) => f.size_at(p, label),
        }
    }

    /// The smallest value a constant or per-label bound takes, or a field's lower bound when
    /// it knows one (`None` otherwise, and for no bound).
    pub fn smallest(&self) -> Option<f64> {
        match self {
            Sizing::Constant(v) => Some(*v),
            Sizing::PerLabel { default, values } => {
                Some(values.values().fold(*default, |m, &v| m.min(v)))
            }
            Sizing::Field(f) => f.smallest(),
            Sizing::Unbounded => None,
        }
    }

    /// Whether there is a bound at all.
    pub fn is_bounded(&self) -> bool {
        !matches!(self, Sizing::Unbounded)
    }

    /// Whether the bound may differ between labels at the same point: sampling it then needs
    /// the label of the point (fields may use labels too; those given by the command line do
    /// not).
    pub fn depends_on_label(&self) -> bool {
        matches!(self, Sizing::PerLabel { .. })
    }
}

impl fmt::Debug for Sizing {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Sizing::Unbounded => write!(f, "Unbounded"),
            Sizing::Constant(v) => write!(f, "Constant({v})"),
            Sizing::PerLabel { default, values } => write!(f, "PerLabel({default}, {values:?})"),
            Sizing::Field(_) => write!(f, "Field"),
        }
    }
}

/// Criteria on restricted facets (rule R2 of the thesis, in CGAL's vocabulary).
#[derive(Clone, Debug)]
pub struct FacetCriteria {
    /// Lower bound on the smallest angle of a facet, in degrees (0 disables it). Termination is
    /// guaranteed up to 30°.
    pub angle_deg: f64,
    /// Upper bound on the radius of the surface Delaunay balls.
    pub size: Sizing,
    /// Upper bound on the distance between a facet's circumcentre and its surface ball centre.
    pub distance: Sizing,
}

/// Criteria on the tetrahedra inside the domain (rule R3).
#[derive(Clone, Debug)]
pub struct CellCriteria {
    /// Upper bound on circumradius / shortest edge (0 disables it; ≥ 2 for guaranteed termination).
    pub radius_edge_ratio: f64,
    /// Upper bound on the circumradius.
    pub size: Sizing,
}

#[derive(Clone, Debug)]
/// Every criterion of a 3D mesh: feature edges, boundary facets and cells.
pub struct MeshCriteria {
    /// Upper bound on the radius of the protecting balls along feature curves (CGAL's
    /// `edge_size`), so on the length of the mesh edges that follow them; the label is the curve.
    /// Unused by smooth domains.
    pub edge_size: Sizing,
    /// Smallest protecting ball radius (CGAL 6's `edge_min_size`): features closer than this are
    /// no longer split, but still meshed. 0 picks [`DEFAULT_EDGE_MIN_FRACTION`] of the bounding-box
    /// diagonal. Unused by smooth domains.
    pub edge_min_size: f64,
    /// The criteria of the boundary facets.
    pub facet: FacetCriteria,
    /// The criteria of the cells.
    pub cell: CellCriteria,
}

/// Default smallest protecting ball radius, as a fraction of the bounding-box diagonal: far below
/// any edge size a user asks for, large enough to bound the protection of features that touch.
pub const DEFAULT_EDGE_MIN_FRACTION: f64 = 1e-3;

/// Bend tolerance of the protection as a fraction of the smallest facet distance (see
/// [`MeshCriteria::bend_tolerance`]).
pub const BEND_TOLERANCE_FRACTION: f64 = 0.25;

/// The automatic vertex limit ([`MeshCriteria::vertex_budget`]) as a multiple of the count the
/// criteria predict, and its bounds.
pub const VERTEX_BUDGET_FACTOR: f64 = 50.0;
/// Smallest automatic vertex limit.
pub const MIN_VERTEX_BUDGET: usize = 100_000;
/// Largest automatic vertex limit (the limit before it was automatic).
pub const MAX_VERTEX_BUDGET: usize = 2_000_000;

/// The refinement floor of a domain without features as a fraction of the finest scale (see
/// [`MeshCriteria::smooth_refinement_floor`]).
pub const SMOOTH_FLOOR_FRACTION: f64 = 0.25;

impl MeshCriteria {
    /// The smallest protecting ball radius for a domain with bounding box `bbox`.
    pub fn edge_min_size_for(&self, bbox: &Aabb) -> f64 {
        if self.edge_min_size > 0.0 {
            self.edge_min_size
        } else {
            DEFAULT_EDGE_MIN_FRACTION * bbox.diagonal()
        }
    }

    /// How far a feature curve's mesh edges may leave the input's tessellation of it
    /// ([`ProtectLimits::bend_tolerance`](super::protect::ProtectLimits::bend_tolerance)): a
    /// quarter of the smallest facet distance, so the curves stay well inside the surface's own
    /// fidelity; 0 (every polyline vertex kept) when no facet distance is asked for.
    pub fn bend_tolerance(&self) -> f64 {
        self.facet
            .distance
            .smallest()
            .filter(|d| d.is_finite() && *d > 0.0)
            .map_or(0.0, |d| BEND_TOLERANCE_FRACTION * d)
    }

    /// The vertex limit when none is given: [`VERTEX_BUDGET_FACTOR`] times the count the
    /// criteria predict for a domain filling `bbox` (its faces sampled at the facet size, or at
    /// the spacing the facet distance asks on a curvature radius of an eighth of the diagonal;
    /// its volume at the cell size), within [`MIN_VERTEX_BUDGET`], [`MAX_VERTEX_BUDGET`]. A
    /// domain that needs far more than its criteria predict (a 1e-6 slab, a 0.1° wedge, whose
    /// thin parts refine down to the floor) stops within seconds with an error naming the limit,
    /// instead of running for minutes.
    pub fn vertex_budget(&self, bbox: &Aabb) -> usize {
        let e = (bbox.max - bbox.min).max(Point3::ZERO);
        let d = bbox.diagonal();
        let smallest = |s: &Sizing| s.smallest().filter(|v| v.is_finite() && *v > 0.0);
        let mut spacing = [&self.facet.size, &self.edge_size]
            .into_iter()
            .filter_map(smallest)
            .fold(d, f64::min);
        if let Some(delta) = smallest(&self.facet.distance) {
            spacing = spacing.min((delta * d / 4.0).sqrt());
        }
        let cell = smallest(&self.cell.size).unwrap_or(d).min(d);
        let area = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
        let volume = e.x * e.y * e.z;
        let expected = area / (spacing * spacing) + volume / (cell * cell * cell);
        let budget = VERTEX_BUDGET_FACTOR * expected;
        if budget.is_finite() {
            (budget as usize).clamp(MIN_VERTEX_BUDGET, MAX_VERTEX_BUDGET)
        } else {
            MAX_VERTEX_BUDGET
        }
    }

    /// Radius under which no facet or cell of a domain with features is refined: the finest
    /// scale asked for (the smallest protecting ball, or a smaller constant size or distance),
    /// so that refinement near a seam finer than that ends (without features, see
    /// [`MeshCriteria::smooth_refinement_floor`]). Sheets of the surface closer
    /// than this are not separated (a plate thinner than the smallest ball may be lost): resolving
    /// them would take points in proportion to the area over the square of their gap, and a
    /// smaller `edge_min_size` asks for that.
    pub fn refinement_floor(&self, bbox: &Aabb) -> f64 {
        [&self.facet.size, &self.facet.distance, &self.cell.size]
            .into_iter()
            .filter_map(Sizing::smallest)
            .fold(self.edge_min_size_for(bbox), f64::min)
    }

    /// The refinement floor of a domain without features (chapter 3), which has no protecting
    /// ball to be the finest scale: [`SMOOTH_FLOOR_FRACTION`] of the smallest constant size,
    /// distance or `edge_min_size`. A facet distance met where the surface bends sharply (a
    /// voxel staircase) takes facets smaller than itself.
    pub fn smooth_refinement_floor(&self, bbox: &Aabb) -> f64 {
        SMOOTH_FLOOR_FRACTION * self.refinement_floor(bbox)
    }

    /// Criteria that give a medium-resolution mesh of any domain, scaled by its bounding box, so
    /// that meshing needs no option.
    pub fn default_for(bbox: &Aabb) -> Self {
        let d = bbox.diagonal();
        MeshCriteria::uniform(d / 20.0, d / 400.0)
    }

    /// One constant `size` for feature edges, facets and cells, a constant facet `distance`,
    /// and the angle (25°) and radius-edge ratio (3) that guarantee termination.
    pub fn uniform(size: f64, distance: f64) -> Self {
        MeshCriteria {
            edge_size: Sizing::Constant(size),
            edge_min_size: 0.0,
            facet: FacetCriteria {
                angle_deg: 25.0,
                size: Sizing::Constant(size),
                distance: Sizing::Constant(distance),
            },
            cell: CellCriteria {
                radius_edge_ratio: 3.0,
                size: Sizing::Constant(size),
            },
        }
    }
}

/// Why a set of criteria was refused before meshing (see [`MeshCriteria::validate`]).
#[derive(Debug, thiserror::Error)]
#[error("{criterion} {value:?}: {problem}")]
pub struct CriteriaError {
    /// The criterion, named as the command line's option (`facet-angle`, `cell-size`...).
    pub criterion: &'static str,
    /// The value refused.
    pub value: f64,
    /// Why.
    pub problem: String,
}

/// Largest facet angle bound for which refinement is proven to terminate (Boissonnat–Oudot).
pub const MAX_FACET_ANGLE_DEG: f64 = 30.0;
/// Radius-edge bound from which refinement is proven to terminate (Shewchuk).
pub const SAFE_RADIUS_EDGE_RATIO: f64 = 2.0;
/// No refinement reaches a radius-edge bound below this: even regular tetrahedra have √6/4, and
/// slivers next to the surface keep the ratio near 1 without optimisation.
pub const MIN_RADIUS_EDGE_RATIO: f64 = 1.0;

/// The warning for a radius-edge bound that is reachable but not proven to terminate.
pub fn radius_edge_warning(ratio: f64) -> Option<String> {
    (MIN_RADIUS_EDGE_RATIO..SAFE_RADIUS_EDGE_RATIO).contains(&ratio).then(|| {
        format!(
            "cell-radius-edge-ratio below {SAFE_RADIUS_EDGE_RATIO} may not terminate before the \
             vertex limit"
        )
    })
}

impl MeshCriteria {
    /// The one place the criteria are checked before meshing: refuses what cannot terminate
    /// (facet angle above 30°, radius-edge bound below 1), non-positive or non-finite sizes, and
    /// sizes that need more than `max_vertices` vertices across the box `bbox` (a connected surface
    /// spanning the longest side `L` needs at least `L / 2r` balls of radius `r`). Returns warnings
    /// for what may not terminate before the vertex limit.
    pub fn validate(&self, bbox: &Aabb, max_vertices: usize) -> Result<Vec<String>, CriteriaError> {
        let refuse = |criterion, value, problem: String| CriteriaError {
            criterion,
            value,
            problem,
        };
        let mut warnings = Vec::new();
        let angle = self.facet.angle_deg;
        if !(0.0..=MAX_FACET_ANGLE_DEG).contains(&angle) {
            return Err(refuse(
                "facet-angle",
                angle,
                format!(
                    "must be in [0°, {MAX_FACET_ANGLE_DEG}°]: above, refinement may never terminate"
                ),
            ));
        }
        let ratio = self.cell.radius_edge_ratio;
        if !(ratio.is_finite() && ratio >= 0.0) {
            return Err(refuse(
                "cell-radius-edge-ratio",
                ratio,
                "must be a number ≥ 0 (0 disables it)".into(),
            ));
        }
        if ratio > 0.0 && ratio < MIN_RADIUS_EDGE_RATIO {
            return Err(refuse(
                "cell-radius-edge-ratio",
                ratio,
                format!(
                    "refinement cannot reach a bound below {MIN_RADIUS_EDGE_RATIO} \
                     ({SAFE_RADIUS_EDGE_RATIO} or more is guaranteed to terminate)"
                ),
            ));
        }
        warnings.extend(radius_edge_warning(ratio));
        let span = (bbox.max - bbox.min).max_element();
        let sizes = [
            ("edge-size", &self.edge_size),
            ("facet-size", &self.facet.size),
            ("facet-distance", &self.facet.distance),
            ("cell-size", &self.cell.size),
        ];
        for (criterion, sizing) in sizes {
            let values: Vec<f64> = match sizing {
                Sizing::Constant(v) => vec![*v],
                // An infinite default: no bound outside the labels given.
                Sizing::PerLabel { default, values } => std::iter::once(*default)
                    .filter(|d| *d != f64::INFINITY)
                    .chain(values.values().copied())
                    .collect(),
                // A field's values were checked when it was built; its smallest bounds the count.
                Sizing::Field(field) => field.smallest().into_iter().collect(),
                Sizing::Unbounded => Vec::new(),
            };
            for v in values {
                if !(v.is_finite() && v > 0.0) {
                    return Err(refuse(criterion, v, "must be a positive number".into()));
                }
                // The distance bound says nothing about flat parts: no count follows from it.
                // Protecting balls never shrink below the smallest edge size.
                let effective = if criterion == "edge-size" {
                    v.max(self.edge_min_size_for(bbox))
                } else {
                    v
                };
                let needed = span / (2.0 * effective);
                if criterion != "facet-distance" && needed > max_vertices as f64 {
                    return Err(refuse(
                        criterion,
                        v,
                        format!(
                            "needs at least {needed:.1e} vertices across the {span:.3e} box, \
                             more than --max-vertices {max_vertices}"
                        ),
                    ));
                }
            }
        }
        Ok(warnings)
    }
}

/// Squared radius of the smallest sphere orthogonal to two weighted points (negative when their
/// balls overlap deeply, zero when they meet at one point).
fn orthogonal_radius2(p: Point3, wp: f64, q: Point3, wq: f64) -> f64 {
    let d2 = p.distance_squared(q);
    if d2 == 0.0 {
        return -wp.min(wq);
    }
    let t = (d2 + wp - wq) / (2.0 * d2);
    t * t * d2 - wp
}

/// Which facet criteria a restricted facet touching protecting balls is exempt from: CGAL
/// Mesh_3's rule for domains with features. A facet fanning out of a protecting ball is shaped by
/// the ball, not by the surface: its vertices on the ball sit where the protection put them, so
/// refining it for shape, size or distance only adds points that the ball's neighbourhood cannot
/// use (they pile up along the curve). The facet is exempt from a criterion when its unweighted
/// vertices lie close to the balls of its weighted ones, relative to the balls' radii.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FeatureExemption {
    /// All three vertices are protecting balls with a common point: the facet lies on a curve's
    /// protection and no criterion applies.
    pub all: bool,
    /// No distance criterion.
    pub distance: bool,
    /// No angle criterion.
    pub angle: bool,
    /// No size criterion.
    pub size: bool,
}

impl FeatureExemption {
    /// The exemption of a facet with vertices `p` and weights `w` (squared ball radii, 0 for
    /// points that are not ball centres).
    pub fn of_facet(p: [Point3; 3], w: [f64; 3]) -> Self {
        let weighted: Vec<usize> = (0..3).filter(|&k| w[k] > 0.0).collect();
        let plain: Vec<usize> = (0..3).filter(|&k| w[k] <= 0.0).collect();
        let (ratio, intersect) = match weighted.len() {
            1 => {
                let a = weighted[0];
                let r = plain
                    .iter()
                    .map(|&k| orthogonal_radius2(p[a], w[a], p[k], 0.0))
                    .fold(f64::NEG_INFINITY, f64::max);
                (r / w[a], true)
            }
            2 => {
                let (a, b, c) = (weighted[0], weighted[1], plain[0]);
                let ra = orthogonal_radius2(p[a], w[a], p[c], 0.0) / w[a];
                let rb = orthogonal_radius2(p[b], w[b], p[c], 0.0) / w[b];
                let intersect = orthogonal_radius2(p[a], w[a], p[b], w[b]) <= 0.0;
                (ra.max(rb), intersect)
            }
            3 => {
                let (_, r2) = super::geometry::weighted_triangle_circumcenter(p, w);
                return FeatureExemption {
                    all: r2 <= 0.0,
                    ..Self::default()
                };
            }
            _ => return Self::default(),
        };
        let near = |bound: f64| intersect && ratio < bound;
        FeatureExemption {
            all: false,
            distance: near(DISTANCE_EXEMPTION),
            angle: near(ANGLE_EXEMPTION),
            size: near(SIZE_EXEMPTION),
        }
    }
}

/// Bounds on (squared radius of the sphere orthogonal to a facet's ball and its other vertex) /
/// (ball's squared radius) under which a criterion is waived (CGAL's values: (2·0.1)², (2·0.5)²,
/// (2·0.4)²).
const DISTANCE_EXEMPTION: f64 = 0.04;
const ANGLE_EXEMPTION: f64 = 1.0;
const SIZE_EXEMPTION: f64 = 0.64;

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> Aabb {
        Aabb {
            min: Point3::ZERO,
            max: Point3::ONE,
        }
    }

    /// The automatic vertex limit follows the criteria: a cube at the defaults gets well above
    /// what it needs (a few thousand vertices), a thin slab the smallest limit, criteria a
    /// hundred times finer the largest.
    #[test]
    fn the_vertex_budget_follows_the_criteria() {
        let cube = MeshCriteria::default_for(&unit_box());
        let budget = cube.vertex_budget(&unit_box());
        assert!(
            (MIN_VERTEX_BUDGET..MAX_VERTEX_BUDGET).contains(&budget),
            "{budget}"
        );
        let slab = Aabb {
            min: Point3::ZERO,
            max: Point3::new(1.0, 1.0, 1e-6),
        };
        let thin = MeshCriteria::default_for(&slab);
        assert_eq!(thin.vertex_budget(&slab), MIN_VERTEX_BUDGET);
        let mut fine = cube.clone();
        fine.facet.size = Sizing::Constant(0.001);
        assert_eq!(fine.vertex_budget(&unit_box()), MAX_VERTEX_BUDGET);
        let mut finer_distance = cube.clone();
        finer_distance.facet.distance = Sizing::Constant(1e-4);
        assert!(finer_distance.vertex_budget(&unit_box()) > budget);
    }

    #[test]
    fn defaults_pass_and_what_cannot_terminate_is_refused() {
        let ok = MeshCriteria::default_for(&unit_box());
        assert!(ok.validate(&unit_box(), 1000).is_ok());
        let mut c = ok.clone();
        c.facet.angle_deg = 90.0;
        assert_eq!(
            c.validate(&unit_box(), 1000).err().map(|e| e.criterion),
            Some("facet-angle")
        );
        let mut c = ok.clone();
        c.cell.radius_edge_ratio = 0.5;
        assert!(c.validate(&unit_box(), 1000).is_err());
        c.cell.radius_edge_ratio = 1.5;
        assert_eq!(c.validate(&unit_box(), 1000).map(|w| w.len()).ok(), Some(1));
        let mut c = ok.clone();
        c.facet.size = Sizing::Constant(1e-300);
        assert_eq!(
            c.validate(&unit_box(), 1000).err().map(|e| e.criterion),
            Some("facet-size")
        );
        let mut c = ok;
        c.cell.size = Sizing::Constant(f64::NAN);
        assert!(c.validate(&unit_box(), 1000).is_err());
    }
}
