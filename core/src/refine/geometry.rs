//! Small constructions the 3D levels need on triangles and tetrahedra.

use super::engine::Candidate;
use crate::kernel::Point3;
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

    #[test]
    fn circumcenter_is_equidistant_and_coplanar() {
        let (a, b, c) = (
            Point3::new(1.0, 0.2, 0.0),
            Point3::new(-0.3, 2.0, 1.0),
            Point3::new(0.5, -1.0, 2.0),
        );
        let o = triangle_circumcenter(a, b, c);
        let (ra, rb, rc) = (o.distance(a), o.distance(b), o.distance(c));
        assert!((ra - rb).abs() < 1e-12 && (ra - rc).abs() < 1e-12);
        assert!((o - a).dot((b - a).cross(c - a)).abs() < 1e-12);
    }

    #[test]
    fn weighted_circumcenter_has_equal_powers() {
        let p = [
            Point3::new(1.0, 0.2, 0.0),
            Point3::new(-0.3, 2.0, 1.0),
            Point3::new(0.5, -1.0, 2.0),
        ];
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
