//! Subdomains sharing a face. Supported convention: each subdomain is a closed, outward-oriented
//! component, and a face between two subdomains appears in both, as two triangles with the same
//! vertices in opposite orientations (welded or not). Around an edge of such a face, four
//! triangles meet; each one outside the shared face belongs with the shared-face copy that runs
//! through the edge the other way, which tells the components apart. Each component then gets its
//! own copy of its vertices, so that the polyhedral oracle sees separate closed surfaces.

use crate::edges::EdgeIncidence;
use crate::features::Features;
use delamesh_core::union_find::UnionFind;
use glam::DVec3;
use std::collections::BTreeMap;

/// The surface with every closed component on its own vertices (unchanged without shared faces).
pub(crate) fn separate_components(features: &Features) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    if features.shared_faces.is_empty() {
        return (features.positions.clone(), features.triangles.clone());
    }
    let triangles = &features.triangles;
    let mut twin: Vec<Option<u32>> = vec![None; triangles.len()];
    for &[a, b] in &features.shared_faces {
        twin[a as usize] = Some(b);
        twin[b as usize] = Some(a);
    }
    let incidence = EdgeIncidence::new(triangles, |_| true);
    let mut sets = UnionFind::new(triangles.len());
    for e in 0..incidence.edges.len() {
        let uses = incidence.uses(e);
        for u in uses {
            let mut partners: Vec<u32> = uses
                .iter()
                .filter(|w| w.forward != u.forward && twin[u.triangle as usize] != Some(w.triangle))
                .map(|w| w.triangle)
                .collect();
            if partners.len() > 1 && twin[u.triangle as usize].is_none() {
                partners.retain(|&w| twin[w as usize].is_some());
            }
            if let [w] = partners[..] {
                sets.union(u.triangle, w);
            }
        }
    }
    let mut positions = Vec::new();
    let mut renumber: BTreeMap<(u32, u32), u32> = BTreeMap::new();
    let separated = (0..triangles.len())
        .map(|t| {
            let component = sets.find(t as u32);
            triangles[t].map(|v| {
                *renumber.entry((component, v)).or_insert_with(|| {
                    positions.push(features.positions[v as usize]);
                    positions.len() as u32 - 1
                })
            })
        })
        .collect();
    (positions, separated)
}
