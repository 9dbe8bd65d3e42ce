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
