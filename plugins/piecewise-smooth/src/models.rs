//! Closed test shapes with known sharp features (cube, cylinder, L-bracket, box with a hole,
//! wedges, two boxes sharing a face), shared by the feature tests, the end-to-end meshing tests
//! and `tests/data/features/`. All are outward oriented; patch labels are 0 (no input groups).

use delamesh_core::mesh::{PatchId, SurfaceMesh};
use glam::{DVec2, DVec3};
use std::collections::{BTreeMap, BTreeSet};

fn single_patch(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>, name: &str) -> SurfaceMesh {
    SurfaceMesh {
        positions,
        patches: vec![PatchId(0); triangles.len()],
        triangles,
        patch_names: vec![name.to_string()],
    }
}

/// The prism `polygon × [0, height]` over a convex polygon given counter-clockwise, caps fanned
/// from the polygon's first vertex.
pub fn convex_prism(polygon: &[DVec2], height: f64) -> SurfaceMesh {
    let n = polygon.len() as u32;
    let positions = polygon
        .iter()
        .map(|p| p.extend(0.0))
        .chain(polygon.iter().map(|p| p.extend(height)))
        .collect();
    let mut triangles = Vec::new();
    for i in 1..n.saturating_sub(1) {
        triangles.push([0, i + 1, i]);
        triangles.push([n, n + i, n + i + 1]);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        triangles.push([i, j, n + j]);
        triangles.push([i, n + j, n + i]);
    }
    single_patch(positions, triangles, "prism")
}

/// A cylinder of `sides` facets around the z axis: two circular feature curves when the facets
/// turn by less than the feature angle (more than 6 sides at 60°).
pub fn cylinder(radius: f64, height: f64, sides: usize) -> SurfaceMesh {
    let polygon: Vec<DVec2> = (0..sides)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / sides as f64;
            radius * DVec2::new(a.cos(), a.sin())
        })
        .collect();
    convex_prism(&polygon, height)
}

/// A wedge whose edge along the z axis has a dihedral angle of `angle_deg`: the prism over the
/// isosceles triangle with that angle at the origin and sides of length `side`.
pub fn wedge(angle_deg: f64, side: f64, height: f64) -> SurfaceMesh {
    let a = angle_deg.to_radians();
    let polygon = [
        DVec2::ZERO,
        DVec2::new(side, 0.0),
        side * DVec2::new(a.cos(), a.sin()),
    ];
    convex_prism(&polygon, height)
}

/// The boundary of a union of unit voxels scaled by `size` (faces between a voxel and an empty
/// cell), vertices shared. The union must be edge-manifold (no voxels touching along an edge only).
pub fn voxels(cells: &[[i32; 3]], size: f64) -> SurfaceMesh {
    const SIDES: [([i32; 3], [usize; 4]); 6] = [
        ([0, 0, -1], [0, 2, 3, 1]),
        ([0, 0, 1], [4, 5, 7, 6]),
        ([0, -1, 0], [0, 1, 5, 4]),
        ([0, 1, 0], [2, 6, 7, 3]),
        ([-1, 0, 0], [0, 4, 6, 2]),
        ([1, 0, 0], [1, 3, 7, 5]),
    ];
    let filled: BTreeSet<[i32; 3]> = cells.iter().copied().collect();
    let mut index: BTreeMap<[i32; 3], u32> = BTreeMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for c in &filled {
        for (dir, quad) in SIDES {
            if filled.contains(&[c[0] + dir[0], c[1] + dir[1], c[2] + dir[2]]) {
                continue;
            }
            let [a, b, cc, d] = quad.map(|bits| {
                let g = [
                    c[0] + (bits & 1) as i32,
                    c[1] + ((bits >> 1) & 1) as i32,
                    c[2] + ((bits >> 2) & 1) as i32,
                ];
                *index.entry(g).or_insert_with(|| {
                    positions.push(size * DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64));
                    positions.len() as u32 - 1
                })
            });
            triangles.push([a, b, cc]);
            triangles.push([a, cc, d]);
        }
    }
    single_patch(positions, triangles, "voxels")
}

/// An L-shaped bracket: the prism over an L hexagon (three unit squares), one unit thick.
pub fn l_bracket() -> SurfaceMesh {
    voxels(&[[0, 0, 0], [1, 0, 0], [0, 1, 0]], 1.0)
}

/// A 3 × 3 × 1 box with a square through hole in the middle.
pub fn box_with_hole() -> SurfaceMesh {
    let ring: Vec<[i32; 3]> = (0..3)
        .flat_map(|i| (0..3).map(move |j| [i, j, 0]))
        .filter(|&[i, j, _]| (i, j) != (1, 1))
        .collect();
    voxels(&ring, 1.0)
}

/// Unit boxes `[0, 1]³` and `[1, 2] × [0, 1]²`, each with its own copy of the face `x = 1`: two
/// subdomains and an interface patch (the convention described in the crate documentation).
pub fn two_boxes() -> SurfaceMesh {
    let a = SurfaceMesh::cuboid(DVec3::ZERO, DVec3::ONE);
    let b = SurfaceMesh::cuboid(DVec3::X, DVec3::new(2.0, 1.0, 1.0));
    let offset = a.positions.len() as u32;
    let mut positions = a.positions;
    positions.extend(b.positions);
    let mut triangles = a.triangles;
    triangles.extend(b.triangles.iter().map(|t| t.map(|v| v + offset)));
    single_patch(positions, triangles, "boxes")
}
