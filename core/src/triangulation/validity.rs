//! Validity checks of a `Delaunay3` or `Regular3`: combinatorial consistency, orientation, and the
//! exact local Delaunay (regularity) property of every facet under the kernel's symbolic
//! perturbation; for `Regular3` also that every hidden vertex is really hidden.
//!
//! By the local-implies-global theorem the facet check makes the whole triangulation Delaunay
//! (regular), and with perturbation that triangulation is unique, so a passing check pins the
//! result down exactly. Meant for tests (O(n log n)), including other crates' tests.

use super::triangulation3::ConflictKernel;
use super::{CellId, Delaunay3, Regular3, Triangulation, Triangulation3, VertexId};
use crate::kernel::{Sign, orient3d};

/// The first defect found.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum ValidityError {
    #[error("the triangulation spans fewer than 3 dimensions but has {0} cells")]
    CellsBeforeDimension3(usize),
    #[error(
        "stored counts ({stored_live} live, {stored_finite} finite) differ from the cells found ({live} live, {finite} finite)"
    )]
    Counts {
        stored_live: usize,
        stored_finite: usize,
        live: usize,
        finite: usize,
    },
    #[error("cell {cell:?} has vertices {vertices:?}: repeated or out of range")]
    BadVertices {
        cell: CellId,
        vertices: [VertexId; 4],
    },
    #[error("neighbour {facet} of cell {cell:?} is {neighbor:?}, not a live cell")]
    DeadNeighbor {
        cell: CellId,
        facet: usize,
        neighbor: CellId,
    },
    #[error(
        "cell {cell:?} sees {neighbor:?} across facet {facet}, but the link back is missing or joins another facet"
    )]
    Asymmetric {
        cell: CellId,
        facet: usize,
        neighbor: CellId,
    },
    #[error("finite cell {cell:?} {vertices:?} has orientation {sign:?}, expected positive")]
    Orientation {
        cell: CellId,
        vertices: [VertexId; 4],
        sign: Sign,
    },
    #[error("vertex {vertex:?} points to cell {cell:?}, which does not contain it")]
    VertexCell {
        vertex: VertexId,
        cell: Option<CellId>,
    },
    #[error("vertex {0:?} belongs to no cell")]
    IsolatedVertex(VertexId),
    #[error("hidden vertex {0:?} belongs to a cell")]
    HiddenInCell(VertexId),
    #[error(
        "hidden vertex {vertex:?} conflicts with cell {cell:?}, which contains its point: it should be in the triangulation"
    )]
    NotHidden { vertex: VertexId, cell: CellId },
    #[error("Euler characteristic V - E + F - C = {0}, expected 0 for a closed 3-sphere")]
    Euler(i64),
    #[error(
        "facet {facet} of cell {cell:?} is not locally Delaunay: vertex {vertex:?} across it conflicts with the cell"
    )]
    NotDelaunay {
        cell: CellId,
        facet: usize,
        vertex: VertexId,
    },
}

/// Checks everything listed in the module documentation; `Ok` means `dt` is the (perturbed)
/// Delaunay triangulation of its vertices.
pub fn check_delaunay3(dt: &Delaunay3) -> Result<(), ValidityError> {
    check_triangulation3(dt)
}

/// Checks everything listed in the module documentation; `Ok` means `rt` is the (perturbed)
/// regular triangulation of its weighted vertices, hidden ones included.
pub fn check_regular3(rt: &Regular3) -> Result<(), ValidityError> {
    check_triangulation3(rt)?;
    check_hidden(rt)
}

fn check_triangulation3<K: ConflictKernel>(dt: &Triangulation3<K>) -> Result<(), ValidityError> {
    if dt.dimension() < 3 {
        return match dt.num_cells() {
            0 => Ok(()),
            n => Err(ValidityError::CellsBeforeDimension3(n)),
        };
    }
    check_cells(dt)?;
    check_vertices(dt)?;
    check_euler(dt)?;
    check_local_delaunay(dt)
}

fn check_cells<K: ConflictKernel>(dt: &Triangulation3<K>) -> Result<(), ValidityError> {
    let inf = dt.infinite_vertex();
    let n = dt.num_vertices() as u32;
    let (mut live, mut finite) = (0, 0);
    for c in dt.cells() {
        live += 1;
        let v = dt.cell(c);
        let repeated = (0..4).any(|i| (i + 1..4).any(|j| v[i] == v[j]));
        if repeated || v.iter().any(|&x| x != inf && x.0 >= n) {
            return Err(ValidityError::BadVertices {
                cell: c,
                vertices: v,
            });
        }
        for i in 0..4 {
            let nb = dt.neighbor(c, i);
            if (nb.0 as usize) >= dt.cell_capacity() || !dt.is_live(nb) {
                return Err(ValidityError::DeadNeighbor {
                    cell: c,
                    facet: i,
                    neighbor: nb,
                });
            }
            let m = dt.mirror_index(c, i);
            let w = dt.cell(nb);
            let shared = (0..4)
                .filter(|&j| j != i)
                .all(|j| w.contains(&v[j]) && w[m] != v[j]);
            if dt.neighbor(nb, m) != c
                || dt.mirror_index(nb, m) != i
                || !shared
                || w.contains(&v[i])
            {
                return Err(ValidityError::Asymmetric {
                    cell: c,
                    facet: i,
                    neighbor: nb,
                });
            }
        }
        if !v.contains(&inf) {
            finite += 1;
            let [a, b, cc, d] = v.map(|x| dt.point(x));
            let sign = orient3d(a, b, cc, d);
            if sign != Sign::Positive {
                return Err(ValidityError::Orientation {
                    cell: c,
                    vertices: v,
                    sign,
                });
            }
        }
    }
    if live != dt.num_cells() || finite != dt.num_finite_cells() {
        return Err(ValidityError::Counts {
            stored_live: dt.num_cells(),
            stored_finite: dt.num_finite_cells(),
            live,
            finite,
        });
    }
    Ok(())
}

fn check_vertices<K: ConflictKernel>(dt: &Triangulation3<K>) -> Result<(), ValidityError> {
    let mut used = vec![false; dt.num_vertices()];
    for c in dt.cells() {
        for v in dt.cell(c) {
            if !dt.is_infinite_vertex(v) {
                used[v.0 as usize] = true;
            }
        }
    }
    for v in dt.vertices() {
        if dt.is_hidden(v) {
            if used[v.0 as usize] || dt.vertex_cell(v).is_some() {
                return Err(ValidityError::HiddenInCell(v));
            }
            continue;
        }
        if !used[v.0 as usize] {
            return Err(ValidityError::IsolatedVertex(v));
        }
        let c = dt.vertex_cell(v);
        if !c.is_some_and(|c| dt.is_live(c) && dt.cell(c).contains(&v)) {
            return Err(ValidityError::VertexCell { vertex: v, cell: c });
        }
    }
    Ok(())
}

fn check_euler<K: ConflictKernel>(dt: &Triangulation3<K>) -> Result<(), ValidityError> {
    let v = (dt.num_vertices() - dt.hidden_vertices().count()) as i64 + 1;
    let e = dt.edges().len() as i64;
    let f = dt.facets().count() as i64;
    let c = dt.num_cells() as i64;
    let chi = v - e + f - c;
    if chi != 0 {
        return Err(ValidityError::Euler(chi));
    }
    Ok(())
}

fn check_local_delaunay<K: ConflictKernel>(dt: &Triangulation3<K>) -> Result<(), ValidityError> {
    for c in dt.cells() {
        for i in 0..4 {
            let nb = dt.neighbor(c, i);
            let vertex = dt.cell(nb)[dt.mirror_index(c, i)];
            // The infinite vertex conflicts with no finite cell.
            if !dt.is_infinite_vertex(vertex)
                && dt.in_conflict(c.0, dt.point(vertex), dt.weight(vertex))
            {
                return Err(ValidityError::NotDelaunay {
                    cell: c,
                    facet: i,
                    vertex,
                });
            }
        }
    }
    Ok(())
}

/// Every hidden vertex lies in a cell it does not conflict with (exact, perturbed power test).
fn check_hidden(rt: &Regular3) -> Result<(), ValidityError> {
    if rt.dimension() < 3 {
        return Ok(());
    }
    for vertex in rt.hidden_vertices() {
        let p = rt.point(vertex);
        let cell = rt
            .locate(p, None)
            .ok_or(ValidityError::CellsBeforeDimension3(0))?;
        if rt.in_conflict(cell.0, p, rt.weight(vertex)) {
            return Err(ValidityError::NotHidden { vertex, cell });
        }
    }
    Ok(())
}
