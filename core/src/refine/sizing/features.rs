//! Sharp features as sources of small size for gradation: the protecting balls the mesher will
//! put on corners and curves are shrunk by nearby features, short curve pieces and sharp bends,
//! and the mesh around a ball is about its radius whatever the field says. Seeding the graded
//! grid with them makes the size grow away from small features by at most the gradation too.

use crate::kernel::Point3;
use crate::oracle::Oracle;
use crate::refine::criteria::MeshCriteria;
use crate::refine::protect::{ProtectLimits, protect};

/// The centre and radius of every protecting ball the oracle's features get under `criteria`
/// (the protection of `mesh_domain`, run once more before meshing): empty without features, or
/// when the protection fails (meshing then reports why).
pub fn feature_sizes(oracle: &dyn Oracle, criteria: &MeshCriteria) -> Vec<(Point3, f64)> {
    let curves = oracle.feature_curves();
    let corners = oracle.corners();
    if curves.is_empty() && corners.is_empty() {
        return Vec::new();
    }
    let bbox = oracle.bounding_box();
    let limits = ProtectLimits {
        min_radius: criteria.edge_min_size_for(&bbox),
        max_balls: criteria.vertex_budget(&bbox),
        deadline: None,
        bend_tolerance: criteria.bend_tolerance(),
    };
    let onto_curve = |c, p| oracle.project_to_curve(c, p);
    protect(&curves, &corners, &criteria.edge_size, &limits, &onto_curve)
        .map(|p| p.balls.iter().map(|b| (b.center, b.radius)).collect())
        .unwrap_or_default()
}
