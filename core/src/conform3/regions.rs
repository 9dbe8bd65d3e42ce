//! From a conforming triangulation to the mesh: cells joined across every face that is not a
//! piece of an input triangle form the regions; the one holding the infinite cells is outside,
//! each other takes the subdomain the oracle gives its largest cell's centroid.

use super::constraints::Constraints;
use crate::complex::{MeshComplex, VertexDimension, facets_to_smaller};
use crate::kernel::{Sign, orient3d};
use crate::oracle::{OUTSIDE, Oracle, PatchId, SubdomainId};
use crate::refine::{cell_vertices, facet_vertices, is_flat};
use crate::triangulation::{CellId, Delaunay3, Triangulation, VertexId};
use crate::union_find::UnionFind;
use rustc_hash::FxHashMap as HashMap;

pub(super) fn key(mut f: [VertexId; 3]) -> [VertexId; 3] {
    f.sort_unstable();
    f
}

/// The pieces of the input triangles, for face lookups: each piece (its vertices sorted) with the
/// index of its triangle, and which vertices lie on a piece, so that the many faces with a
/// vertex inside the volume are answered without hashing.
pub(super) struct Pieces {
    facet_of: HashMap<[VertexId; 3], usize>,
    on_piece: Vec<bool>,
}

impl Pieces {
    /// The pieces `faces` lists for each input triangle.
    pub(super) fn new(faces: &[Vec<[VertexId; 3]>]) -> Self {
        let mut pieces = Pieces {
            facet_of: HashMap::default(),
            on_piece: Vec::new(),
        };
        for (f, list) in faces.iter().enumerate() {
            for &face in list {
                pieces.insert(face, f);
            }
        }
        pieces
    }

    fn insert(&mut self, face: [VertexId; 3], f: usize) {
        for v in face {
            let i = v.0 as usize;
            if self.on_piece.len() <= i {
                self.on_piece.resize(i + 1, false);
            }
            self.on_piece[i] = true;
        }
        self.facet_of.insert(key(face), f);
    }

    /// The input triangle of which `face` (its vertices in any order) is a piece.
    pub(super) fn triangle_of(&self, face: [VertexId; 3]) -> Option<usize> {
        let on = |v: VertexId| self.on_piece.get(v.0 as usize).copied().unwrap_or(false);
        if !face.into_iter().all(on) {
            return None;
        }
        self.facet_of.get(&key(face)).copied()
    }
}

/// The subdomain of every cell (indexed by cell id): cells joined across faces that are not
/// pieces form a region; the region of the infinite cells is outside, each other takes the
/// subdomain the oracle gives its largest cell's centroid.
pub(super) fn cell_subdomains(
    dt: &Delaunay3,
    pieces: &Pieces,
    oracle: &dyn Oracle,
) -> Vec<SubdomainId> {
    let cells: Vec<CellId> = dt.cells().collect();
    let mut subdomain = Vec::new();
    // With every cell to label, no region meets another cell.
    label_cells(dt, pieces, oracle, &cells, &mut subdomain);
    subdomain
}

/// Gives each of `cells` (live, in increasing order) its subdomain in `subdomain` (indexed by
/// cell id; the other cells keep theirs): `cells` joined across faces that are not pieces form
/// regions; one that meets another cell across such a face takes that cell's subdomain (the
/// pieces separate subdomains, so an untouched cell's region still is its subdomain), one holding
/// an infinite cell is outside, each other takes the subdomain the oracle gives its largest
/// cell's centroid. Relabelling only the cells insertions created since the labels were right
/// spares the cell level a pass over the whole mesh per round (a region keeps the subdomain it
/// was given even when its largest cell is gone: only pockets of flat cells, for whose centroids
/// the oracle's answer means little, could be given another). False, with `subdomain`
/// unchanged, when a region meets cells of two subdomains: the new cells joined two regions
/// (a pocket of flat cells between pieces, to which the oracle gave the outside, opened into
/// the domain), whose cells all need labelling again.
pub(super) fn label_cells(
    dt: &Delaunay3,
    pieces: &Pieces,
    oracle: &dyn Oracle,
    cells: &[CellId],
    subdomain: &mut Vec<SubdomainId>,
) -> bool {
    subdomain.resize(dt.cell_capacity(), OUTSIDE);
    let mut position = vec![u32::MAX; dt.cell_capacity()];
    for (k, c) in cells.iter().enumerate() {
        position[c.0 as usize] = k as u32;
    }
    let mut regions = UnionFind::new(cells.len());
    // The subdomain a region meets across a face that is not a piece, by the region's first cell.
    let mut met: Vec<(u32, SubdomainId)> = Vec::new();
    for (k, &c) in cells.iter().enumerate() {
        let cell = cell_vertices(dt, c);
        for i in 0..4 {
            let n = dt.neighbor(c, i);
            let m = position[n.0 as usize];
            if m != u32::MAX && m < k as u32 {
                continue;
            }
            if pieces.triangle_of(facet_vertices(&cell, i)).is_some() {
                continue;
            }
            if m == u32::MAX {
                met.push((k as u32, subdomain[n.0 as usize]));
            } else {
                regions.union(k as u32, m);
            }
        }
    }
    let mut label: HashMap<u32, SubdomainId> = HashMap::default();
    for &(k, s) in &met {
        if *label.entry(regions.find(k)).or_insert(s) != s {
            return false;
        }
    }
    for (k, &c) in cells.iter().enumerate() {
        if dt.is_infinite_cell(c) {
            label.insert(regions.find(k as u32), OUTSIDE);
        }
    }
    // Per region left, its largest cell.
    let mut largest: HashMap<u32, (f64, CellId)> = HashMap::default();
    for (k, &c) in cells.iter().enumerate() {
        let root = regions.find(k as u32);
        if label.contains_key(&root) {
            continue;
        }
        let p = cell_vertices(dt, c).map(|v| dt.point(v));
        let volume = (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]).abs();
        let entry = largest.entry(root).or_insert((volume, c));
        if volume > entry.0 {
            *entry = (volume, c);
        }
    }
    for (root, (_, c)) in largest {
        let p = cell_vertices(dt, c).map(|v| dt.point(v));
        let centroid = (p[0] + p[1] + p[2] + p[3]) * 0.25;
        label.insert(root, oracle.subdomain(centroid));
    }
    for (k, &c) in cells.iter().enumerate() {
        subdomain[c.0 as usize] = label
            .get(&regions.find(k as u32))
            .copied()
            .unwrap_or(OUTSIDE);
    }
    true
}

/// The interior cells of the recovered surface with their subdomains, and the faces between
/// subdomains with the patch of the input triangle they lie in. `inside` lists (in increasing
/// order) the vertices placed inside the volume; every other vertex lies on the surface.
pub(super) fn complex(
    dt: &Delaunay3,
    faces: &[Vec<[VertexId; 3]>],
    constraints: &Constraints,
    oracle: &dyn Oracle,
    inside: &[VertexId],
) -> MeshComplex {
    let mut pieces = Pieces::new(faces);
    let mut subdomain = cell_subdomains(dt, &pieces, oracle);
    move_flat_cells_across(dt, &mut subdomain, &mut pieces);
    let patch_of: HashMap<[VertexId; 3], PatchId> = pieces
        .facet_of
        .into_iter()
        .map(|(face, f)| (face, constraints.facets[f].patch))
        .collect();
    collect(dt, &subdomain, &patch_of, inside)
}

/// Steiner points on an input triangle lie on it only up to rounding, so four of them (or with
/// the triangle's vertices) can make a flat Delaunay cell lying in the triangle's plane. When
/// such a cell of the domain borders the outside across exactly two faces, both pieces of one
/// input triangle, those two and its other two cover the same piece of that triangle: the cell
/// can move outside, its other two faces becoming the triangle's pieces. These are the two
/// faces (indices in the cell). (Between two subdomains either side would keep the cell; across
/// pieces of two triangles, its other faces would cross their common edge: it stays, and the
/// cell level refines it.)
pub(super) fn faces_to_move_across(
    dt: &Delaunay3,
    c: CellId,
    subdomain: &[SubdomainId],
    pieces: &Pieces,
) -> Option<[usize; 2]> {
    let own = subdomain[c.0 as usize];
    let across: Vec<(usize, SubdomainId)> = (0..4)
        .map(|i| (i, subdomain[dt.neighbor(c, i).0 as usize]))
        .filter(|&(_, s)| s != own)
        .collect();
    let [(i, other), (j, second)] = across[..] else {
        return None;
    };
    if own == OUTSIDE || other != OUTSIDE || second != OUTSIDE {
        return None;
    }
    let cell = cell_vertices(dt, c);
    let f = pieces.triangle_of(facet_vertices(&cell, i))?;
    (pieces.triangle_of(facet_vertices(&cell, j)) == Some(f)).then_some([i, j])
}

/// Moves outside the flat cells [`faces_to_move_across`] finds, giving their other two faces
/// the input triangle. Stacked flat cells follow one another; each moves once.
fn move_flat_cells_across(dt: &Delaunay3, subdomain: &mut [SubdomainId], pieces: &mut Pieces) {
    let mut flat: Vec<CellId> = dt
        .finite_cells()
        .filter(|&c| is_flat(&cell_vertices(dt, c).map(|v| dt.point(v))))
        .collect();
    loop {
        let mut moved = false;
        flat.retain(|&c| {
            let Some([i, j]) = faces_to_move_across(dt, c, subdomain, pieces) else {
                return true;
            };
            let cell = cell_vertices(dt, c);
            if let Some(f) = pieces.triangle_of(facet_vertices(&cell, i)) {
                for k in (0..4).filter(|&k| k != i && k != j) {
                    pieces.insert(facet_vertices(&cell, k), f);
                }
            }
            subdomain[c.0 as usize] = OUTSIDE;
            moved = true;
            false
        });
        if !moved {
            break;
        }
    }
}

/// The complex of the cells with a subdomain, vertices numbered in `VertexId` order.
fn collect(
    dt: &Delaunay3,
    subdomain: &[SubdomainId],
    patch_of: &HashMap<[VertexId; 3], PatchId>,
    inside: &[VertexId],
) -> MeshComplex {
    let kept = |c: CellId| subdomain[c.0 as usize] != OUTSIDE;
    let mut used: Vec<VertexId> = dt
        .finite_cells()
        .filter(|&c| kept(c))
        .flat_map(|c| cell_vertices(dt, c))
        .collect();
    used.sort_unstable();
    used.dedup();
    let mut index = vec![u32::MAX; dt.num_vertices()];
    let mut complex = MeshComplex::default();
    for (i, &v) in used.iter().enumerate() {
        index[v.0 as usize] = i as u32;
        complex.points.push(dt.point(v));
        complex
            .vertex_dimension
            .push(if inside.binary_search(&v).is_ok() {
                VertexDimension::Volume
            } else {
                VertexDimension::Surface
            });
    }
    for c in dt.finite_cells().filter(|&c| kept(c)) {
        let sub = subdomain[c.0 as usize];
        let cell = cell_vertices(dt, c);
        let p = cell.map(|v| dt.point(v));
        // Finite cells are positive in Shewchuk's sign, the opposite of the output convention.
        let mut tet = cell.map(|v| index[v.0 as usize]);
        tet.swap(0, 1);
        complex.tets.push(tet);
        complex.tet_subdomain.push(sub);
        for (i, other) in facets_to_smaller(dt, c, sub, |n| subdomain[n.0 as usize]) {
            let mut f = facet_vertices(&cell, i);
            let [a, b, d] = f.map(|v| dt.point(v));
            // The normal (counter-clockwise side) points away from this cell, to `other`.
            if orient3d(a, b, d, p[i]) != Sign::Positive {
                f.swap(0, 1);
            }
            complex
                .facet_patch
                .push(patch_of.get(&key(f)).copied().unwrap_or(PatchId(0)));
            complex.facets.push(f.map(|v| index[v.0 as usize]));
            complex.facet_subdomains.push([sub, other]);
        }
    }
    complex
}
