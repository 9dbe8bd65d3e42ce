//! An AABB tree (bounding volume hierarchy) over triangles: every segment crossing, closest
//! points, and candidate pairs for self-intersection tests, in O(log n) per query.

use glam::DVec3;

#[derive(Clone, Copy, Debug)]
struct Node {
    min: DVec3,
    max: DVec3,
    /// Leaf: `first..first + count` in `order`. Inner: `count == 0`, children at `first`, `first + 1`.
    first: u32,
    count: u32,
}

/// The tree stores triangle indices; the triangles themselves stay with the caller.
#[derive(Clone, Debug)]
pub struct TriangleTree {
    nodes: Vec<Node>,
    order: Vec<u32>,
    /// Boxes are widened by this much so that floating-point slab tests never miss a triangle
    /// that the exact predicates would report.
    slack: f64,
}

const LEAF_SIZE: usize = 4;

impl TriangleTree {
    /// The tree over `triangles`; query results are indices into that slice.
    pub fn new(triangles: &[[DVec3; 3]]) -> Self {
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let centroids: Vec<DVec3> = triangles
            .iter()
            .map(|t| (t[0] + t[1] + t[2]) / 3.0)
            .collect();
        let (lo, hi) = triangles
            .iter()
            .flatten()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let extent = if triangles.is_empty() {
            0.0
        } else {
            (hi - lo)
                .max_element()
                .max(lo.abs().max(hi.abs()).max_element())
        };
        let mut tree = TriangleTree {
            nodes: Vec::with_capacity(2 * triangles.len() / LEAF_SIZE + 1),
            order: Vec::new(),
            slack: 1e-9 * extent,
        };
        tree.nodes.push(Node {
            min: DVec3::ZERO,
            max: DVec3::ZERO,
            first: 0,
            count: 0,
        });
        if !triangles.is_empty() {
            tree.build(0, &mut order, 0, triangles, &centroids);
        }
        tree.order = order;
        tree
    }

    fn build(
        &mut self,
        node: usize,
        order: &mut [u32],
        first: usize,
        triangles: &[[DVec3; 3]],
        centroids: &[DVec3],
    ) {
        let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &t in order.iter() {
            for p in triangles[t as usize] {
                min = min.min(p);
                max = max.max(p);
            }
        }
        min -= DVec3::splat(self.slack);
        max += DVec3::splat(self.slack);
        if order.len() <= LEAF_SIZE {
            self.nodes[node] = Node {
                min,
                max,
                first: first as u32,
                count: order.len() as u32,
            };
            return;
        }
        let axis = (max - min).max_position();
        let mid = order.len() / 2;
        order.select_nth_unstable_by(mid, |&a, &b| {
            centroids[a as usize][axis]
                .total_cmp(&centroids[b as usize][axis])
                .then(a.cmp(&b))
        });
        let left = self.nodes.len();
        self.nodes.push(Node {
            min,
            max,
            first: 0,
            count: 0,
        });
        self.nodes.push(Node {
            min,
            max,
            first: 0,
            count: 0,
        });
        self.nodes[node] = Node {
            min,
            max,
            first: left as u32,
            count: 0,
        };
        let (lo, hi) = order.split_at_mut(mid);
        self.build(left, lo, first, triangles, centroids);
        self.build(left + 1, hi, first + mid, triangles, centroids);
    }

    /// Calls `visit` with every triangle whose box meets the segment `[a, b]`.
    pub fn for_each_near_segment(&self, a: DVec3, b: DVec3, visit: impl FnMut(u32)) {
        let d = b - a;
        let inv = d.recip();
        self.for_each_in_boxes(|min, max| segment_meets_box(a, d, inv, min, max), visit);
    }

    /// Calls `visit` with every triangle whose box meets the box `[min, max]`.
    pub fn for_each_near_box(&self, min: DVec3, max: DVec3, visit: impl FnMut(u32)) {
        self.for_each_in_boxes(
            |lo, hi| !(lo.cmpgt(max).any() || hi.cmplt(min).any()),
            visit,
        );
    }

    /// Depth-first walk of the nodes whose box passes `meets`, visiting the triangles of the leaves.
    fn for_each_in_boxes(&self, meets: impl Fn(DVec3, DVec3) -> bool, mut visit: impl FnMut(u32)) {
        if self.order.is_empty() {
            return;
        }
        // Node ids only (no keys): a quarter of `NodeStack`'s bytes to clear per query.
        let mut stack = [0u32; STACK_DEPTH];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let node = self.nodes[stack[len] as usize];
            if !meets(node.min, node.max) {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                for &t in &self.order[first..first + node.count as usize] {
                    visit(t);
                }
            } else {
                stack[len] = node.first + 1;
                stack[len + 1] = node.first;
                len += 2;
            }
        }
    }

    /// The distance from `p` to the nearest triangle (∞ for an empty tree).
    pub fn distance(&self, p: DVec3, triangles: &[[DVec3; 3]]) -> f64 {
        if self.order.is_empty() {
            return f64::INFINITY;
        }
        let mut best = f64::INFINITY;
        let mut stack = NodeStack::default();
        while let Some((n, d2)) = stack.pop_with_key() {
            if d2 >= best {
                continue;
            }
            let node = self.nodes[n];
            if node.count > 0 {
                let first = node.first as usize;
                for &t in &self.order[first..first + node.count as usize] {
                    best = best.min(
                        p.distance_squared(closest_point_on_triangle(p, &triangles[t as usize])),
                    );
                }
            } else {
                let (l, r) = (node.first as usize, node.first as usize + 1);
                let (dl, dr) = (
                    box_distance2(p, &self.nodes[l]),
                    box_distance2(p, &self.nodes[r]),
                );
                if dl < dr {
                    stack.push(r, dr);
                    stack.push(l, dl);
                } else {
                    stack.push(l, dl);
                    stack.push(r, dr);
                }
            }
        }
        best.sqrt()
    }
}

const STACK_DEPTH: usize = 66;

/// The traversal stack: a median-split tree over at most 2^32 triangles is less than 64 levels
/// deep, and a depth-first traversal holds at most one pending sibling per level.
struct NodeStack {
    items: [(u32, f64); STACK_DEPTH],
    len: usize,
}

impl Default for NodeStack {
    fn default() -> Self {
        NodeStack {
            items: [(0, 0.0); STACK_DEPTH],
            len: 1,
        }
    }
}

impl NodeStack {
    fn push(&mut self, node: usize, key: f64) {
        self.items[self.len] = (node as u32, key);
        self.len += 1;
    }
    fn pop_with_key(&mut self) -> Option<(usize, f64)> {
        self.len = self.len.checked_sub(1)?;
        let (n, k) = self.items[self.len];
        Some((n as usize, k))
    }
}

fn box_distance2(p: DVec3, n: &Node) -> f64 {
    let q = p.clamp(n.min, n.max);
    p.distance_squared(q)
}

/// Slab test of the segment `a + t d`, t ∈ [0, 1], against a box.
fn segment_meets_box(a: DVec3, d: DVec3, inv: DVec3, min: DVec3, max: DVec3) -> bool {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..3 {
        if d[k] == 0.0 {
            if a[k] < min[k] || a[k] > max[k] {
                return false;
            }
            continue;
        }
        let (mut u, mut v) = ((min[k] - a[k]) * inv[k], (max[k] - a[k]) * inv[k]);
        if u > v {
            std::mem::swap(&mut u, &mut v);
        }
        // Plain comparisons rather than `f64::max`: no NaN bookkeeping in the hottest loop of
        // the mesher, and a NaN bound (0 × ∞) leaves the interval unshrunk, erring on "meets".
        if u > t0 {
            t0 = u;
        }
        if v < t1 {
            t1 = v;
        }
        if t0 > t1 {
            return false;
        }
    }
    true
}

/// The point of triangle `t` closest to `p` (Ericson, Real-Time Collision Detection, 5.1.5).
pub fn closest_point_on_triangle(p: DVec3, t: &[DVec3; 3]) -> DVec3 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom == 0.0 {
        // A degenerate (flat) triangle: the nearest of its vertices is close enough.
        return [a, b, c]
            .into_iter()
            .min_by(|x, y| p.distance_squared(*x).total_cmp(&p.distance_squared(*y)))
            .unwrap_or(a);
    }
    a + ab * (vb / denom) + ac * (vc / denom)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize) -> Vec<[DVec3; 3]> {
        let mut tris = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let p = |x: usize, y: usize| DVec3::new(x as f64, y as f64, 0.0);
                tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
        tris
    }

    #[test]
    fn segment_query_finds_what_brute_force_finds() {
        let tris = grid(8);
        let tree = TriangleTree::new(&tris);
        let (a, b) = (DVec3::new(2.3, 5.7, -1.0), DVec3::new(2.3, 5.7, 1.0));
        let mut found = Vec::new();
        tree.for_each_near_segment(a, b, |t| found.push(t));
        // The triangle containing (2.3, 5.7) must be among the candidates.
        let inside = |t: &[DVec3; 3]| {
            closest_point_on_triangle(DVec3::new(2.3, 5.7, 0.0), t)
                .distance(DVec3::new(2.3, 5.7, 0.0))
                < 1e-12
        };
        let truth: Vec<u32> = (0..tris.len() as u32)
            .filter(|&t| inside(&tris[t as usize]))
            .collect();
        assert!(!truth.is_empty());
        assert!(truth.iter().all(|t| found.contains(t)));
        assert!(found.len() < tris.len() / 4);
    }

    #[test]
    fn distance_matches_brute_force() {
        let tris = grid(6);
        let tree = TriangleTree::new(&tris);
        for p in [
            DVec3::new(3.2, 1.1, 2.0),
            DVec3::new(-1.0, -1.0, 0.5),
            DVec3::new(7.0, 2.0, -3.0),
        ] {
            let brute = tris
                .iter()
                .map(|t| closest_point_on_triangle(p, t).distance(p))
                .fold(f64::INFINITY, f64::min);
            assert!((tree.distance(p, &tris) - brute).abs() < 1e-12);
        }
    }
}
