//! Small constructions the 3D levels need on triangles and tetrahedra.

use super::engine::Candidate;
use crate::kernel::Point3;
use crate::oracle::Aabb;
use crate::triangulation::{CellId, Triangulation, VertexId};

/// The four vertex ids of a cell of a 3D triangulation.
pub(crate) fn cell_vertices<T: Triangulation>(tr: &T, c: CellId) -> [VertexId; 4] {
    let cell = tr.cell(c);
    let v = cell.as_ref();
    [v[0], v[1], v[2], v[3]]
}

/// Is `c` still the cell with vertices `stored`? Cell ids are recycled by the triangulation.
pub(crate) fn is_same_cell<T: Triangulation>(tr: &T, c: CellId, stored: &[VertexId; 4]) -> bool {
    tr.is_live(c) && tr.cell(c).as_ref() == stored.as_slice()
}

/// Is a vertex much closer to the centre of an empty ball (squared radius `radius2`) than the
/// ball's radius? In exact arithmetic no vertex is; one is when the centre was constructed from
/// nearly degenerate cells, and inserting it would create a near-duplicate vertex that no
/// amount of refinement can separate. The nearest vertex of a point that close is a vertex of
/// the cell containing it.
pub(crate) fn crowds_a_vertex<T: Triangulation<Point = Point3>>(
    tr: &T,
    c: &Candidate<Point3>,
    radius2: f64,
) -> bool {
    let Some(cell) = tr.locate(c.point, c.hint) else {
        return false;
    };
    tr.cell(cell)
        .as_ref()
        .iter()
        .filter(|&&v| !tr.is_infinite_vertex(v))
        .any(|&v| power_distance(tr, v, c.point) < 0.25 * radius2)
}

/// Power distance from `p` to vertex `v`: `|p − p_v|² − w_v`, the squared distance when `v` has
/// no weight (Delaunay), negative inside a protecting ball.
pub(crate) fn power_distance<T: Triangulation<Point = Point3>>(
    tr: &T,
    v: VertexId,
    p: Point3,
) -> f64 {
    tr.point(v).distance_squared(p) - tr.weight(v)
}

/// The three vertices of the facet of a cell opposite its vertex `i`.
pub(crate) fn facet_vertices(cell: &[VertexId; 4], i: usize) -> [VertexId; 3] {
    [cell[(i + 1) % 4], cell[(i + 2) % 4], cell[(i + 3) % 4]]
}

/// Where the centre of the ball through a facet and an apex lies along the facet's normal line.
///
/// The facet has circumcentre `center` and squared circumradius `radius2`; `axis` is its unit
/// normal pointing towards `apex`'s side. The centre is `center + t·axis`, with `t` from
/// `|center + t·axis − apex|² = radius2 + t²`. Only the apex's height above the facet's plane
/// is small for a nearly flat cell, and its sign is known from the side, so `t` gets the right
/// sign and a magnitude that is merely large (±∞ when the apex lies in the plane).
pub(crate) fn dual_parameter(center: Point3, radius2: f64, axis: Point3, apex: Point3) -> f64 {
    let height = axis.dot(apex - center).abs();
    (apex.distance_squared(center) - radius2) / (2.0 * height)
}

/// The dual Voronoi edge of a facet, from `center + lo·axis` to `center + hi·axis` (`axis` a
/// unit vector, the ends possibly infinite), clipped to a ball around `bbox` so that a segment
/// query gets ends with significant digits. `None` when the clipped edge is empty.
pub(crate) fn clipped_dual_edge(
    center: Point3,
    axis: Point3,
    lo: f64,
    hi: f64,
    bbox: &Aabb,
) -> Option<(Point3, Point3)> {
    let reach = center.distance(bbox.center()) + bbox.diagonal();
    // `f64::max` and `min` ignore a NaN end (an apex on the facet's circle and plane).
    let (lo, hi) = (lo.max(-reach), hi.min(reach));
    (lo <= hi).then(|| (center + lo * axis, center + hi * axis))
}

/// The normal of the facet `facet` (as [`facet_vertices`] lists it) of a positively oriented
/// cell, pointing away from the cell's vertex `i`. The side comes from the orientation the cell
/// is known to have, not from the sign of a dot product, which is noise for a nearly flat cell.
pub(crate) fn facet_normal_away_from_apex(facet: [Point3; 3], i: usize) -> Point3 {
    let [a, b, c] = facet;
    let normal = (b - a).cross(c - a);
    // `(v[i+1], v[i+2], v[i+3], v[i])` is `v` rotated by `i + 1` places, an odd permutation per
    // place; a positively oriented tetrahedron has `det[b - a, c - a, d - a] < 0`.
    if i % 2 == 0 { -normal } else { normal }
}

/// Circumcentre of a triangle in space.
pub(crate) fn triangle_circumcenter(a: Point3, b: Point3, c: Point3) -> Point3 {
    let ab = b - a;
    let ac = c - a;
    let n = ab.cross(ac);
    let n2 = n.length_squared();
    if n2 == 0.0 {
        return (a + b + c) / 3.0;
    }
    a + (ac.length_squared() * n.cross(ab) + ab.length_squared() * ac.cross(n)) / (2.0 * n2)
}

/// Centre and squared radius of the smallest sphere orthogonal to three weighted points (the
/// weighted circumcircle of a facet of a regular triangulation): the point of the triangle's
/// plane with the same power distance to the three, and that power distance.
pub(crate) fn weighted_triangle_circumcenter(p: [Point3; 3], w: [f64; 3]) -> (Point3, f64) {
    let (u, v) = (p[1] - p[0], p[2] - p[0]);
    let (uu, uv, vv) = (u.dot(u), u.dot(v), v.dot(v));
    let (ru, rv) = (0.5 * (uu + w[0] - w[1]), 0.5 * (vv + w[0] - w[2]));
    let det = uu * vv - uv * uv;
    if det == 0.0 {
        let c = (p[0] + p[1] + p[2]) / 3.0;
        return (c, c.distance_squared(p[0]) - w[0]);
    }
    let alpha = (ru * vv - rv * uv) / det;
    let beta = (rv * uu - ru * uv) / det;
    let x = alpha * u + beta * v;
    (p[0] + x, x.length_squared() - w[0])
}

/// Smallest angle of a triangle, in degrees.
pub(crate) fn triangle_min_angle_deg(a: Point3, b: Point3, c: Point3) -> f64 {
    let angle = |p: Point3, q: Point3, r: Point3| (q - p).angle_between(r - p).to_degrees();
    let (x, y) = (angle(a, b, c), angle(b, c, a));
    x.min(y).min(180.0 - x - y)
}

/// A tetrahedron is flat when |6V| ≤ `FLAT_VOLUME` · (longest edge)³: no solver can use it, and
/// its circumcentre has no significant digit. Checkers count |6V| ≤ 1e-12 · L³ as flat; the
/// margin catches the cells that rounding in a later stage could push below that.
pub(crate) const FLAT_VOLUME: f64 = 1e-9;

/// What checkers (and the tests) count as flat: |6V| ≤ `CHECKER_FLAT_VOLUME` · (longest edge)³.
pub(crate) const CHECKER_FLAT_VOLUME: f64 = 1e-12;

/// Is the tetrahedron `p` flat (see [`FLAT_VOLUME`])?
pub(crate) fn is_flat(p: &[Point3; 4]) -> bool {
    is_flat_within(p, FLAT_VOLUME)
}

/// Is |6V| of the tetrahedron `p` at most `ratio` times its longest edge cubed?
pub(crate) fn is_flat_within(p: &[Point3; 4], ratio: f64) -> bool {
    let mut longest2 = 0.0f64;
    for i in 0..4 {
        for j in i + 1..4 {
            longest2 = longest2.max(p[i].distance_squared(p[j]));
        }
    }
    let v6 = (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]);
    v6.abs() <= ratio * longest2 * longest2.sqrt()
}

/// Candidate refinement points of a flat cell: four facets times [`FLAT_HEIGHTS`], then four
/// facets times [`FLAT_FAR_HEIGHTS`].
pub(crate) const FLAT_CANDIDATES: usize = 4 * (FLAT_HEIGHTS.len() + FLAT_FAR_HEIGHTS.len());

/// Heights of the candidates above a facet's circumcentre, in facet circumradii.
const FLAT_HEIGHTS: [f64; 3] = [0.5, 0.75, 0.25];

/// Heights of the last candidates, in radii of the cell's largest protecting ball: a flat cell
/// of ball centres along a feature curve has every nearer candidate inside a ball.
const FLAT_FAR_HEIGHTS: [f64; 2] = [1.25, 2.0];

/// Candidate `attempt` of the refinement points that destroy a flat cell, with the squared
/// radius it is refined at.
///
/// The circumcentre of a flat cell is meaningless: cocircular points on a planar patch have a
/// whole line of empty spheres, and rounding puts the computed centre anywhere along it. The
/// cell's true circumsphere, for the orientation the triangulation gave it, is nearly the
/// half-space on one side of its plane; that side is known exactly from the orientation (see
/// [`dual_parameter`]). A point on the normal line through a facet's circumcentre, on that side
/// and less than the facet's circumradius `r` from it, lies inside that sphere whatever its
/// size, so inserting it destroys the cell, and it is off the plane, so it cannot make new flat
/// cells with the facets. Candidates go through the facets from the largest, at heights
/// [`FLAT_HEIGHTS`]; the caller tries the next one when a candidate is refused forever (inside
/// a protecting ball, crowding a vertex).
pub(crate) fn flat_cell_refinement_point<T: Triangulation<Point = Point3>>(
    tr: &T,
    cell: &[VertexId; 4],
    attempt: usize,
) -> Option<(Point3, f64)> {
    let area2 = |i: usize| {
        let [a, b, c] = facet_vertices(cell, i).map(|v| tr.point(v));
        (b - a).cross(c - a).length_squared()
    };
    let mut facets = [0, 1, 2, 3];
    facets.sort_by(|&x, &y| area2(y).total_cmp(&area2(x)));
    let near = 4 * FLAT_HEIGHTS.len();
    let (i, height) = if attempt < near {
        (
            attempt / FLAT_HEIGHTS.len(),
            Height::Near(FLAT_HEIGHTS[attempt % FLAT_HEIGHTS.len()]),
        )
    } else {
        let far = attempt - near;
        let h = *FLAT_FAR_HEIGHTS.get(far % FLAT_FAR_HEIGHTS.len())?;
        (far / FLAT_FAR_HEIGHTS.len(), Height::Far(h))
    };
    let i = *facets.get(i)?;
    let fv = facet_vertices(cell, i);
    let facet = fv.map(|v| tr.point(v));
    let weights = fv.map(|v| tr.weight(v));
    let (center, radius2) = if weights == [0.0; 3] {
        let center = triangle_circumcenter(facet[0], facet[1], facet[2]);
        (center, center.distance_squared(facet[0]))
    } else {
        weighted_triangle_circumcenter(facet, weights)
    };
    let axis = facet_normal_away_from_apex(facet, i).normalize_or_zero();
    if axis == Point3::ZERO || !center.is_finite() || radius2 <= 0.0 {
        return None;
    }
    let apex = cell[i];
    let t = -dual_parameter(center, radius2 + tr.weight(apex), -axis, tr.point(apex));
    let side = if t < 0.0 { -1.0 } else { 1.0 };
    let distance = match height {
        Height::Near(h) => h * radius2.sqrt(),
        Height::Far(h) => {
            let ball = cell
                .iter()
                .map(|&v| tr.weight(v))
                .fold(0.0, f64::max)
                .sqrt();
            // Inside the cell's orthosphere, centred `t` along the axis: below `2|t|`.
            let d = (h * ball).min(0.95 * t.abs());
            if ball <= radius2.sqrt() || !d.is_finite() {
                return None;
            }
            d
        }
    };
    Some((center + side * distance * axis, radius2))
}

/// How high above a facet a flat cell's candidate lies.
#[derive(Clone, Copy)]
enum Height {
    /// In facet circumradii.
    Near(f64),
    /// In radii of the cell's largest protecting ball.
    Far(f64),
}

/// Length of the shortest edge of a tetrahedron.
pub(crate) fn shortest_edge(p: &[Point3; 4]) -> f64 {
    let mut m = f64::INFINITY;
    for i in 0..4 {
        for j in i + 1..4 {
            m = m.min(p[i].distance_squared(p[j]));
        }
    }
    m.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scalene triangle with its corners at heights `z`.
    fn triangle(z: [f64; 3]) -> [Point3; 3] {
        let xy = [(1.0, 0.2), (-0.3, 2.0), (0.5, -1.0)];
        std::array::from_fn(|i| Point3::new(xy[i].0, xy[i].1, z[i]))
    }

    #[test]
    fn circumcenter_is_equidistant_and_coplanar() {
        let [a, b, c] = triangle([0.0, 1.0, 2.0]);
        let o = triangle_circumcenter(a, b, c);
        let (ra, rb, rc) = (o.distance(a), o.distance(b), o.distance(c));
        assert!((ra - rb).abs() < 1e-12 && (ra - rc).abs() < 1e-12);
        assert!((o - a).dot((b - a).cross(c - a)).abs() < 1e-12);
    }

    #[test]
    fn dual_parameter_gives_the_circumcentre_of_the_cell() {
        let [a, b, c] = triangle([0.0, 0.1, 0.2]);
        let center = triangle_circumcenter(a, b, c);
        let axis = (b - a).cross(c - a).normalize();
        for apex in [
            Point3::new(0.2, 0.3, 1.5),
            Point3::new(3.0, -2.0, -0.7),
            Point3::new(0.1, 0.4, -0.2),
        ] {
            let side = if axis.dot(apex - a) > 0.0 {
                axis
            } else {
                -axis
            };
            let o = center + dual_parameter(center, center.distance_squared(a), side, apex) * side;
            let r = o.distance(a);
            for p in [b, c, apex] {
                assert!((o.distance(p) - r).abs() < 1e-9 * r.max(1.0));
            }
        }
    }

    #[test]
    fn nearly_flat_cell_has_its_circumcentre_on_the_right_side() {
        // An apex inside the facet's circle, a hair above its plane: the circumcentre is far
        // away on the side opposite the apex, never on the apex's side.
        let (a, b, c) = (Point3::X, Point3::Y, Point3::new(-1.0, -1.0, 0.0));
        let center = triangle_circumcenter(a, b, c);
        let radius2 = center.distance_squared(a);
        let apex = Point3::new(0.1, 0.1, 1e-15);
        let t = dual_parameter(center, radius2, Point3::Z, apex);
        assert!(t < -1e10);
        // In the plane, outside the circle: at +∞ on the apex's side.
        let t = dual_parameter(center, radius2, Point3::Z, Point3::new(5.0, 5.0, 0.0));
        assert_eq!(t, f64::INFINITY);
    }

    #[test]
    fn facet_normals_point_away_from_the_apex() {
        use crate::kernel::{Sign, orient3d};
        let mut p = [
            Point3::new(0.1, 0.0, 0.2),
            Point3::new(1.0, 0.3, -0.1),
            Point3::new(0.2, 1.1, 0.0),
            Point3::new(0.3, 0.2, 0.9),
        ];
        for flip in [false, true] {
            if flip || orient3d(p[0], p[1], p[2], p[3]) != Sign::Positive {
                p.swap(0, 1);
            }
            assert_eq!(orient3d(p[0], p[1], p[2], p[3]), Sign::Positive);
            let ids = [0, 1, 2, 3].map(VertexId);
            for i in 0..4 {
                let facet = facet_vertices(&ids, i).map(|v| p[v.0 as usize]);
                let normal = facet_normal_away_from_apex(facet, i);
                assert!(normal.dot(p[i] - facet[0]) < 0.0, "facet {i}");
            }
            p.swap(2, 3);
        }
    }

    #[test]
    fn dual_edge_is_clipped_to_the_box() {
        let bbox = Aabb {
            min: Point3::splat(-1.0),
            max: Point3::splat(1.0),
        };
        let center = Point3::new(0.1, 0.2, 0.3);
        let in_reach = |p: Point3| p.distance(bbox.center()) <= 2.0 * bbox.diagonal();
        let (p, q) = clipped_dual_edge(center, Point3::Z, -4.8e15, 0.2, &bbox).unwrap();
        assert!(p.z < -1.0 && in_reach(p) && (q.z - 0.5).abs() < 1e-12);
        let (p, q) = clipped_dual_edge(center, Point3::Z, 0.2, f64::INFINITY, &bbox).unwrap();
        assert!((p.z - 0.5).abs() < 1e-12 && q.z > 1.0 && in_reach(q));
        let (p, q) = clipped_dual_edge(center, Point3::Z, f64::NAN, f64::NAN, &bbox).unwrap();
        assert!(p.z < -1.0 && q.z > 1.0);
        assert!(clipped_dual_edge(center, Point3::Z, 1e9, f64::INFINITY, &bbox).is_none());
    }

    #[test]
    fn weighted_circumcenter_has_equal_powers() {
        let p = triangle([0.0, 1.0, 2.0]);
        let w = [0.3, 0.0, 1.1];
        let (c, r2) = weighted_triangle_circumcenter(p, w);
        for i in 0..3 {
            assert!((c.distance_squared(p[i]) - w[i] - r2).abs() < 1e-12);
        }
        assert!((c - p[0]).dot((p[1] - p[0]).cross(p[2] - p[0])).abs() < 1e-12);
        let (o, r2) = weighted_triangle_circumcenter(p, [0.0; 3]);
        assert!(o.distance(triangle_circumcenter(p[0], p[1], p[2])) < 1e-12);
        assert!((r2 - o.distance_squared(p[0])).abs() < 1e-12);
    }

    #[test]
    fn equilateral_min_angle_is_60() {
        let a = Point3::ZERO;
        let b = Point3::X;
        let c = Point3::new(0.5, 3f64.sqrt() / 2.0, 0.0);
        assert!((triangle_min_angle_deg(a, b, c) - 60.0).abs() < 1e-9);
    }
}
