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
    /// Smallest protecting ball radius (CGAL 6's `edge_min_size`): features closer than this are
    /// no longer split, but still meshed. 0 picks [`DEFAULT_EDGE_MIN_FRACTION`] of the bounding-box
    /// diagonal. Unused by smooth domains.
    pub edge_min_size: f64,
    pub facet: FacetCriteria,
    pub cell: CellCriteria,
}

/// Default smallest protecting ball radius, as a fraction of the bounding-box diagonal: far below
/// any edge size a user asks for, large enough to bound the protection of features that touch.
pub const DEFAULT_EDGE_MIN_FRACTION: f64 = 1e-3;

impl MeshCriteria {
    /// The smallest protecting ball radius for a domain with bounding box `bbox`.
    pub fn edge_min_size_for(&self, bbox: &Aabb) -> f64 {
        if self.edge_min_size > 0.0 {
            self.edge_min_size
        } else {
            DEFAULT_EDGE_MIN_FRACTION * bbox.diagonal()
        }
    }

    /// Criteria that give a medium-resolution mesh of any domain, scaled by its bounding box, so
    /// that meshing needs no option.
    pub fn default_for(bbox: &Aabb) -> Self {
        let d = bbox.diagonal();
        MeshCriteria {
            edge_size: Sizing::Constant(d / 20.0),
            edge_min_size: 0.0,
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
