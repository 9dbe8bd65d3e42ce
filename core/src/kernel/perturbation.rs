//! Symbolic perturbation of the in-sphere predicates (simulation of simplicity).
//!
//! The lift `|p|²` of every point is raised by an infinitesimal `ε_p`, with `ε_p ≫ ε_q` whenever `p`
//! comes after `q` in the lexicographic order of coordinates. The perturbed points are in general
//! position for the lifted determinant, so "on the sphere" never happens and the Delaunay
//! triangulation is unique and independent of the insertion order (the order is a property of the
//! points, not of their insertion rank). Coordinates themselves are not perturbed: orientation
//! degeneracies of finite points are real and handled by the triangulation.
//!
//! The 5×5 lifted determinant is linear in the lift column, so once the exact value is zero its
//! sign is that of the cofactor of the largest infinitesimal whose cofactor is non-zero. The
//! cofactor of a cell vertex `v` is the orientation of the cell with `v` replaced by the query
//! point; the cofactor of the query point is minus the (positive) orientation of the cell.

use super::power::{WeightedPoint3, coplanar_power_test, off_plane_point, power_test};
use super::{Point3, Sign, insphere, orient3d};
use std::cmp::Ordering;

/// The total order of the perturbation: lexicographic on `(x, y, z)`. Inputs are finite.
#[inline]
pub fn lex_cmp(a: Point3, b: Point3) -> Ordering {
    a.x.partial_cmp(&b.x)
        .unwrap_or(Ordering::Equal)
        .then(a.y.partial_cmp(&b.y).unwrap_or(Ordering::Equal))
        .then(a.z.partial_cmp(&b.z).unwrap_or(Ordering::Equal))
}

/// Indices `0..N` of `pts` sorted from the lexicographically largest point down (the order in which
/// the perturbation's infinitesimals dominate).
#[inline]
fn by_decreasing_rank<const N: usize>(pts: &[Point3; N]) -> [usize; N] {
    let mut idx = [0usize; N];
    for (i, slot) in idx.iter_mut().enumerate() {
        *slot = i;
    }
    // Insertion sort: N ≤ 5.
    for i in 1..N {
        let mut j = i;
        while j > 0 && lex_cmp(pts[idx[j - 1]], pts[idx[j]]) == Ordering::Less {
            idx.swap(j - 1, j);
            j -= 1;
        }
    }
    idx
}

/// Is `e` strictly inside the perturbed circumsphere of the positively oriented tetrahedron
/// `cell`? Never undecided; `e` must differ from the cell's vertices.
#[inline]
pub fn in_sphere_perturbed(cell: [Point3; 4], e: Point3) -> bool {
    match insphere(cell[0], cell[1], cell[2], cell[3], e) {
        Sign::Positive => true,
        Sign::Negative => false,
        Sign::Zero => in_sphere_tie_break(cell, e),
    }
}

#[cold]
fn in_sphere_tie_break(cell: [Point3; 4], e: Point3) -> bool {
    let pts = [cell[0], cell[1], cell[2], cell[3], e];
    for k in by_decreasing_rank(&pts) {
        if k == 4 {
            // The query's own lift dominates: raising it moves it outside.
            return false;
        }
        let mut t = cell;
        t[k] = e;
        match orient3d(t[0], t[1], t[2], t[3]) {
            Sign::Positive => return true,
            Sign::Negative => return false,
            Sign::Zero => {}
        }
    }
    unreachable!("the query point is one of the ranked points")
}

/// For `e` coplanar with the non-collinear triangle `tri`: is `e` strictly inside the perturbed
/// circumcircle of `tri`? The same perturbation as [`in_sphere_perturbed`], restricted to the
/// plane (this is the conflict test of a hull facet with a point on its supporting plane).
pub fn in_circle_coplanar_perturbed(tri: [Point3; 3], e: Point3) -> bool {
    let (q, plane_sign) = off_plane_point(tri);
    // Any sphere through the triangle cuts its plane along the triangle's circumcircle.
    let s = insphere(tri[0], tri[1], tri[2], q, e);
    if s != Sign::Zero {
        return s == plane_sign;
    }
    in_circle_tie_break(tri, q, plane_sign, e)
}

/// The perturbed answer for a query exactly on the (orthogonal) circle of `tri`, with `q` and
/// `plane_sign` from [`off_plane_point`]. The lifts' infinitesimals do not depend on weights.
#[cold]
fn in_circle_tie_break(tri: [Point3; 3], q: Point3, plane_sign: Sign, e: Point3) -> bool {
    let pts = [tri[0], tri[1], tri[2], e];
    for k in by_decreasing_rank(&pts) {
        if k == 3 {
            return false;
        }
        let mut t = tri;
        t[k] = e;
        let o = orient3d(t[0], t[1], t[2], q);
        if o != Sign::Zero {
            return o == plane_sign;
        }
    }
    unreachable!("the query point is one of the ranked points")
}

/// Does the weighted point `e` conflict with the positively oriented weighted tetrahedron `cell`
/// (negative power distance to its orthogonal sphere)? Exact ties are broken by the same
/// perturbation of the lifts as [`in_sphere_perturbed`] (the lift `|p|² − w` is linear in the
/// perturbed column, so its cofactors are the same orientations), hence with all weights zero the
/// answer is exactly the in-sphere one. `e` must not share its position with a vertex of `cell`
/// and the same weight.
pub fn power_test_perturbed(cell: [WeightedPoint3; 4], e: WeightedPoint3) -> bool {
    match power_test(cell[0], cell[1], cell[2], cell[3], e) {
        Sign::Positive => true,
        Sign::Negative => false,
        Sign::Zero => in_sphere_tie_break(cell.map(|c| c.point), e.point),
    }
}

/// [`beyond_hull_facet_perturbed`] for weighted points: on the hull facet's plane, the conflict
/// test is the coplanar power test against the circle orthogonal to the facet's vertices.
pub fn power_beyond_hull_facet_perturbed(
    tri: [WeightedPoint3; 3],
    orient: Sign,
    e: WeightedPoint3,
) -> bool {
    match orient {
        Sign::Positive => true,
        Sign::Negative => false,
        Sign::Zero => match coplanar_power_test(tri[0], tri[1], tri[2], e) {
            Sign::Positive => true,
            Sign::Negative => false,
            Sign::Zero => {
                let points = tri.map(|t| t.point);
                let (q, plane_sign) = off_plane_point(points);
                in_circle_tie_break(points, q, plane_sign, e.point)
            }
        },
    }
}

/// Is `e` in conflict with the infinite cell whose finite facet, completed by `e`, gives the
/// orientation `orient` (positive when `e` lies strictly beyond the hull facet `tri`)?
#[inline]
pub fn beyond_hull_facet_perturbed(tri: [Point3; 3], orient: Sign, e: Point3) -> bool {
    match orient {
        Sign::Positive => true,
        Sign::Negative => false,
        Sign::Zero => in_circle_coplanar_perturbed(tri, e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube_cell() -> [Point3; 4] {
        // Positively oriented (see predicates::orient3d).
        let c = [
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(0.0, 0.0, 1.0),
            Point3::new(0.0, 0.0, 0.0),
        ];
        assert_eq!(orient3d(c[0], c[1], c[2], c[3]), Sign::Positive);
        c
    }

    #[test]
    fn cospherical_points_are_decided_and_consistent() {
        // (1,1,1) is on the sphere of the corner tetrahedron of the unit cube.
        let cell = cube_cell();
        let e = Point3::ONE;
        assert_eq!(insphere(cell[0], cell[1], cell[2], cell[3], e), Sign::Zero);
        let inside = in_sphere_perturbed(cell, e);
        // Exactly one of the two tetrahedra sharing a facet with e's side can be Delaunay: swapping
        // the roles of e and the vertex it would replace must give the opposite answer.
        for k in 0..4 {
            let mut other = cell;
            other[k] = e;
            if orient3d(other[0], other[1], other[2], other[3]) == Sign::Positive {
                assert_ne!(in_sphere_perturbed(other, cell[k]), inside);
            }
        }
    }

    #[test]
    fn perturbation_is_invariant_under_even_permutations_of_the_cell() {
        let cell = cube_cell();
        let e = Point3::ONE;
        let rotated = [cell[1], cell[2], cell[0], cell[3]];
        assert_eq!(
            in_sphere_perturbed(cell, e),
            in_sphere_perturbed(rotated, e)
        );
    }

    #[test]
    fn coplanar_cocircular_points_are_decided_consistently() {
        let a = Point3::new(0.0, 0.0, 5.0);
        let b = Point3::new(1.0, 0.0, 5.0);
        let c = Point3::new(1.0, 1.0, 5.0);
        let d = Point3::new(0.0, 1.0, 5.0);
        let inside = in_circle_coplanar_perturbed([a, b, c], d);
        assert_eq!(in_circle_coplanar_perturbed([b, c, a], d), inside);
        assert_eq!(in_circle_coplanar_perturbed([b, a, c], d), inside);
        // The square has two diagonals; the perturbation must make exactly one pair of triangles empty.
        let diagonal_ac = !in_circle_coplanar_perturbed([a, b, c], d)
            && !in_circle_coplanar_perturbed([a, c, d], b);
        let diagonal_bd = !in_circle_coplanar_perturbed([a, b, d], c)
            && !in_circle_coplanar_perturbed([b, c, d], a);
        assert!(diagonal_ac != diagonal_bd);
        assert!(in_circle_coplanar_perturbed(
            [a, b, c],
            Point3::new(0.5, 0.5, 5.0)
        ));
        assert!(!in_circle_coplanar_perturbed(
            [a, b, c],
            Point3::new(3.0, 0.5, 5.0)
        ));
    }

    #[test]
    fn perturbed_in_sphere_is_consistent_across_a_cospherical_grid() {
        // For every positively oriented tetrahedron of lattice points and every fifth lattice
        // point, even permutations of the cell leave the answer unchanged.
        let pts: Vec<Point3> = (0..27)
            .map(|i| Point3::new((i % 3) as f64, (i / 3 % 3) as f64, (i / 9) as f64))
            .collect();
        let mut checked = 0;
        for a in 0..27 {
            for b in (a + 1)..27 {
                for c in (b + 1)..27 {
                    let (d, e) = ((a + b + c) % 27, (a * 7 + c) % 27);
                    if [a, b, c].contains(&d) || [a, b, c, d].contains(&e) {
                        continue;
                    }
                    let mut cell = [pts[a], pts[b], pts[c], pts[d]];
                    match orient3d(cell[0], cell[1], cell[2], cell[3]) {
                        Sign::Zero => continue,
                        Sign::Negative => cell.swap(0, 1),
                        Sign::Positive => {}
                    }
                    let inside = in_sphere_perturbed(cell, pts[e]);
                    for perm in [[1, 2, 0, 3], [2, 0, 1, 3], [1, 0, 3, 2], [3, 2, 1, 0]] {
                        assert_eq!(in_sphere_perturbed(perm.map(|k| cell[k]), pts[e]), inside);
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked > 100);
    }
}
