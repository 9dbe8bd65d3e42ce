//! Chaining of feature edges into curves that run between corners.

use crate::edges::adjacency;
use glam::DVec3;

/// A curve as a chain of vertices; a closed curve does not repeat its first vertex.
pub struct Chain {
    /// The vertices in order along the curve.
    pub vertices: Vec<u32>,
    /// The last vertex joins the first.
    pub closed: bool,
}

/// Corners (sorted) and the curves between them.
pub struct Chains {
    /// Vertices where curves end.
    pub corners: Vec<u32>,
    /// The curves.
    pub curves: Vec<Chain>,
}

/// Splits the graph of feature `edges` (sorted `[a, b]` with `a < b`, no duplicates) into curves.
///
/// Corners are the vertices where other than two feature edges meet, the `forced` ones, and the
/// vertices where a curve turns by more than `angle_deg`. Curves leave the corners in increasing
/// vertex order, each corner's edges in increasing neighbour order; the loops left over (without
/// corner) start at their smallest vertex towards its smaller neighbour. A curve that comes back to
/// its corner is closed and starts there.
pub fn chain(positions: &[DVec3], edges: &[[u32; 2]], forced: &[u32], angle_deg: f64) -> Chains {
    let n = positions.len();
    let (offsets, adj) = adjacency(n, edges);
    let around = |v: u32| &adj[offsets[v as usize]..offsets[v as usize + 1]];
    let turns_sharply = |v: u32| {
        let [p, q] = [around(v)[0], around(v)[1]].map(|w| positions[w as usize]);
        let x = positions[v as usize];
        let (d1, d2) = (x - p, q - x);
        d1.cross(d2).length().atan2(d1.dot(d2)).to_degrees() > angle_deg
    };
    let mut is_corner = vec![false; n];
    for v in 0..n as u32 {
        let degree = around(v).len();
        is_corner[v as usize] = degree > 0 && (degree != 2 || turns_sharply(v));
    }
    for &v in forced {
        if let Some(c) = is_corner.get_mut(v as usize) {
            *c = true;
        }
    }
    let edge_index = |a: u32, b: u32| edges.binary_search(&[a.min(b), a.max(b)]).ok();
    let mut used = vec![false; edges.len()];
    let walk = |start: u32, first: u32, used: &mut Vec<bool>| {
        let mut vertices = vec![start];
        let (mut prev, mut cur) = (start, first);
        if let Some(e) = edge_index(start, first) {
            used[e] = true;
        }
        loop {
            if cur == start {
                return Chain {
                    vertices,
                    closed: true,
                };
            }
            vertices.push(cur);
            if is_corner[cur as usize] {
                return Chain {
                    vertices,
                    closed: false,
                };
            }
            // Not a corner: exactly two feature edges meet at `cur`.
            let next = match around(cur) {
                &[a, b] => {
                    if a == prev {
                        b
                    } else {
                        a
                    }
                }
                _ => {
                    return Chain {
                        vertices,
                        closed: false,
                    };
                }
            };
            if let Some(e) = edge_index(cur, next) {
                used[e] = true;
            }
            (prev, cur) = (cur, next);
        }
    };
    let corners: Vec<u32> = (0..n as u32).filter(|&v| is_corner[v as usize]).collect();
    let mut curves = Vec::new();
    for &c in &corners {
        for &w in around(c) {
            if edge_index(c, w).is_some_and(|e| !used[e]) {
                curves.push(walk(c, w, &mut used));
            }
        }
    }
    for (e, &[a, b]) in edges.iter().enumerate() {
        if !used[e] {
            curves.push(walk(a, b, &mut used));
        }
    }
    Chains { corners, curves }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_loop() -> (Vec<DVec3>, Vec<[u32; 2]>) {
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        (p, vec![[0, 1], [0, 3], [1, 2], [2, 3]])
    }

    #[test]
    fn a_square_has_four_corners_at_its_right_angles_unless_the_threshold_is_higher() {
        let (p, e) = square_loop();
        let c = chain(&p, &e, &[], 60.0);
        assert_eq!(c.corners, vec![0, 1, 2, 3]);
        assert_eq!(c.curves.len(), 4);
        assert!(c.curves.iter().all(|k| !k.closed && k.vertices.len() == 2));
        let c = chain(&p, &e, &[], 95.0);
        assert!(c.corners.is_empty());
        assert_eq!(c.curves.len(), 1);
        assert!(c.curves[0].closed);
        assert_eq!(c.curves[0].vertices, vec![0, 1, 2, 3]);
    }

    #[test]
    fn a_forced_corner_closes_a_loop_on_itself() {
        let (p, e) = square_loop();
        let c = chain(&p, &e, &[2], 95.0);
        assert_eq!(c.corners, vec![2]);
        assert_eq!(c.curves.len(), 1);
        assert!(c.curves[0].closed);
        assert_eq!(c.curves[0].vertices, vec![2, 1, 0, 3]);
    }

    #[test]
    fn every_edge_is_on_exactly_one_curve() {
        // A "T": three straight branches meeting at vertex 1.
        let p = vec![
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let e = vec![[0, 1], [1, 2], [1, 4], [2, 3]];
        let c = chain(&p, &e, &[], 60.0);
        assert_eq!(c.corners, vec![0, 1, 3, 4]);
        let mut seen: Vec<[u32; 2]> = c
            .curves
            .iter()
            .flat_map(|k| {
                k.vertices
                    .windows(2)
                    .map(|w| [w[0].min(w[1]), w[0].max(w[1])])
            })
            .collect();
        seen.sort_unstable();
        assert_eq!(seen, e);
        assert_eq!(c.curves.len(), 3);
    }
}
