//! The last resort for a 2-manifold boundary: relabel cells where refinement could not make one.
//!
//! Refinement makes the boundary a 2-manifold wherever the sizes can resolve the surface (the
//! repairs of [`super::repair`]). Below the refinement floor they cannot: two sheets of a CSG
//! seam closer than the smallest protecting ball, a slot thinner than the cells. There the
//! boundary pinches at a vertex or an edge. Seen from a vertex `v`, the cells around it tile a
//! sphere (its link), split into inside and outside regions; the boundary is a disc at `v`
//! exactly when each region is connected through facets containing `v`. So at a pinched vertex
//! the smallest region (by volume) is given the other label, merging it with its neighbours,
//! until one inside and one outside region are left; the vertices of the relabelled cells are
//! looked at again. Each relabelling moves at most the volume of a few cells at the scale the
//! mesh could not resolve.

use super::cells::CellLevel;
use super::geometry::{cell_vertices, is_flat};
use crate::complex::signed_volume;
use crate::kernel::Point3;
use crate::oracle::{OUTSIDE, SubdomainId};
use crate::quality::dihedral_angles_deg;
use crate::triangulation::{CellId, Triangulation, VertexId};
use crate::union_find::UnionFind;
use std::collections::{BTreeMap, BTreeSet};

/// What the relabelling did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Relabelling {
    /// Cells moved into the domain.
    pub cells_in: usize,
    /// Cells moved out of the domain.
    pub cells_out: usize,
    /// Volume those moves added to (positive) or took from (negative) the domain.
    pub volume_change: f64,
    /// Pinched vertices left when the budget ran out (0 when the boundary is a 2-manifold).
    pub pinched_left: usize,
    /// Cells moved from one subdomain to another (the domain stays the same).
    pub cells_across: usize,
}

/// A region of the cells around a vertex: cells of one side connected through facets holding
/// the vertex.
struct Region {
    cells: Vec<CellId>,
    inside: bool,
    volume: f64,
    /// Contains the infinite cell or a flat cell: cannot be moved into the domain.
    stuck_outside: bool,
    /// Contains a cell relabelled before: cannot be moved again.
    moved: bool,
    /// Contains a cell with a vertex off the surface: moved only when no other region can be
    /// (a volume vertex comes onto the boundary, away from the surface).
    off_surface: bool,
}

/// Relabel cells until the boundary of the labelled cells is a 2-manifold at every vertex, or
/// `max_moves` regions were moved. `pinched` must hold every vertex where it is not (the vertices
/// of the non-manifold edges and the non-manifold vertices): the walk starts there and follows
/// the moves, instead of looking at every boundary vertex.
pub(crate) fn relabel_to_manifold<T: Triangulation<Point = Point3>>(
    tr: &T,
    cells: &mut CellLevel<'_>,
    pinched: &[VertexId],
    on_surface: &dyn Fn(VertexId) -> bool,
    max_moves: usize,
) -> Relabelling {
    let mut result = Relabelling::default();
    let mut todo: BTreeSet<u32> = pinched.iter().map(|v| v.0).collect();
    let mut around = Vec::new();
    let mut moved = vec![false; tr.cell_capacity()];
    let mut moves = 0;
    while let Some(v) = todo.pop_first() {
        let v = VertexId(v);
        loop {
            tr.incident_cells(v, &mut around);
            let regions = regions_around(tr, cells, v, &around, &moved, on_surface);
            let inside = regions.iter().filter(|r| r.inside).count();
            if inside <= 1 && regions.len() - inside <= 1 {
                break;
            }
            if moves >= max_moves {
                result.pinched_left += 1;
                break;
            }
            let label = majority_label(cells, &regions);
            // The smallest movable region undoing a contact of the boundary with itself (raising
            // the domain's Euler characteristic) or else keeping the characteristic, one joining
            // surface points only if there is one.
            let Some(r) = regions
                .iter()
                .filter(|r| !r.moved && (r.inside || !r.stuck_outside))
                .map(|r| {
                    let change = euler_characteristic_change(tr, cells, r).signum();
                    ((-change, r.off_surface, r.volume), r)
                })
                .min_by(|(a, _), (b, _)| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal))
                .map(|(_, r)| r)
            else {
                result.pinched_left += 1;
                break;
            };
            moves += 1;
            for &c in &r.cells {
                moved[c.0 as usize] = true;
                if r.inside {
                    cells.set_subdomain(c, OUTSIDE);
                    result.cells_out += 1;
                } else {
                    cells.set_subdomain(c, label);
                    result.cells_in += 1;
                }
                todo.extend(cell_vertices(tr, c).iter().map(|w| w.0));
            }
            result.volume_change += if r.inside { -r.volume } else { r.volume };
        }
    }
    result
}

/// Where a subdomain's boundary touches itself at a vertex (an interface pinched against another
/// subdomain, or two sheets of an inclusion's surface, or an inclusion and the outer surface,
/// that the sizes could not separate), relabel cells between subdomains there. Around a vertex,
/// the boundary of subdomain `L` is one disc exactly when the cells of `L`, and the other cells,
/// each form one piece connected through facets holding the vertex. The smallest movable piece
/// that breaks this is moved: a piece of `L` to the subdomain it shares the most facets with, or
/// a piece of the other cells (clear of the outside) into `L`. Pinches against the outside alone
/// are [`relabel_to_manifold`]'s. Each cell moves once, so it ends; the domain does not change.
pub(crate) fn relabel_interfaces<T: Triangulation<Point = Point3>>(
    tr: &T,
    cells: &mut CellLevel<'_>,
    pinched: &[VertexId],
    result: &mut Relabelling,
) {
    let mut todo: BTreeSet<u32> = pinched.iter().map(|v| v.0).collect();
    let mut around = Vec::new();
    let mut moved = vec![false; tr.cell_capacity()];
    while let Some(v) = todo.pop_first() {
        let v = VertexId(v);
        loop {
            tr.incident_cells(v, &mut around);
            let label: Vec<SubdomainId> = around
                .iter()
                .map(|&c| {
                    if tr.is_infinite_cell(c) {
                        OUTSIDE
                    } else {
                        cells.subdomain(c)
                    }
                })
                .collect();
            // Cells around `v` sharing a facet that holds `v`.
            let mut next: Vec<Vec<usize>> = vec![Vec::new(); around.len()];
            for (k, &c) in around.iter().enumerate() {
                for (i, &w) in tr.cell(c).as_ref().iter().enumerate() {
                    if w != v
                        && let Some(j) = around.iter().position(|&x| x == tr.neighbor(c, i))
                    {
                        next[k].push(j);
                    }
                }
            }
            let movable = |piece: &[usize]| {
                piece.iter().all(|&k| {
                    label[k] != OUTSIDE && !moved.get(around[k].0 as usize).copied().unwrap_or(true)
                })
            };
            let volume = |piece: &[usize]| piece.iter().map(|&k| volume_of(tr, around[k])).sum();
            // Candidate moves: (volume, cells around `v` by index, new subdomain).
            let mut moves: Vec<(f64, Vec<usize>, SubdomainId)> = Vec::new();
            let labels: BTreeSet<SubdomainId> =
                label.iter().copied().filter(|&l| l != OUTSIDE).collect();
            for l in labels {
                let inner = pieces(&next, |k| label[k] == l);
                let outer = pieces(&next, |k| label[k] != l);
                if inner.len() <= 1 && outer.len() <= 1 {
                    continue;
                }
                if inner.len() > 1 {
                    for piece in inner.into_iter().filter(|p| movable(p)) {
                        let mut votes: BTreeMap<SubdomainId, usize> = BTreeMap::new();
                        for &k in &piece {
                            for &j in &next[k] {
                                if label[j] != l && label[j] != OUTSIDE {
                                    *votes.entry(label[j]).or_default() += 1;
                                }
                            }
                        }
                        if let Some((to, _)) = votes
                            .into_iter()
                            .max_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)))
                        {
                            moves.push((volume(&piece), piece, to));
                        }
                    }
                }
                for piece in outer.into_iter().filter(|p| movable(p)) {
                    moves.push((volume(&piece), piece, l));
                }
            }
            let Some((_, piece, to)) = moves
                .into_iter()
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
            else {
                break;
            };
            for k in piece {
                let c = around[k];
                moved[c.0 as usize] = true;
                cells.set_subdomain(c, to);
                result.cells_across += 1;
                todo.extend(cell_vertices(tr, c).iter().map(|w| w.0));
            }
        }
    }
}

/// The pieces of the cells `member` accepts, connected through `next`, each sorted.
fn pieces(next: &[Vec<usize>], member: impl Fn(usize) -> bool) -> Vec<Vec<usize>> {
    let mut seen = vec![false; next.len()];
    let mut out = Vec::new();
    for start in 0..next.len() {
        if seen[start] || !member(start) {
            continue;
        }
        seen[start] = true;
        let mut piece = vec![start];
        let mut k = 0;
        while k < piece.len() {
            for &j in &next[piece[k]] {
                if !seen[j] && member(j) {
                    seen[j] = true;
                    piece.push(j);
                }
            }
            k += 1;
        }
        piece.sort_unstable();
        out.push(piece);
    }
    out
}

/// Give the other label to the `count` smallest face-connected pieces of cells (islands of
/// inside cells, cavities of outside ones; never the outside piece holding the infinite cell),
/// each smaller than [`STRAY_VOLUME`] of the domain: the extra boundary components that
/// unresolved seams leave. Cavities holding a flat cell stay (filling them would put the flat
/// cell in the mesh). Returns the cells moved in and out, and the volume change.
pub(crate) fn remove_stray_pieces<T: Triangulation<Point = Point3>>(
    tr: &T,
    cells: &mut CellLevel<'_>,
    count: usize,
    result: &mut Relabelling,
) {
    if count == 0 {
        return;
    }
    let n = tr.cell_capacity();
    let inside = |c: CellId| !tr.is_infinite_cell(c) && cells.subdomain(c) != OUTSIDE;
    let mut sets = UnionFind::new(n);
    let live: Vec<CellId> = tr.cells().collect();
    for &c in &live {
        for i in 0..4 {
            let nb = tr.neighbor(c, i);
            if inside(nb) == inside(c) {
                sets.union(c.0, nb.0);
            }
        }
    }
    // Per piece (by root): volume, can it be relabelled, its cells.
    let mut volume = vec![0.0f64; n];
    let mut movable = vec![true; n];
    let mut domain_volume = 0.0;
    for &c in &live {
        let root = sets.find(c.0) as usize;
        if tr.is_infinite_cell(c) {
            movable[root] = false;
            continue;
        }
        let p = cell_vertices(tr, c).map(|w| tr.point(w));
        let v = signed_volume(&p).abs();
        volume[root] += v;
        if inside(c) {
            domain_volume += v;
        } else if is_flat(&p) {
            movable[root] = false;
        }
    }
    let mut roots: Vec<u32> = live
        .iter()
        .map(|&c| sets.find(c.0))
        .filter(|&r| movable[r as usize] && volume[r as usize] < STRAY_VOLUME * domain_volume)
        .collect();
    roots.sort_unstable();
    roots.dedup();
    roots.sort_by(|&a, &b| {
        volume[a as usize]
            .total_cmp(&volume[b as usize])
            .then(a.cmp(&b))
    });
    roots.truncate(count);
    let label = live
        .iter()
        .map(|&c| cells.subdomain(c))
        .filter(|&s| s != OUTSIDE)
        .min()
        .unwrap_or(OUTSIDE);
    // Decide every move first: a filled cavity takes the subdomain of a neighbour across its
    // boundary, so the labels must be read before any changes.
    let mut changes: Vec<(CellId, SubdomainId)> = Vec::new();
    for &c in &live {
        if !roots.contains(&sets.find(c.0)) {
            continue;
        }
        let to = if inside(c) {
            OUTSIDE
        } else {
            (0..4)
                .map(|i| tr.neighbor(c, i))
                .find(|&nb| inside(nb))
                .map_or(label, |nb| cells.subdomain(nb))
        };
        changes.push((c, to));
    }
    for (c, to) in changes {
        let v = volume_of(tr, c);
        if to == OUTSIDE {
            result.cells_out += 1;
            result.volume_change -= v;
        } else {
            result.cells_in += 1;
            result.volume_change += v;
        }
        cells.set_subdomain(c, to);
    }
}

/// Largest piece [`remove_stray_pieces`] relabels, as a fraction of the domain's volume.
pub const STRAY_VOLUME: f64 = 1e-3;

/// Smallest dihedral angle (degrees) under which a cell alone in its subdomain is given the label
/// around it ([`absorb_sliver_islands`]).
const ISLAND_SLIVER_DEG: f64 = 5.0;

/// Give the label around it to each cell that is a component of its subdomain on its own (its
/// four neighbours all of one other label) and a sliver (smallest dihedral angle under
/// [`ISLAND_SLIVER_DEG`]). Such a cell is all refinement made of a blob below its floor (a
/// speckle voxel of an image): four boundary points nearly in a plane, with next to no volume,
/// which no optimiser can mend since each of its vertices lies on its boundary. Cells are taken
/// in order and see the labels given before them. Returns how many were relabelled.
pub(crate) fn absorb_sliver_islands<T: Triangulation<Point = Point3>>(
    tr: &T,
    cells: &mut CellLevel<'_>,
    result: &mut Relabelling,
) -> usize {
    let label = |cells: &CellLevel<'_>, c: CellId| {
        if tr.is_infinite_cell(c) {
            OUTSIDE
        } else {
            cells.subdomain(c)
        }
    };
    let mut absorbed = 0;
    for c in tr.finite_cells() {
        let own = cells.subdomain(c);
        if own == OUTSIDE {
            continue;
        }
        let around: [SubdomainId; 4] = std::array::from_fn(|i| label(cells, tr.neighbor(c, i)));
        let to = around[0];
        if to == own || around.iter().any(|&l| l != to) {
            continue;
        }
        let p = cell_vertices(tr, c).map(|w| tr.point(w));
        let smallest = dihedral_angles_deg(&p)
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        if smallest.is_nan() || smallest >= ISLAND_SLIVER_DEG {
            continue;
        }
        if to == OUTSIDE {
            result.cells_out += 1;
            result.volume_change -= volume_of(tr, c);
        } else {
            result.cells_across += 1;
        }
        cells.set_subdomain(c, to);
        absorbed += 1;
    }
    absorbed
}

fn volume_of<T: Triangulation<Point = Point3>>(tr: &T, c: CellId) -> f64 {
    signed_volume(&cell_vertices(tr, c).map(|w| tr.point(w))).abs()
}

/// The regions of the cells `around` vertex `v`.
fn regions_around<T: Triangulation<Point = Point3>>(
    tr: &T,
    cells: &CellLevel<'_>,
    v: VertexId,
    around: &[CellId],
    moved: &[bool],
    on_surface: &dyn Fn(VertexId) -> bool,
) -> Vec<Region> {
    let inside = |c: CellId| !tr.is_infinite_cell(c) && cells.subdomain(c) != OUTSIDE;
    let mut sets = UnionFind::new(around.len());
    for (k, &c) in around.iter().enumerate() {
        let vertices = tr.cell(c);
        for (i, &w) in vertices.as_ref().iter().enumerate() {
            if w == v {
                continue;
            }
            // The facet opposite `w` holds `v`: its other cell is around `v` too.
            let n = tr.neighbor(c, i);
            if inside(n) == inside(c)
                && let Some(j) = around.iter().position(|&x| x == n)
            {
                sets.union(k as u32, j as u32);
            }
        }
    }
    let mut regions: Vec<Region> = Vec::new();
    let mut region_of_root: Vec<Option<usize>> = vec![None; around.len()];
    for (k, &c) in around.iter().enumerate() {
        let root = sets.find(k as u32) as usize;
        let r = *region_of_root[root].get_or_insert_with(|| {
            regions.push(Region {
                cells: Vec::new(),
                inside: inside(c),
                volume: 0.0,
                stuck_outside: false,
                moved: false,
                off_surface: false,
            });
            regions.len() - 1
        });
        let region = &mut regions[r];
        region.cells.push(c);
        region.moved |= moved.get(c.0 as usize).copied().unwrap_or(true);
        region.off_surface |= tr
            .cell(c)
            .as_ref()
            .iter()
            .any(|&w| !tr.is_infinite_vertex(w) && !on_surface(w));
        if tr.is_infinite_cell(c) {
            region.stuck_outside = true;
        } else {
            let p = cell_vertices(tr, c).map(|w| tr.point(w));
            region.volume += signed_volume(&p).abs();
            region.stuck_outside |= is_flat(&p);
        }
    }
    regions
}

/// How much giving `region`'s cells the other label changes the Euler characteristic of the
/// domain (the closure of the inside cells). A pinch is the boundary touching itself where the
/// mesh could not resolve two sheets: a slot closed at a vertex or along a seam, a thin wall
/// pierced there. The contact closes a loop of the domain or of its complement that the input
/// does not have, lowering the characteristic by one per loop; of the moves that remove the
/// contact, the one that opens the loop again raises it back, while the others keep the loop as
/// a handle (the vertices of a pinched seam decided one by one on volume alone alternate between
/// filling and cutting and leave such handles). With `J` the inside cells not in the region, the
/// change is `±(χ(R̄) − χ(R̄ ∩ J̄))`: `+` when the region moves in, `−` when it moves out.
fn euler_characteristic_change<T: Triangulation<Point = Point3>>(
    tr: &T,
    cells: &CellLevel<'_>,
    region: &Region,
) -> i64 {
    let rest = |c: CellId| {
        !tr.is_infinite_cell(c) && cells.subdomain(c) != OUTSIDE && !region.cells.contains(&c)
    };
    let mut vertices: BTreeSet<u32> = BTreeSet::new();
    let mut edges: BTreeSet<[u32; 2]> = BTreeSet::new();
    let mut triangles: BTreeSet<[u32; 3]> = BTreeSet::new();
    // Faces of the region (tets are never shared: `J` holds none of them).
    let mut euler = -(region.cells.len() as i64);
    let mut shared = 0i64;
    for &c in &region.cells {
        let vs = cell_vertices(tr, c);
        for i in 0..4 {
            let mut t = super::geometry::facet_vertices(&vs, i).map(|v| v.0);
            t.sort_unstable();
            if triangles.insert(t) {
                euler += 1;
                shared += i64::from(rest(tr.neighbor(c, i)));
            }
            vertices.insert(vs[i].0);
            for j in i + 1..4 {
                edges.insert([vs[i].0.min(vs[j].0), vs[i].0.max(vs[j].0)]);
            }
        }
    }
    let mut around: BTreeMap<u32, Vec<CellId>> = BTreeMap::new();
    for &v in &vertices {
        let mut list = Vec::new();
        tr.incident_cells(VertexId(v), &mut list);
        euler += 1;
        shared += i64::from(list.iter().any(|&c| rest(c)));
        around.insert(v, list);
    }
    for [a, b] in edges {
        euler -= 1;
        let on_edge = around[&a]
            .iter()
            .any(|&c| rest(c) && tr.cell(c).as_ref().contains(&VertexId(b)));
        shared -= i64::from(on_edge);
    }
    let change = euler - shared;
    if region.inside { -change } else { change }
}

/// The subdomain most of the inside cells around a vertex have (the smallest on a tie).
fn majority_label(cells: &CellLevel<'_>, regions: &[Region]) -> SubdomainId {
    let mut labels: Vec<SubdomainId> = regions
        .iter()
        .filter(|r| r.inside)
        .flat_map(|r| r.cells.iter().map(|&c| cells.subdomain(c)))
        .collect();
    labels.sort_unstable();
    let mut best = (0usize, OUTSIDE);
    for run in labels.chunk_by(|a, b| a == b) {
        if run.len() > best.0 {
            best = (run.len(), run[0]);
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::oracle::{Aabb, Everywhere};
    use crate::random::XorShift;
    use crate::refine::criteria::{CellCriteria, Sizing};
    use crate::refine::engine::MesherLevel;
    use crate::triangulation::Delaunay3;

    /// Every point inside, in the unit box: the labels are set by the test.
    const UNIT_BOX: Aabb = Aabb {
        min: Point3::ZERO,
        max: Point3::ONE,
    };

    /// Euler characteristic of the closure of the inside cells, from all its simplices.
    fn domain_euler<T: Triangulation<Point = Point3>>(tr: &T, cells: &CellLevel<'_>) -> i64 {
        let mut simplices: BTreeSet<Vec<u32>> = BTreeSet::new();
        for c in tr.finite_cells() {
            if cells.subdomain(c) == OUTSIDE {
                continue;
            }
            let mut vs = cell_vertices(tr, c).map(|v| v.0);
            vs.sort_unstable();
            for mask in 1u32..16 {
                let face = (0..4).filter(|&k| mask & (1 << k) != 0).map(|k| vs[k]);
                simplices.insert(face.collect());
            }
        }
        simplices
            .iter()
            .map(|s| if s.len() % 2 == 1 { 1 } else { -1 })
            .sum()
    }

    /// The Delaunay triangulation of `n` random points of the unit box, and a cell level that
    /// refines nothing, its cells labelled 1.
    fn random_cells(rng: &mut XorShift, n: usize) -> (Delaunay3, CellLevel<'static>) {
        let points: Vec<Point3> = (0..n)
            .map(|_| Point3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()))
            .collect();
        let tr = Delaunay3::from_points(&points).expect("points in general position");
        let criteria = CellCriteria {
            radius_edge_ratio: 0.0,
            size: Sizing::Constant(f64::INFINITY),
        };
        let mut cells = CellLevel::new(&Everywhere(UNIT_BOX), criteria);
        cells.scan(&tr);
        (tr, cells)
    }

    /// On random labellings of a random Delaunay triangulation, the change predicted for moving
    /// any movable region around any vertex is the change of the whole domain's characteristic.
    #[test]
    fn predicted_euler_change_is_the_domains() {
        let mut rng = XorShift::new(0x2545_f491_4f6c_dd1d);
        let (tr, mut cells) = random_cells(&mut rng, 80);
        let mut next = || rng.next_f64();
        let all: Vec<CellId> = tr.finite_cells().collect();
        let moved = vec![false; tr.cell_capacity()];
        let mut around = Vec::new();
        let mut checked = 0;
        for _ in 0..4 {
            cells.scan(&tr);
            for &c in &all {
                if next() < 0.5 {
                    cells.set_subdomain(c, OUTSIDE);
                }
            }
            let before = domain_euler(&tr, &cells);
            for v in tr.vertices() {
                tr.incident_cells(v, &mut around);
                let regions = regions_around(&tr, &cells, v, &around, &moved, &|_| true);
                for r in regions.iter().filter(|r| r.inside || !r.stuck_outside) {
                    let change = euler_characteristic_change(&tr, &cells, r);
                    let flip = |cells: &mut CellLevel<'_>, to_inside: bool| {
                        for &c in &r.cells {
                            cells
                                .set_subdomain(c, if to_inside { SubdomainId(1) } else { OUTSIDE });
                        }
                    };
                    flip(&mut cells, !r.inside);
                    assert_eq!(domain_euler(&tr, &cells), before + change);
                    flip(&mut cells, r.inside);
                    checked += usize::from(change != 0);
                }
            }
        }
        // Moves that change the characteristic were among those checked.
        assert!(checked > 10, "{checked}");
    }

    /// Cells alone in subdomain 2 amid subdomain 1 of a random Delaunay triangulation: the
    /// slivers among them take label 1, the others keep theirs, and so does every cell of a
    /// pair of neighbours in subdomain 2.
    #[test]
    fn sliver_islands_take_the_label_around_them() {
        let (tr, mut cells) = random_cells(&mut XorShift::new(0x9e37_79b9_7f4a_7c15), 300);
        let smallest = |c: CellId| {
            let p = cell_vertices(&tr, c).map(|w| tr.point(w));
            dihedral_angles_deg(&p)
                .into_iter()
                .fold(f64::INFINITY, f64::min)
        };
        let interior = |c: CellId| (0..4).all(|i| !tr.is_infinite_cell(tr.neighbor(c, i)));
        let mut taken = vec![false; tr.cell_capacity()];
        let (mut islands, mut pairs) = (Vec::new(), Vec::new());
        for c in tr.finite_cells() {
            let free = |x: CellId| !taken[x.0 as usize] && interior(x);
            let nbs: Vec<CellId> = (0..4).map(|i| tr.neighbor(c, i)).collect();
            if !free(c) || nbs.iter().any(|&n| taken[n.0 as usize]) {
                continue;
            }
            // Every third choice, a sliver with a neighbour in subdomain 2 too: no island.
            if smallest(c) < ISLAND_SLIVER_DEG && pairs.len() < 3 && free(nbs[0]) {
                let n = nbs[0];
                if (0..4).all(|i| !taken[tr.neighbor(n, i).0 as usize]) {
                    for x in [c, n] {
                        taken[x.0 as usize] = true;
                        cells.set_subdomain(x, SubdomainId(2));
                        pairs.push(x);
                    }
                    continue;
                }
            }
            taken[c.0 as usize] = true;
            cells.set_subdomain(c, SubdomainId(2));
            islands.push(c);
        }
        let slivers = islands
            .iter()
            .filter(|&&c| smallest(c) < ISLAND_SLIVER_DEG)
            .count();
        assert!(slivers > 0 && slivers < islands.len() && !pairs.is_empty());
        let mut result = Relabelling::default();
        assert_eq!(absorb_sliver_islands(&tr, &mut cells, &mut result), slivers);
        assert_eq!(result.cells_across, slivers);
        for &c in &islands {
            let expected = if smallest(c) < ISLAND_SLIVER_DEG {
                1
            } else {
                2
            };
            assert_eq!(cells.subdomain(c), SubdomainId(expected));
        }
        for &c in &pairs {
            assert_eq!(cells.subdomain(c), SubdomainId(2));
        }
    }
}
