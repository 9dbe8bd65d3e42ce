//! Mesh criteria as CGAL Mesh_3 users know them, and sizing fields.

use crate::kernel::Point3;
use crate::oracle::Aabb;
use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

/// A bound that may vary in space: a mesh size, an approximation distance.
///
/// `label` is the subdomain for cell criteria and the surface patch for facet criteria.
#[derive(Clone)]
pub enum Sizing {
    /// No bound.
    Unbounded,
    Constant(f64),
    /// A value per label, `default` elsewhere.
    PerLabel {
        default: f64,
        values: BTreeMap<u32, f64>,
    },
    Function(Arc<dyn Fn(Point3, u32) -> f64 + Send + Sync>),
}

impl Sizing {
    pub fn at(&self, p: Point3, label: u32) -> f64 {
        match self {
            Sizing::Unbounded => f64::INFINITY,
            Sizing::Constant(v) => *v,
            Sizing::PerLabel { default, values } => values.get(&label).copied().unwrap_or(*default),
            Sizing::Function(f) => f(p, label),
        }
    }

    pub fn is_bounded(&self) -> bool {
        !matches!(self, Sizing::Unbounded)
    }
}

impl fmt::Debug for Sizing {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Sizing::Unbounded => write!(f, "Unbounded"),
            Sizing::Constant(v) => write!(f, "Constant({v})"),
            Sizing::PerLabel { default, values } => write!(f, "PerLabel({default}, {values:?})"),
            Sizing::Function(_) => write!(f, "Function"),
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
pub struct MeshCriteria {
    /// Upper bound on the radius of the protecting balls along feature curves (CGAL's
    /// `edge_size`), so on the length of the mesh edges that follow them; the label is the curve.
    /// Unused by smooth domains.
    pub edge_size: Sizing,
    pub facet: FacetCriteria,
    pub cell: CellCriteria,
}

impl MeshCriteria {
    /// Criteria that give a medium-resolution mesh of any domain, scaled by its bounding box, so
    /// that meshing needs no option.
    pub fn default_for(bbox: &Aabb) -> Self {
        let d = bbox.diagonal();
        MeshCriteria {
            edge_size: Sizing::Constant(d / 20.0),
            facet: FacetCriteria {
                angle_deg: 25.0,
                size: Sizing::Constant(d / 20.0),
                distance: Sizing::Constant(d / 400.0),
            },
            cell: CellCriteria {
                radius_edge_ratio: 3.0,
                size: Sizing::Constant(d / 20.0),
            },
        }
    }
}

/// Why a set of criteria was refused before meshing (see [`MeshCriteria::validate`]).
#[derive(Debug, thiserror::Error)]
#[error("{criterion} {value}: {problem}")]
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
                Sizing::PerLabel { default, values } => std::iter::once(*default)
                    .chain(values.values().copied())
                    .collect(),
                Sizing::Unbounded | Sizing::Function(_) => Vec::new(),
            };
            for v in values {
                if !(v.is_finite() && v > 0.0) {
                    return Err(refuse(criterion, v, "must be a positive number".into()));
                }
                // The distance bound says nothing about flat parts: no count follows from it.
                let needed = span / (2.0 * v);
                if criterion != "facet-distance" && needed > max_vertices as f64 {
                    return Err(refuse(
                        criterion,
                        v,
                        format!(
                            "needs at least {needed:.1e} vertices across the {span:.3e} box, \
                             more than max-vertices {max_vertices}"
                        ),
                    ));
                }
            }
        }
        Ok(warnings)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> Aabb {
        Aabb {
            min: Point3::ZERO,
            max: Point3::ONE,
        }
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
