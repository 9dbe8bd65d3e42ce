//! Welding of triangle soups by exact position, so that a closed STL or glTF surface comes out closed.

use glam::DVec3;
use std::collections::HashMap;

/// Merges vertices with bit-identical coordinates (`-0.0` counts as `0.0`) and renumbers `triangles`.
///
/// Survivors keep their first-occurrence order, so a mesh without duplicates is returned unchanged.
/// Returns the number of vertices removed.
pub fn weld_exact(positions: &mut Vec<DVec3>, triangles: &mut [[u32; 3]]) -> usize {
    weld_exact_indices(positions, triangles.as_flattened_mut())
}

/// [`weld_exact`] for any list of vertex indices (the corners of polygons of any size).
pub fn weld_exact_indices(positions: &mut Vec<DVec3>, indices: &mut [u32]) -> usize {
    // Adding 0.0 turns -0.0 into +0.0 and leaves every other value (NaN included) bit-identical.
    let key = |p: DVec3| {
        [
            (p.x + 0.0).to_bits(),
            (p.y + 0.0).to_bits(),
            (p.z + 0.0).to_bits(),
        ]
    };
    let mut first: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len());
    let mut remap = Vec::with_capacity(positions.len());
    let mut kept = Vec::with_capacity(positions.len());
    for &p in positions.iter() {
        let next = kept.len() as u32;
        let id = *first.entry(key(p)).or_insert(next);
        if id == next {
            kept.push(p);
        }
        remap.push(id);
    }
    let merged = positions.len() - kept.len();
    if merged > 0 {
        for v in indices.iter_mut() {
            if let Some(&r) = remap.get(*v as usize) {
                *v = r;
            }
        }
        *positions = kept;
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn soup_of_two_triangles_shares_an_edge_after_welding() {
        let mut p = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::X,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, -0.0),
        ];
        let mut t = vec![[0, 1, 2], [3, 4, 5]];
        assert_eq!(weld_exact(&mut p, &mut t), 2);
        assert_eq!(p.len(), 4);
        assert_eq!(t, vec![[0, 1, 2], [1, 3, 2]]);
    }

    #[test]
    fn distinct_positions_are_left_alone() {
        let mut p = vec![DVec3::ZERO, DVec3::X, DVec3::new(f64::EPSILON, 0.0, 0.0)];
        let mut t = vec![[0, 1, 2]];
        assert_eq!(weld_exact(&mut p, &mut t), 0);
        assert_eq!(p.len(), 3);
        assert_eq!(t, vec![[0, 1, 2]]);
    }
}
