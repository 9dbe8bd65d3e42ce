//! What both mesher levels share: the constrained sub-segments (with the region on each side), which
//! vertices are input vertices, and the segments each vertex lies on.

use crate::triangulation::Triangulation;
use crate::triangulation::delaunay2::predicates::dot_sign;
use crate::triangulation::delaunay2::{Delaunay2, VertexId};
use glam::DVec2;
use std::cmp::Ordering;

/// Where a triangle lies.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Label {
    /// Not decided yet (created while some sub-segment was missing from the triangulation).
    Unknown,
    /// Outside the domain: beyond the outer boundary or in a hole.
    Outside,
    /// Inside the domain, in the region with this index (see `Mesher::regions`).
    Region(u32),
}

/// A piece of an input segment, oriented like it, with the region on each side.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) struct SubSegment {
    pub a: VertexId,
    pub b: VertexId,
    pub origin: u32,
    pub left: Label,
    pub right: Label,
}

#[derive(Debug, Default)]
pub(crate) struct Constraints {
    /// Input segments, as triangulation vertices.
    pub segments: Vec<[VertexId; 2]>,
    /// Per vertex: input segments it is an endpoint of (input vertices) or the one segment it was
    /// inserted on (Steiner vertices); empty for free vertices.
    pub on_segments: Vec<Vec<u32>>,
    /// Per vertex: whether it is an input vertex.
    pub is_input: Vec<bool>,
    /// Per vertex: the other ends of the sub-segments at it.
    around: Vec<Vec<VertexId>>,
    /// Per vertex, parallel to `around`: where each of those sub-segments is in `subs`. Vertices
    /// carry few sub-segments, so scanning these short lists beats hashing the edge.
    slots: Vec<Vec<u32>>,
    subs: Vec<SubSegment>,
}

fn key(a: VertexId, b: VertexId) -> (VertexId, VertexId) {
    (a.min(b), a.max(b))
}

impl Constraints {
    pub(crate) fn new(num_vertices: usize, segments: Vec<[VertexId; 2]>) -> Self {
        let mut c = Constraints {
            is_input: vec![true; num_vertices],
            on_segments: vec![Vec::new(); num_vertices],
            around: vec![Vec::new(); num_vertices],
            slots: vec![Vec::new(); num_vertices],
            ..Default::default()
        };
        for (s, &[a, b]) in segments.iter().enumerate() {
            c.on_segments[a.0 as usize].push(s as u32);
            c.on_segments[b.0 as usize].push(s as u32);
            c.add(
                SubSegment {
                    a,
                    b,
                    origin: s as u32,
                    left: Label::Unknown,
                    right: Label::Unknown,
                },
                None,
            );
        }
        c.segments = segments;
        c
    }

    fn ensure(&mut self, v: VertexId) {
        let n = v.0 as usize + 1;
        if self.is_input.len() < n {
            self.is_input.resize(n, false);
            self.on_segments.resize(n, Vec::new());
            self.around.resize(n, Vec::new());
            self.slots.resize(n, Vec::new());
        }
    }

    /// Stores `s` in `slot` (a new one when `None`) and records it at both ends.
    fn add(&mut self, s: SubSegment, slot: Option<u32>) {
        self.ensure(s.a.max(s.b));
        let slot = slot.unwrap_or_else(|| {
            self.subs.push(s);
            (self.subs.len() - 1) as u32
        });
        self.subs[slot as usize] = s;
        for (x, y) in [(s.a, s.b), (s.b, s.a)] {
            self.around[x.0 as usize].push(y);
            self.slots[x.0 as usize].push(slot);
        }
    }

    /// Where sub-segment `(a, b)` is in `subs`, and its position in `a`'s lists.
    fn find(&self, a: VertexId, b: VertexId) -> Option<(u32, usize)> {
        let i = self.around(a).iter().position(|&y| y == b)?;
        Some((self.slots[a.0 as usize][i], i))
    }

    pub(crate) fn get(&self, a: VertexId, b: VertexId) -> Option<&SubSegment> {
        self.find(a, b).map(|(slot, _)| &self.subs[slot as usize])
    }

    pub(crate) fn get_mut(&mut self, a: VertexId, b: VertexId) -> Option<&mut SubSegment> {
        self.find(a, b)
            .map(|(slot, _)| &mut self.subs[slot as usize])
    }

    /// Other ends of the sub-segments at `v`.
    pub(crate) fn around(&self, v: VertexId) -> &[VertexId] {
        self.around.get(v.0 as usize).map_or(&[], |x| x.as_slice())
    }

    /// All sub-segments, in a deterministic order.
    pub(crate) fn sorted(&self) -> Vec<SubSegment> {
        let mut all = self.subs.clone();
        all.sort_unstable_by_key(|s| key(s.a, s.b));
        all
    }

    /// Replaces sub-segment `(a, b)` by its two halves at the new vertex `m`.
    pub(crate) fn split(&mut self, a: VertexId, b: VertexId, m: VertexId) {
        let Some((slot, _)) = self.find(a, b) else {
            return;
        };
        let s = self.subs[slot as usize];
        for (x, y) in [(s.a, s.b), (s.b, s.a)] {
            if let Some((_, i)) = self.find(x, y) {
                self.around[x.0 as usize].remove(i);
                self.slots[x.0 as usize].remove(i);
            }
        }
        self.ensure(m);
        self.is_input[m.0 as usize] = false;
        self.on_segments[m.0 as usize] = vec![s.origin];
        self.add(SubSegment { b: m, ..s }, Some(slot));
        self.add(SubSegment { a: m, ..s }, None);
    }

    /// Whether `v` is an input vertex where two input segments meet at less than `max_deg`.
    pub(crate) fn is_small_angle_apex(&self, tr: &Delaunay2, v: VertexId, max_deg: f64) -> bool {
        if !self.is_input.get(v.0 as usize).copied().unwrap_or(false) {
            return false;
        }
        let segs = &self.on_segments[v.0 as usize];
        let pv = tr.point(v);
        let dir = |s: u32| {
            let [a, b] = self.segments[s as usize];
            let w = if a == v { b } else { a };
            (tr.point(w) - pv).normalize()
        };
        let cos_max = max_deg.to_radians().cos();
        segs.iter()
            .enumerate()
            .any(|(i, &s)| segs[i + 1..].iter().any(|&t| dir(s).dot(dir(t)) > cos_max))
    }
}

/// The region in which a vertex encroaches a sub-segment: Triangle's diametral lens, the points
/// that see the sub-segment under an angle of at least 180° − 2θ for the angle bound θ. Vertices
/// between the lens and the diametral circle cannot create triangles worse than θ there, so
/// sparing those sub-segments gives fewer points (Shewchuk, "Delaunay refinement algorithms for
/// triangular mesh generation", 2002, §3.4). Without an angle bound the lens has no meaning and
/// the closed diametral disk (exact) is used.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) struct Encroachment {
    /// cos(180° − 2θ), or `None` for the diametral disk.
    lens_cos: Option<f64>,
}

impl Encroachment {
    pub(crate) fn new(min_angle_deg: f64) -> Self {
        Encroachment {
            lens_cos: (min_angle_deg > 0.0)
                .then(|| (180.0 - 2.0 * min_angle_deg).to_radians().cos()),
        }
    }

    /// Whether `p` encroaches the sub-segment `(a, b)`.
    pub(crate) fn encroaches(&self, p: DVec2, a: DVec2, b: DVec2) -> bool {
        match self.lens_cos {
            None => dot_sign(p, a, b) != Ordering::Greater,
            Some(c) => {
                let (u, v) = (a - p, b - p);
                let dot = u.dot(v);
                dot <= 0.0 && dot * dot >= c * c * u.length_squared() * v.length_squared()
            }
        }
    }
}

/// Whether sub-segment `(a, b)` must be split: it is missing from the triangulation, or (given an
/// `encroachment` rule) a vertex on a domain side encroaches it — the side rule of Triangle, which only
/// tests the apex inside the domain; a vertex outside the domain may encroach as long as the
/// sub-segment stays an edge. Testing the two apexes suffices: a vertex in the lens of a Delaunay
/// edge would lie in the circumdisk of the triangle on its side.
pub(crate) fn needs_split(
    tr: &Delaunay2,
    cons: &Constraints,
    a: VertexId,
    b: VertexId,
    encroachment: Option<&Encroachment>,
) -> bool {
    let Some(&s) = cons.get(a, b) else {
        return false;
    };
    let Some((c, i)) = tr.edge_cell(s.a, s.b) else {
        return true;
    };
    let Some(encroachment) = encroachment else {
        return false;
    };
    let (pa, pb) = (tr.point(s.a), tr.point(s.b));
    let n = tr.neighbor(c, i);
    let sides = [
        (tr.cell(c)[i], s.left),
        (tr.cell(n)[tr.mirror_index(c, i)], s.right),
    ];
    sides.iter().any(|&(w, label)| {
        label != Label::Outside
            && !tr.is_infinite_vertex(w)
            && encroachment.encroaches(tr.point(w), pa, pb)
    })
}
