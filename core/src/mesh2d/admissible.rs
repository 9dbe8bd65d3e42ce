//! Pébay's classification Θ₂ of a constraint edge `[P_i P_j]` with respect to a point set S, with
//! exact predicates and no general-position assumption. Theorem 2.1: the edge is an edge of the
//! Delaunay cover of S (in every Delaunay triangulation) iff its class is 0, 1.0 or 1.2.0.

use crate::triangulation::delaunay2::predicates::{circumcenter, dot_sign, incircle, orient2d};
use glam::DVec2;
use std::cmp::Ordering;

/// The classes of Θ₂ (Pébay 1998, §2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Theta2 {
    /// 0: the closed diametral disk holds no other point (a Gabriel edge).
    Empty,
    /// 1.0: encroaching points on one side only, and the circle through the endpoints and the
    /// worst of them (`Q*`, largest angle) has nothing else in its closed disk (or `Q*` is on the
    /// diametral circle).
    OneSideClear,
    /// 1.1: some point lies strictly inside that circle, on the other side: in no triangulation.
    OneSideBlocked,
    /// 1.2.0: other points on that circle, all on the side of `Q*`: still in every triangulation.
    CocircularOneSide,
    /// 1.2.1: points on that circle on both sides: a diagonal of a cocircular Delaunay cell.
    CocircularBothSides,
    /// 2: encroaching points on both sides (or on the edge itself).
    BothSides,
}

impl Theta2 {
    /// Theorem 2.1: strongly Delaunay-admissible classes.
    pub fn is_strongly_admissible(self) -> bool {
        matches!(
            self,
            Self::Empty | Self::OneSideClear | Self::CocircularOneSide
        )
    }

    /// The class as Pébay writes it.
    pub fn label(self) -> &'static str {
        match self {
            Self::Empty => "0",
            Self::OneSideClear => "1.0",
            Self::OneSideBlocked => "1.1",
            Self::CocircularOneSide => "1.2.0",
            Self::CocircularBothSides => "1.2.1",
            Self::BothSides => "2",
        }
    }
}

/// A closed disk through both endpoints that holds no other point while the edge is admissible:
/// while a new point stays strictly outside it, the edge stays admissible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Witness {
    /// The diametral disk of the edge.
    Diametral,
    /// The disk of the counter-clockwise triangle `(P_i or P_j, the other, Q*)`.
    Circle([DVec2; 3]),
}

/// The class of an edge and what the algorithms need besides.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Classification {
    pub class: Theta2,
    /// Points of S in the closed diametral disk other than the endpoints (`S_ij \ {P_i, P_j}`).
    pub encroaching: Vec<u32>,
    pub witness: Witness,
}

impl Witness {
    /// Whether `m` lies in the closed witness disk of edge `[a, b]`.
    pub(crate) fn holds(&self, a: DVec2, b: DVec2, m: DVec2) -> bool {
        match self {
            Self::Diametral => dot_sign(m, a, b) != Ordering::Greater,
            Self::Circle([p, q, r]) => incircle(*p, *q, *r, m) != Ordering::Less,
        }
    }

    /// A box containing the witness disk, for cheap filtering.
    pub(crate) fn bounds(&self, a: DVec2, b: DVec2) -> (DVec2, DVec2) {
        let (c, r) = match self {
            Self::Diametral => ((a + b) * 0.5, (b - a).length() * 0.5),
            Self::Circle([p, q, s]) => {
                let c = circumcenter(*p, *q, *s);
                (c, (c - *p).length())
            }
        };
        let r = r * (1.0 + 1e-9) + 1e-300 + (c.abs().max_element() * 4.0 * f64::EPSILON);
        (c - DVec2::splat(r), c + DVec2::splat(r))
    }
}

/// Θ₂ of the edge `[points[i], points[j]]` with respect to all of `points` (brute force).
pub fn classify(points: &[DVec2], i: usize, j: usize) -> Theta2 {
    classify_with(points, i as u32, j as u32, |_, _, out| {
        out.clear();
        out.extend(0..points.len() as u32);
    })
    .class
}

/// Whether the edge `[points[i], points[j]]` is an edge of every Delaunay triangulation of `points`.
pub fn is_strongly_admissible(points: &[DVec2], i: usize, j: usize) -> bool {
    classify(points, i, j).is_strongly_admissible()
}

/// Θ₂ with `candidates(lo, hi, out)` filling `out` with (at least) every point index in the box.
pub(crate) fn classify_with(
    points: &[DVec2],
    i: u32,
    j: u32,
    mut candidates: impl FnMut(DVec2, DVec2, &mut Vec<u32>),
) -> Classification {
    let (pi, pj) = (points[i as usize], points[j as usize]);
    let mut cand = Vec::new();
    let (lo, hi) = Witness::Diametral.bounds(pi, pj);
    candidates(lo, hi, &mut cand);
    let encroaching: Vec<u32> = cand
        .iter()
        .copied()
        .filter(|&k| k != i && k != j && dot_sign(points[k as usize], pi, pj) != Ordering::Greater)
        .collect();
    let done = |class, witness, encroaching| Classification {
        class,
        encroaching,
        witness,
    };
    let Some(&first) = encroaching.first() else {
        return done(Theta2::Empty, Witness::Diametral, encroaching);
    };
    let side = orient2d(pi, pj, points[first as usize]);
    if side == Ordering::Equal
        || encroaching
            .iter()
            .any(|&k| orient2d(pi, pj, points[k as usize]) != side)
    {
        return done(Theta2::BothSides, Witness::Diametral, encroaching);
    }
    // Counter-clockwise triangle on the edge with apex q.
    let tri = |q: DVec2| {
        if side == Ordering::Greater {
            [pi, pj, q]
        } else {
            [pj, pi, q]
        }
    };
    // Q*: the encroaching point seeing the edge under the largest angle, i.e. strictly inside the
    // circle through the edge and any point with a smaller angle (inscribed-angle theorem).
    let mut qstar = first;
    for &k in &encroaching[1..] {
        let [a, b, c] = tri(points[qstar as usize]);
        if incircle(a, b, c, points[k as usize]) == Ordering::Greater {
            qstar = k;
        }
    }
    let q = points[qstar as usize];
    if dot_sign(q, pi, pj) == Ordering::Equal {
        return done(Theta2::OneSideClear, Witness::Diametral, encroaching);
    }
    let t = tri(q);
    let witness = Witness::Circle(t);
    let (lo, hi) = witness.bounds(pi, pj);
    candidates(lo, hi, &mut cand);
    let mut cocircular_both_sides = false;
    let mut cocircular = false;
    for &k in &cand {
        if k == i || k == j || k == qstar {
            continue;
        }
        let p = points[k as usize];
        match incircle(t[0], t[1], t[2], p) {
            Ordering::Greater => return done(Theta2::OneSideBlocked, witness, encroaching),
            Ordering::Equal => {
                cocircular = true;
                cocircular_both_sides |= orient2d(pi, pj, p) != side;
            }
            Ordering::Less => {}
        }
    }
    let class = match (cocircular, cocircular_both_sides) {
        (false, _) => Theta2::OneSideClear,
        (true, false) => Theta2::CocircularOneSide,
        (true, true) => Theta2::CocircularBothSides,
    };
    done(class, witness, encroaching)
}
