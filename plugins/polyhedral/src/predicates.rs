//! Exact segment–triangle tests on top of Shewchuk's adaptive `orient3d`.

use glam::DVec3;
use std::cmp::Ordering;

/// Sign of the orientation of `d` relative to the plane of `a b c`: positive when `d` lies on the
/// side the normal `(b - a) × (c - a)` points away from (`a b c` clockwise seen from `d`).
pub(crate) fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Ordering {
    let k = |p: DVec3| robust::Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    };
    robust::orient3d(k(a), k(b), k(c), k(d))
        .partial_cmp(&0.0)
        .unwrap_or(Ordering::Equal)
}

/// Are `a`, `b`, `c` exactly collinear (a triangle of zero area)? They are when their projections
/// on the three coordinate planes all are.
pub(crate) fn orient2d_all_zero(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let k = |p: DVec3, i: usize, j: usize| robust::Coord { x: p[i], y: p[j] };
    [(0, 1), (1, 2), (2, 0)]
        .into_iter()
        .all(|(i, j)| robust::orient2d(k(a, i, j), k(b, i, j), k(c, i, j)) == 0.0)
}

/// How a segment meets a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Crossing {
    None,
    /// Through the interior; `from_back` when `p` is behind the triangle (the side opposite to
    /// its normal), i.e. the segment leaves the solid bounded by an outward-oriented surface.
    Proper {
        from_back: bool,
    },
    /// Through an edge or a vertex of the triangle, or an endpoint on the triangle.
    Degenerate,
    /// The segment lies in the plane of the triangle (whether or not they overlap).
    Coplanar,
}

/// Exact classification of segment `[p, q]` against triangle `t`.
pub(crate) fn segment_crossing(p: DVec3, q: DVec3, t: &[DVec3; 3]) -> Crossing {
    let [a, b, c] = *t;
    let (sp, sq) = (orient(a, b, c, p), orient(a, b, c, q));
    if sp == sq {
        return if sp == Ordering::Equal {
            Crossing::Coplanar
        } else {
            Crossing::None
        };
    }
    let e = [orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a)];
    let has_pos = e.contains(&Ordering::Greater);
    let has_neg = e.contains(&Ordering::Less);
    if has_pos && has_neg {
        return Crossing::None;
    }
    if sp == Ordering::Equal || sq == Ordering::Equal || e.contains(&Ordering::Equal) {
        return Crossing::Degenerate;
    }
    Crossing::Proper {
        from_back: sp == Ordering::Greater,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: [DVec3; 3] = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
    ];

    #[test]
    fn classifies_crossings() {
        let up = DVec3::new(0.2, 0.2, 1.0);
        let down = DVec3::new(0.2, 0.2, -1.0);
        // The normal of T is +z: going up from below leaves the solid.
        assert_eq!(
            segment_crossing(down, up, &T),
            Crossing::Proper { from_back: true }
        );
        assert_eq!(
            segment_crossing(up, down, &T),
            Crossing::Proper { from_back: false }
        );
        assert_eq!(
            segment_crossing(DVec3::new(2.0, 2.0, -1.0), DVec3::new(2.0, 2.0, 1.0), &T),
            Crossing::None
        );
        // Through an edge, and ending on the triangle.
        assert_eq!(
            segment_crossing(DVec3::new(0.5, 0.0, -1.0), DVec3::new(0.5, 0.0, 1.0), &T),
            Crossing::Degenerate
        );
        assert_eq!(
            segment_crossing(DVec3::new(0.2, 0.2, 0.0), up, &T),
            Crossing::Degenerate
        );
        assert_eq!(
            segment_crossing(DVec3::new(0.2, 0.2, 2.0), up, &T),
            Crossing::None
        );
    }
}
