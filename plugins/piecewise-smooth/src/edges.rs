//! Edge–triangle incidences of a welded triangle surface, grouped by undirected edge.

use std::ops::Range;

/// One use of an edge by a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) struct EdgeUse {
    pub triangle: u32,
    /// The triangle runs through the edge from its lower to its higher vertex index.
    pub forward: bool,
}

/// Every undirected edge `[a, b]` (`a < b`, sorted) with the triangles using it.
pub(crate) struct EdgeIncidence {
    pub edges: Vec<[u32; 2]>,
    ranges: Vec<Range<usize>>,
    uses: Vec<EdgeUse>,
}

impl EdgeIncidence {
    /// Incidences of the triangles `t` for which `keep(t)` holds; triangles with a repeated vertex
    /// have no edges.
    pub fn new(triangles: &[[u32; 3]], keep: impl Fn(usize) -> bool) -> EdgeIncidence {
        let mut all: Vec<([u32; 2], EdgeUse)> = Vec::with_capacity(3 * triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            if !keep(t) || tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let use_ = EdgeUse {
                    triangle: t as u32,
                    forward: a < b,
                };
                all.push(([a.min(b), a.max(b)], use_));
            }
        }
        all.sort_unstable();
        let mut edges = Vec::new();
        let mut ranges = Vec::new();
        let mut start = 0;
        for i in 1..=all.len() {
            if i == all.len() || all[i].0 != all[start].0 {
                edges.push(all[start].0);
                ranges.push(start..i);
                start = i;
            }
        }
        let uses = all.into_iter().map(|(_, u)| u).collect();
        EdgeIncidence {
            edges,
            ranges,
            uses,
        }
    }

    /// The triangles using edge number `e`, in increasing triangle order.
    pub fn uses(&self, e: usize) -> &[EdgeUse] {
        &self.uses[self.ranges[e].clone()]
    }

    /// The number of the edge joining `a` and `b`, if the surface has it.
    pub fn find(&self, a: u32, b: u32) -> Option<usize> {
        self.edges.binary_search(&[a.min(b), a.max(b)]).ok()
    }

    /// For each vertex below `num_vertices`, its neighbours along edges, in increasing order
    /// (compressed rows: neighbours of `v` are `adjacency[offsets[v]..offsets[v + 1]]`).
    pub fn neighbours(&self, num_vertices: usize) -> (Vec<usize>, Vec<u32>) {
        adjacency(num_vertices, &self.edges)
    }
}

/// Compressed adjacency of an undirected edge list: `(offsets, neighbours)`, rows sorted.
pub(crate) fn adjacency(num_vertices: usize, edges: &[[u32; 2]]) -> (Vec<usize>, Vec<u32>) {
    let mut offsets = vec![0usize; num_vertices + 1];
    for &[a, b] in edges {
        offsets[a as usize + 1] += 1;
        offsets[b as usize + 1] += 1;
    }
    for v in 0..num_vertices {
        offsets[v + 1] += offsets[v];
    }
    let mut fill = offsets.clone();
    let mut adj = vec![0u32; offsets[num_vertices]];
    for &[a, b] in edges {
        adj[fill[a as usize]] = b;
        fill[a as usize] += 1;
        adj[fill[b as usize]] = a;
        fill[b as usize] += 1;
    }
    for v in 0..num_vertices {
        adj[offsets[v]..offsets[v + 1]].sort_unstable();
    }
    (offsets, adj)
}
