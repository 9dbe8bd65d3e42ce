//! Retriangulation of the planar regions of a surface by Lawson flips, as TetGen merges coplanar
//! facets: CAD and CSG exports triangulate each planar face as a fan of slivers whose angles
//! (0.01° on random CSG parts) no mesh that keeps those triangles can avoid in its cells. Flipping
//! each edge between two coplanar triangles of one patch to the other diagonal of their quad,
//! while that raises the smaller angle of the pair, gives each planar region the triangulation of
//! its own vertices with the largest smallest angle (its constrained Delaunay triangulation). The
//! region's outline, its vertices and the surface's other triangles are kept.

use super::PatchId;
use crate::kernel::{Point3, Sign, orient3d};
use crate::refine::triangle_min_angle_deg;
use rustc_hash::FxHashMap as HashMap;

/// What [`flip_coplanar`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CoplanarFlips {
    /// Edges flipped.
    pub flips: usize,
    /// Largest distance the surface moved: 0 when every flipped quad was exactly planar.
    pub moved: f64,
}

/// Most flips per triangle: Lawson's flips end on their own; this only bounds the work.
const MAX_FLIPS_PER_TRIANGLE: usize = 64;

/// Smallest gain of the pair's smaller angle (degrees) that makes a flip: each flip raises the
/// sorted angles of the surface, so flips cannot cycle even where rounding blurs the angles.
const MIN_GAIN: f64 = 1e-7;

/// Flips, in place, the edges shared by two triangles of one patch whose quad is convex and
/// planar to within `tolerance` (a distance: 0 flips only exactly coplanar quads) while the
/// flip raises the smaller angle of the two triangles. Orientation is kept; an edge that would
/// duplicate an existing one is left.
///
/// ```
/// use delamesh_core::kernel::Point3;
/// use delamesh_core::mesh::{PatchId, flip_coplanar};
/// // A flat rhombus split along its long diagonal into two slivers: the flip takes the short
/// // one.
/// let p = [
///     Point3::new(0.0, 0.0, 0.0),
///     Point3::new(4.0, 0.0, 0.0),
///     Point3::new(2.0, 0.2, 0.0),
///     Point3::new(2.0, -0.2, 0.0),
/// ];
/// let mut t = vec![[0, 1, 2], [1, 0, 3]];
/// let done = flip_coplanar(&p, &mut t, &[PatchId(1); 2], 0.0);
/// assert_eq!(done.flips, 1);
/// assert!(t.iter().all(|f| f.contains(&2) && f.contains(&3)));
/// ```
pub fn flip_coplanar(
    points: &[Point3],
    triangles: &mut [[u32; 3]],
    patches: &[PatchId],
    tolerance: f64,
) -> CoplanarFlips {
    let mut done = CoplanarFlips::default();
    // Each directed edge `u → v` with its triangle; a closed, oriented surface has each twice.
    let mut edge: HashMap<(u32, u32), usize> = HashMap::default();
    // Edges of more than two triangles, or of two that disagree on orientation: never flipped.
    let mut uses: HashMap<(u32, u32), usize> = HashMap::default();
    for (t, f) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (u, v) = (f[k], f[(k + 1) % 3]);
            *uses.entry((u.min(v), u.max(v))).or_default() += 1;
            if edge.insert((u, v), t).is_some() {
                *uses.entry((u.min(v), u.max(v))).or_default() += 2;
            }
        }
    }
    let mut stack: Vec<(u32, u32)> = triangles
        .iter()
        .flat_map(|f| (0..3).map(move |k| (f[k], f[(k + 1) % 3])))
        .filter(|&(u, v)| u < v)
        .collect();
    stack.reverse();
    let budget = MAX_FLIPS_PER_TRIANGLE.saturating_mul(triangles.len());
    while let Some((a, b)) = stack.pop() {
        if done.flips >= budget {
            break;
        }
        let (Some(&t1), Some(&t2)) = (edge.get(&(a, b)), edge.get(&(b, a))) else {
            continue;
        };
        if uses.get(&(a, b)) != Some(&2) {
            continue;
        }
        if t1 == t2 || patches.get(t1) != patches.get(t2) {
            continue;
        }
        let c = third(triangles[t1], a, b);
        let d = third(triangles[t2], a, b);
        if c == d || edge.contains_key(&(c, d)) || edge.contains_key(&(d, c)) {
            continue;
        }
        let Some(moved) = flip_gain(points, [a, b, c, d], tolerance) else {
            continue;
        };
        // (a, b, c) and (b, a, d) become (c, a, d) and (c, d, b): the quad a, d, b, c in turn.
        triangles[t1] = [c, a, d];
        triangles[t2] = [c, d, b];
        edge.remove(&(a, b));
        edge.remove(&(b, a));
        uses.remove(&(a, b));
        uses.insert((c.min(d), c.max(d)), 2);
        for (u, v, t) in [
            (c, a, t1),
            (a, d, t1),
            (d, c, t1),
            (c, d, t2),
            (d, b, t2),
            (b, c, t2),
        ] {
            edge.insert((u, v), t);
        }
        done.flips += 1;
        done.moved = done.moved.max(moved);
        stack.extend([(a, d), (d, b), (b, c), (c, a)].map(|(u, v)| (u.min(v), u.max(v))));
    }
    done
}

/// The vertex of `f` other than `a` and `b`.
fn third(f: [u32; 3], a: u32, b: u32) -> u32 {
    f.into_iter().find(|&v| v != a && v != b).unwrap_or(a)
}

/// For triangles `(a, b, c)` and `(b, a, d)`: `Some(distance the surface moves)` when their quad
/// is planar to within `tolerance`, strictly convex, and the diagonal `c d` gives a larger
/// smaller angle than `a b` (by [`MIN_GAIN`]).
fn flip_gain(points: &[Point3], [a, b, c, d]: [u32; 4], tolerance: f64) -> Option<f64> {
    let [pa, pb, pc, pd] = [a, b, c, d].map(|v| points[v as usize]);
    let moved = if orient3d(pa, pb, pc, pd) == Sign::Zero {
        0.0
    } else {
        // The surface sweeps the tetrahedron a b c d: it moves by at most its largest height.
        let volume6 = (pb - pa).cross(pc - pa).dot(pd - pa).abs();
        let area2 = [(pa, pb, pc), (pa, pb, pd), (pa, pc, pd), (pb, pc, pd)]
            .map(|(x, y, z)| (y - x).cross(z - x).length())
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        let height = volume6 / area2;
        if height.is_nan() || height > tolerance {
            return None;
        }
        height
    };
    // Orientation within the plane: orient3d against a point off it, on the normal's dominant
    // axis, has one sign for every counter-clockwise triple of the quad.
    let normal = (pb - pa).cross(pc - pa);
    let axis = normal.abs().max_position();
    let mut off = pa;
    off[axis] += if normal[axis] >= 0.0 { 1.0 } else { -1.0 } * (pb - pa).length().max(1.0);
    let side = |x: Point3, y: Point3, z: Point3| orient3d(x, y, z, off);
    let up = side(pa, pb, pc);
    // Both triangles turn the same way (the pair does not fold back) and the new diagonal
    // crosses the old one strictly inside both.
    if up == Sign::Zero
        || side(pb, pa, pd) != up
        || side(pc, pd, pb) != up
        || side(pd, pc, pa) != up
    {
        return None;
    }
    let before = smallest_angle(pa, pb, pc).min(smallest_angle(pb, pa, pd));
    let after = smallest_angle(pc, pa, pd).min(smallest_angle(pc, pd, pb));
    (after > before + MIN_GAIN).then_some(moved)
}

/// The smallest angle of a triangle (degrees), computed the same whatever the vertex order,
/// so that a flip and its reverse cannot both gain.
fn smallest_angle(a: Point3, b: Point3, c: Point3) -> f64 {
    let mut p = [a, b, c];
    p.sort_by(|x, y| {
        x.to_array()
            .partial_cmp(&y.to_array())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    triangle_min_angle_deg(p[0], p[1], p[2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::Point3;

    /// A fan of slivers over an ellipse's polygon (axes 3 and 1) in the plane z = h, closed by
    /// a cone below.
    fn fan(n: u32, h: f64) -> (Vec<Point3>, Vec<[u32; 3]>, Vec<PatchId>) {
        let mut p: Vec<Point3> = (0..n)
            .map(|k| {
                let t = std::f64::consts::TAU * f64::from(k) / f64::from(n);
                Point3::new(3.0 * t.cos(), t.sin(), h)
            })
            .collect();
        p.push(Point3::new(0.0, 0.0, h - 1.0));
        let apex = n;
        let mut t = Vec::new();
        let mut patches = Vec::new();
        // The top: a fan from vertex 0, counter-clockwise seen from above.
        for k in 1..n - 1 {
            t.push([0, k, k + 1]);
            patches.push(PatchId(1));
        }
        for k in 0..n {
            t.push([apex, (k + 1) % n, k]);
            patches.push(PatchId(2));
        }
        (p, t, patches)
    }

    fn directed_edges(t: &[[u32; 3]]) -> Vec<(u32, u32)> {
        let mut e: Vec<(u32, u32)> = t
            .iter()
            .flat_map(|f| (0..3).map(move |k| (f[k], f[(k + 1) % 3])))
            .collect();
        e.sort_unstable();
        e
    }

    #[test]
    fn a_fan_becomes_the_polygons_delaunay_triangulation_and_the_surface_stays_closed() {
        let (p, mut t, patches) = fan(24, 0.5);
        let before = t.clone();
        let area = |t: &[[u32; 3]]| -> f64 {
            t.iter()
                .map(|f| {
                    let [a, b, c] = f.map(|v| p[v as usize]);
                    (b - a).cross(c - a).z * 0.5
                })
                .sum()
        };
        let done = flip_coplanar(&p, &mut t, &patches, 0.0);
        assert!(done.flips > 0);
        assert_eq!(done.moved, 0.0);
        // Still closed and oriented: every directed edge once, with its twin.
        let e = directed_edges(&t);
        assert!(e.windows(2).all(|w| w[0] != w[1]));
        assert!(e.iter().all(|&(u, v)| e.binary_search(&(v, u)).is_ok()));
        // The cone (another patch) is untouched; the top keeps its area and orientation.
        assert_eq!(t[22..], before[22..]);
        assert!((area(&t[..22]) - area(&before[..22])).abs() < 1e-12);
        assert!(t[..22].iter().all(|f| {
            let [a, b, c] = f.map(|v| p[v as usize]);
            (b - a).cross(c - a).z > 0.0
        }));
        let worst = |t: &[[u32; 3]]| {
            t.iter()
                .map(|f| smallest_angle(p[f[0] as usize], p[f[1] as usize], p[f[2] as usize]))
                .fold(f64::INFINITY, f64::min)
        };
        // The fan's smallest angle is 2.5°: the flips leave ears only where the ellipse bends.
        assert!(worst(&t[..22]) > worst(&before[..22]) + 0.1);
        // Locally optimal: no flip is left.
        let again = flip_coplanar(&p, &mut t, &patches, 0.0);
        assert_eq!(again.flips, 0);
    }

    #[test]
    fn quads_off_the_plane_flip_only_within_the_tolerance() {
        let p = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(4.0, 0.0, 0.0),
            Point3::new(2.0, 0.2, 1e-6),
            Point3::new(2.0, -0.2, 0.0),
        ];
        let patches = [PatchId(1); 2];
        let mut t = vec![[0, 1, 2], [1, 0, 3]];
        assert_eq!(flip_coplanar(&p, &mut t, &patches, 1e-7).flips, 0);
        let done = flip_coplanar(&p, &mut t, &patches, 1e-5);
        assert_eq!(done.flips, 1);
        assert!(done.moved > 0.0 && done.moved <= 1e-5);
        // A fin on the edge (three triangles) keeps it.
        let mut t = vec![[0, 1, 2], [1, 0, 3], [0, 1, 3]];
        assert_eq!(flip_coplanar(&p, &mut t, &[PatchId(1); 3], 1.0).flips, 0);
        // A pair of two patches, or folded back, never flips.
        let mut t = vec![[0, 1, 2], [1, 0, 3]];
        assert_eq!(
            flip_coplanar(&p, &mut t, &[PatchId(1), PatchId(2)], 1.0).flips,
            0
        );
        let folded = [p[0], p[1], p[2], Point3::new(2.0, 0.1, 0.0)];
        let mut t = vec![[0, 1, 2], [1, 0, 3]];
        assert_eq!(flip_coplanar(&folded, &mut t, &patches, 1.0).flips, 0);
    }
}
