//! Topological checks of a triangle surface: what `delamesh info` reports and what the mesher demands
//! of its input (closed, manifold, consistently oriented).

use crate::union_find::UnionFind;
use glam::DVec3;

/// Everything `surface_topology` finds out about a triangle surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Topology {
    /// Vertices used by at least one non-degenerate triangle.
    pub used_vertices: usize,
    /// Vertices used by no triangle (they do not count in the Euler characteristic).
    pub unused_vertices: usize,
    /// Distinct edges of the non-degenerate triangles.
    pub edges: usize,
    /// Edges with exactly one incident triangle.
    pub boundary_edges: usize,
    /// Edges with three or more incident triangles.
    pub non_manifold_edges: usize,
    /// Vertices whose incident triangles do not form a single fan (e.g. two cones touching at a tip).
    pub non_manifold_vertices: usize,
    /// Connected components (triangles sharing a vertex are connected).
    pub components: usize,
    /// V − E + F over the non-degenerate triangles and the vertices they use.
    pub euler_characteristic: i64,
    /// Sum of the components' genera; only defined for a closed, manifold, oriented surface.
    pub genus: Option<i64>,
    /// Edges shared by two triangles that run through them in the same direction.
    pub misoriented_edges: usize,
    /// Triangles with a repeated vertex or with three exactly collinear corners.
    pub degenerate_triangles: usize,
    /// Sum of the signed volumes of the tetrahedra (origin, triangle); the enclosed volume when closed
    /// and oriented outward, negative when oriented inward.
    pub signed_volume: f64,
    /// No boundary edge.
    pub closed: bool,
    /// No non-manifold edge and no non-manifold vertex.
    pub manifold: bool,
    /// No misoriented edge.
    pub orientation_consistent: bool,
}

impl Topology {
    /// Closed, manifold and consistently oriented: what a volume mesher needs to tell inside from
    /// outside.
    pub fn is_watertight(&self) -> bool {
        self.closed && self.manifold && self.orientation_consistent
    }

    /// Human-readable list of what keeps the surface from being watertight (empty when it is).
    pub fn defects(&self) -> Vec<String> {
        count_phrases([
            (self.boundary_edges, "boundary edges (holes)"),
            (
                self.non_manifold_edges,
                "edges shared by more than two triangles",
            ),
            (self.non_manifold_vertices, "non-manifold vertices"),
            (
                self.misoriented_edges,
                "edges where neighbouring triangles disagree on orientation",
            ),
        ])
    }
}

/// `"{n} {what}"` for each count that is not zero: how reports list defects or repairs, leaving
/// out the kinds that did not occur.
pub fn count_phrases<'a>(counts: impl IntoIterator<Item = (usize, &'a str)>) -> Vec<String> {
    counts
        .into_iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, what)| format!("{n} {what}"))
        .collect()
}

/// Exact test: three points are collinear iff all three coordinate-plane projections are.
fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let orient = |i: usize, j: usize| {
        let p = |v: DVec3| robust::Coord { x: v[i], y: v[j] };
        robust::orient2d(p(a), p(b), p(c))
    };
    orient(0, 1) == 0.0 && orient(1, 2) == 0.0 && orient(2, 0) == 0.0
}

/// Analyses a triangle surface; indices must be in range (see `SurfaceMesh::validate`).
pub fn surface_topology(positions: &[DVec3], triangles: &[[u32; 3]]) -> Topology {
    let mut degenerate_triangles = 0;
    let mut signed_volume = 0.0;
    let mut faces = Vec::with_capacity(triangles.len());
    for &t in triangles {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        signed_volume += a.dot(b.cross(c)) / 6.0;
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] || collinear(a, b, c) {
            degenerate_triangles += 1;
        } else {
            faces.push(t);
        }
    }
    // Faces with a repeated index are left out of the topology; collinear ones still connect edges.
    faces.retain(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0]);

    // Edges: (low, high, runs low→high) per face side, sorted so equal edges are adjacent.
    let mut sides: Vec<(u32, u32, bool)> = Vec::with_capacity(faces.len() * 3);
    for t in &faces {
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            sides.push((u.min(v), u.max(v), u < v));
        }
    }
    sides.sort_unstable();
    let (mut edges, mut boundary_edges, mut non_manifold_edges, mut misoriented_edges) =
        (0, 0, 0, 0);
    for group in sides.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        edges += 1;
        match group.len() {
            1 => boundary_edges += 1,
            2 if group[0].2 == group[1].2 => misoriented_edges += 1,
            2 => {}
            _ => non_manifold_edges += 1,
        }
    }

    // Vertex fans: around v, the opposite sides of its triangles must form one connected link.
    let fans = link_pieces(&faces);
    let used_vertices = fans.len();
    let non_manifold_vertices = fans.iter().filter(|&&(_, pieces)| pieces > 1).count();

    let mut uf = UnionFind::new(positions.len());
    for &[a, b, c] in &faces {
        uf.union(a, b);
        uf.union(b, c);
    }
    let mut roots: Vec<u32> = faces.iter().map(|t| uf.find(t[0])).collect();
    roots.sort_unstable();
    roots.dedup();
    let components = roots.len();

    let euler_characteristic = used_vertices as i64 - edges as i64 + faces.len() as i64;
    let closed = boundary_edges == 0;
    let manifold = non_manifold_edges == 0 && non_manifold_vertices == 0;
    let orientation_consistent = misoriented_edges == 0;
    let genus = (closed && manifold && orientation_consistent)
        .then(|| (2 * components as i64 - euler_characteristic) / 2);
    Topology {
        used_vertices,
        unused_vertices: positions.len() - used_vertices,
        edges,
        boundary_edges,
        non_manifold_edges,
        non_manifold_vertices,
        components,
        euler_characteristic,
        genus,
        misoriented_edges,
        degenerate_triangles,
        signed_volume,
        closed,
        manifold,
        orientation_consistent,
    }
}

/// Where a triangle surface fails to be a 2-manifold: the edges with three or more incident
/// triangles, and the vertices whose incident triangles form more than one fan. Triangles with a
/// repeated index are ignored. Both lists are sorted.
pub fn non_manifold_elements(triangles: &[[u32; 3]]) -> (Vec<[u32; 2]>, Vec<u32>) {
    let faces: Vec<[u32; 3]> = triangles
        .iter()
        .copied()
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        .collect();
    let mut sides: Vec<[u32; 2]> = faces
        .iter()
        .flat_map(|t| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
        .collect();
    sides.sort_unstable();
    let edges = sides
        .chunk_by(|x, y| x == y)
        .filter(|g| g.len() > 2)
        .map(|g| g[0])
        .collect();
    let vertices = link_pieces(&faces)
        .into_iter()
        .filter(|&(_, pieces)| pieces > 1)
        .map(|(v, _)| v)
        .collect();
    (edges, vertices)
}

/// Each used vertex with the number of connected pieces of its link (the opposite sides of its
/// triangles), in vertex order: a vertex is manifold when its triangles form one fan, one piece.
fn link_pieces(faces: &[[u32; 3]]) -> Vec<(u32, usize)> {
    let mut corners: Vec<(u32, u32, u32)> = Vec::with_capacity(faces.len() * 3);
    for &[a, b, c] in faces {
        corners.extend([(a, b, c), (b, c, a), (c, a, b)]);
    }
    corners.sort_unstable();
    let mut link: Vec<u32> = Vec::new();
    corners
        .chunk_by(|x, y| x.0 == y.0)
        .map(|fan| {
            link.clear();
            link.extend(fan.iter().flat_map(|&(_, u, w)| [u, w]));
            link.sort_unstable();
            link.dedup();
            let mut uf = UnionFind::new(link.len());
            let local = |x: u32| link.binary_search(&x).map_or(0, |i| i as u32);
            for &(_, u, w) in fan {
                uf.union(local(u), local(w));
            }
            let pieces = (0..link.len() as u32).filter(|&i| uf.find(i) == i).count();
            (fan[0].0, pieces)
        })
        .collect()
}

/// The connected components of a triangle surface (triangles sharing a vertex are connected) and
/// the Euler characteristic V − E + F of each: `(component of each triangle, characteristic of
/// each component)`, components numbered in the order of their first triangle. Triangles with a
/// repeated index count in their component's faces only.
pub fn component_euler_characteristics(triangles: &[[u32; 3]]) -> (Vec<u32>, Vec<i64>) {
    let n = triangles
        .iter()
        .flatten()
        .max()
        .map_or(0, |&m| m as usize + 1);
    let mut uf = UnionFind::new(n);
    for &[a, b, c] in triangles {
        uf.union(a, b);
        uf.union(b, c);
    }
    let mut number = vec![u32::MAX; n];
    let mut euler: Vec<i64> = Vec::new();
    let component: Vec<u32> = triangles
        .iter()
        .map(|t| {
            let root = uf.find(t[0]) as usize;
            if number[root] == u32::MAX {
                number[root] = euler.len() as u32;
                euler.push(0);
            }
            number[root]
        })
        .collect();
    let mut vertices: Vec<u32> = triangles.iter().flatten().copied().collect();
    vertices.sort_unstable();
    vertices.dedup();
    let mut edges: Vec<[u32; 2]> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
        .filter(|e| e[0] != e[1])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let mut of = |v: u32| number[uf.find(v) as usize] as usize;
    for v in vertices {
        euler[of(v)] += 1;
    }
    for e in edges {
        euler[of(e[0])] -= 1;
    }
    for &k in &component {
        euler[k as usize] += 1;
    }
    (component, euler)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Outward-oriented unit cube, 12 triangles.
    fn cube() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let m = crate::mesh::SurfaceMesh::cuboid(DVec3::ZERO, DVec3::ONE);
        (m.positions, m.triangles)
    }

    /// A torus made of an n×m grid of quads: genus 1.
    fn torus(n: u32, m: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (u, v) = (
                    i as f64 / n as f64 * std::f64::consts::TAU,
                    j as f64 / m as f64 * std::f64::consts::TAU,
                );
                let r = 2.0 + v.cos();
                p.push(DVec3::new(r * u.cos(), r * u.sin(), v.sin()));
            }
        }
        let id = |i: u32, j: u32| (i % n) * m + (j % m);
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..m {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (p, t)
    }

    #[test]
    fn cube_is_a_closed_oriented_sphere_of_volume_one() {
        let (p, t) = cube();
        let topo = surface_topology(&p, &t);
        assert!(topo.is_watertight() && topo.defects().is_empty());
        assert_eq!(topo.euler_characteristic, 2);
        assert_eq!(topo.genus, Some(0));
        assert_eq!(topo.components, 1);
        assert!((topo.signed_volume - 1.0).abs() < 1e-12);
    }

    #[test]
    fn torus_has_genus_one() {
        let (p, t) = torus(8, 6);
        let topo = surface_topology(&p, &t);
        assert!(topo.closed && topo.manifold);
        assert_eq!(topo.euler_characteristic, 0);
        assert_eq!(topo.genus, Some(1));
    }

    #[test]
    fn defects_are_counted() {
        let (p, mut t) = cube();
        // Open: drop a triangle → three boundary edges, no genus.
        t.pop();
        let topo = surface_topology(&p, &t);
        assert!(!topo.closed);
        assert_eq!(topo.boundary_edges, 3);
        assert_eq!(topo.genus, None);
        assert_eq!(topo.defects(), vec!["3 boundary edges (holes)".to_string()]);
        // Flip one triangle → its three edges are misoriented.
        let (p, mut t) = cube();
        t[0].swap(1, 2);
        let topo = surface_topology(&p, &t);
        assert_eq!(topo.misoriented_edges, 3);
        assert!(!topo.orientation_consistent);
        // Inward orientation gives a negative volume.
        let (p, mut t) = cube();
        t.iter_mut().for_each(|f| f.swap(1, 2));
        assert!((surface_topology(&p, &t).signed_volume + 1.0).abs() < 1e-12);
    }

    #[test]
    fn two_cubes_touching_at_a_corner_make_a_non_manifold_vertex() {
        let (mut p, mut t) = cube();
        let (q, s) = cube();
        let base = p.len() as u32;
        // Second cube shifted by (1,1,1): its corner 0 lands on the first cube's corner 7.
        p.extend(q.iter().map(|&v| v + DVec3::ONE));
        t.extend(
            s.iter()
                .map(|f| f.map(|v| if v == 0 { 7 } else { v + base })),
        );
        let topo = surface_topology(&p, &t);
        assert_eq!(topo.non_manifold_vertices, 1);
        assert_eq!(topo.non_manifold_edges, 0);
        assert!(!topo.manifold);
        assert_eq!(topo.unused_vertices, 1);
    }

    #[test]
    fn degenerate_triangles_are_found_exactly() {
        // Nearly collinear but not exactly: the z of the last corner is one ulp above 3.
        let p = vec![
            DVec3::ZERO,
            DVec3::ONE,
            DVec3::new(3.0, 3.0, f64::from_bits(3f64.to_bits() + 1)),
            DVec3::X,
        ];
        let topo = surface_topology(&p, &[[0, 1, 2], [0, 0, 3], [0, 1, 3]]);
        assert_eq!(topo.degenerate_triangles, 1);
        let q = vec![
            DVec3::ZERO,
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(2.0, 4.0, 6.0),
        ];
        assert_eq!(surface_topology(&q, &[[0, 1, 2]]).degenerate_triangles, 1);
    }

    #[test]
    fn non_manifold_elements_are_located() {
        let (_, cube) = cube();
        assert_eq!(non_manifold_elements(&cube), (vec![], vec![]));
        // Two cubes sharing the corner 7 of the first: one non-manifold vertex, no edge.
        let shifted: Vec<[u32; 3]> = cube
            .iter()
            .map(|t| t.map(|v| if v == 0 { 7 } else { v + 8 }))
            .collect();
        let both: Vec<[u32; 3]> = cube.iter().chain(&shifted).copied().collect();
        assert_eq!(non_manifold_elements(&both), (vec![], vec![7]));
        // A third triangle on an edge of a tetrahedron.
        let mut fin = vec![[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0], [0, 1, 4]];
        let (edges, _) = non_manifold_elements(&fin);
        assert_eq!(edges, vec![[0, 1]]);
        fin.pop();
        assert_eq!(non_manifold_elements(&fin), (vec![], vec![]));
    }

    #[test]
    fn euler_characteristic_of_each_component() {
        let (_, cube) = cube();
        let (_, torus) = torus(6, 5);
        let far: Vec<[u32; 3]> = torus.iter().map(|t| t.map(|v| v + 100)).collect();
        let both: Vec<[u32; 3]> = cube.iter().chain(&far).copied().collect();
        let (component, euler) = component_euler_characteristics(&both);
        assert_eq!(euler, vec![2, 0]);
        assert!(component[..cube.len()].iter().all(|&k| k == 0));
        assert!(component[cube.len()..].iter().all(|&k| k == 1));
        assert_eq!(component_euler_characteristics(&[]), (vec![], vec![]));
    }
}
