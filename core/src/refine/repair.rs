//! Validity repairs of the complex once the criteria are met: refinement again where the mesh is
//! not yet usable, in bounded rounds.
//!
//! Three rules, checked on the complex the labels give (cells inside a subdomain, the boundary
//! facets against the outside):
//! - a flat cell inside the domain is refined (see [`is_flat`]): criteria on size and radius-edge
//!   ratio do not see four cocircular points on a planar patch;
//! - where the boundary is not a 2-manifold (an edge in more than two boundary facets, a vertex
//!   whose facets form several fans), the biggest incident facet is refined: the manifold
//!   criterion of the thesis (ch. 3) and of CGAL's `manifold()` option;
//! - where a boundary component's Euler characteristic matches no closed component of the input,
//!   that component's biggest facets are refined, until the characteristics match or a guard
//!   stops it; what is left unmatched is reported, naming the input component.

use super::cells::CellLevel;
use super::facets::SurfaceLevel;
use super::geometry::{cell_vertices, facet_vertices, is_flat};
use crate::kernel::Point3;
use crate::mesh::{component_euler_characteristics, non_manifold_elements};
use crate::oracle::{OUTSIDE, SubdomainId};
use crate::triangulation::{CellId, Triangulation, VertexId};
use std::collections::BTreeMap;

/// What the repairs after the criteria must reach.
#[derive(Clone, Debug, PartialEq)]
pub struct ValidityOptions {
    /// Refine until the boundary is a 2-manifold (off: `--non-manifold`, faster).
    pub manifold: bool,
    /// Euler characteristic of each closed component of the input surface, in the input's order;
    /// when given (and `manifold` is on), boundary components that match none are refined.
    pub input_euler: Option<Vec<i64>>,
    /// Most rounds of repairs, each followed by refinement to the criteria again.
    pub max_rounds: usize,
    /// The topology rule stops once the mesh has this many times the vertices it had when the
    /// criteria were first met.
    pub max_vertex_growth: f64,
}

impl Default for ValidityOptions {
    fn default() -> Self {
        ValidityOptions {
            manifold: true,
            input_euler: None,
            max_rounds: 4,
            max_vertex_growth: 1.5,
        }
    }
}

/// How valid the complex is after the repairs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Validity {
    /// Flat cells left inside the domain: after refinement and its repairs, then counted again
    /// on the output mesh once the optimisers, which may remove them, have run.
    pub flat_cells: usize,
    /// The boundary is a 2-manifold.
    pub manifold: bool,
    /// One sentence per input component whose Euler characteristic the mesh boundary does not
    /// reproduce (empty when the topology matches or was not asked for).
    pub topology_warnings: Vec<String>,
    /// How far the boundary's topology is from the input's: the difference of the total Euler
    /// characteristics plus that of the component counts (0 when they match or were not asked
    /// for).
    pub topology_gap: u64,
    /// Cells relabelled to make the boundary a 2-manifold where refinement could not.
    pub relabelling: super::manifold::Relabelling,
    /// Boundary components beyond those matching the input's components.
    pub extra_components: usize,
    /// Restricted facets where two sheets of the surface are closer than the refinement floor
    /// ([`MeshCriteria::refinement_floor`](super::criteria::MeshCriteria::refinement_floor)), which
    /// refinement does not separate: a plate or a slot thinner than that may be lost or closed.
    pub unresolved_sheets: usize,
}

/// A boundary facet of the complex: the inside cell and the index of the vertex opposite it.
#[derive(Clone, Copy, Debug)]
struct BoundaryFacet {
    cell: CellId,
    index: usize,
}

/// The defects found in one look at the complex, and what to refine for them.
#[derive(Default)]
pub(crate) struct Defects {
    flat: Vec<CellId>,
    /// Boundary facets to refine (by their surface ball, or their cell when they have none).
    facets: Vec<BoundaryFacet>,
    non_manifold: bool,
    /// Vertices of the flat cells, the non-manifold edges and the non-manifold vertices: where
    /// refinement may be kept out by a protecting ball.
    pub(crate) stuck: Vec<VertexId>,
    topology_warnings: Vec<String>,
    topology_gap: u64,
    /// Boundary components beyond those matching the input's.
    extra_components: usize,
}

impl Defects {
    /// Nothing left to refine.
    pub(crate) fn is_empty(&self) -> bool {
        self.flat.is_empty() && self.facets.is_empty()
    }

    /// Queue the refinements in the levels: flat cells and facets without a surface ball in the
    /// cell level, facets with one in the surface level.
    pub(crate) fn queue<T: Triangulation<Point = Point3>>(
        &self,
        tr: &T,
        surface: &mut SurfaceLevel<'_>,
        cells: &mut CellLevel<'_>,
    ) {
        for &c in &self.flat {
            cells.force(tr, c);
        }
        for f in &self.facets {
            if surface.ball(f.cell, f.index).is_some() {
                surface.force(tr, f.cell, f.index);
            } else {
                cells.force(tr, f.cell);
            }
        }
    }

    /// The state these defects leave the complex in, if nothing more is refined.
    pub(crate) fn validity(&self) -> Validity {
        Validity {
            flat_cells: self.flat.len(),
            manifold: !self.non_manifold,
            topology_warnings: self.topology_warnings.clone(),
            topology_gap: self.topology_gap,
            relabelling: Default::default(),
            extra_components: self.extra_components,
            unresolved_sheets: 0,
        }
    }
}

/// The facets between two labels, once from each side inside a subdomain: `sides[k]` is the
/// subdomain of `facets[k]`'s cell, and `once` keeps one side of each facet (the lower label's,
/// or the only one against the outside).
struct LabelBoundary {
    facets: Vec<BoundaryFacet>,
    triangles: Vec<[u32; 3]>,
    sides: Vec<SubdomainId>,
    once: Vec<usize>,
}

/// Look at the complex the labels of `cells` give. The topology rule is applied only when
/// `topology` is set (the guards allow it) and the boundary is a 2-manifold.
pub(crate) fn find_defects<T: Triangulation<Point = Point3>>(
    tr: &T,
    cells: &CellLevel<'_>,
    options: &ValidityOptions,
    topology: bool,
) -> Defects {
    let mut defects = Defects::default();
    let boundary = label_boundary(tr, cells, &mut defects.flat);
    let (spots, pinched) = non_manifold_spots(tr, cells, &boundary);
    defects.non_manifold = !spots.is_empty();
    defects.stuck = pinched
        .iter()
        .map(|&v| VertexId(v))
        .chain(defects.flat.iter().flat_map(|&c| cell_vertices(tr, c)))
        .collect();
    defects.stuck.sort_unstable();
    defects.stuck.dedup();
    if options.manifold && defects.non_manifold {
        // The biggest facet around each spot is refined.
        let size = |k: usize| circumradius2_of(tr, boundary.triangles[k]);
        let mut chosen: Vec<usize> = spots
            .iter()
            .filter_map(|list| {
                list.iter()
                    .copied()
                    .max_by(|&x, &y| size(x).total_cmp(&size(y)).then(y.cmp(&x)))
            })
            .collect();
        chosen.sort_unstable();
        chosen.dedup();
        defects
            .facets
            .extend(chosen.into_iter().map(|k| boundary.facets[k]));
    }
    if !defects.non_manifold
        && let Some(input) = &options.input_euler
    {
        topology_defects(tr, &boundary, input, topology, &mut defects);
    }
    defects
}

/// The facets between labels, and the flat cells inside the domain into `flat`.
fn label_boundary<T: Triangulation<Point = Point3>>(
    tr: &T,
    cells: &CellLevel<'_>,
    flat: &mut Vec<CellId>,
) -> LabelBoundary {
    let mut b = LabelBoundary {
        facets: Vec::new(),
        triangles: Vec::new(),
        sides: Vec::new(),
        once: Vec::new(),
    };
    for c in tr.finite_cells() {
        let label = cells.subdomain(c);
        if label == OUTSIDE {
            continue;
        }
        let cell = cell_vertices(tr, c);
        if is_flat(&cell.map(|v| tr.point(v))) {
            flat.push(c);
        }
        for i in 0..4 {
            let n = tr.neighbor(c, i);
            let other = if tr.is_infinite_cell(n) {
                OUTSIDE
            } else {
                cells.subdomain(n)
            };
            if other != label {
                if other == OUTSIDE || label < other {
                    b.once.push(b.triangles.len());
                }
                b.facets.push(BoundaryFacet { cell: c, index: i });
                b.triangles.push(facet_vertices(&cell, i).map(|v| v.0));
                b.sides.push(label);
            }
        }
    }
    b
}

/// Squared circumradius of the triangle of vertices `t`.
fn circumradius2_of<T: Triangulation<Point = Point3>>(tr: &T, t: [u32; 3]) -> f64 {
    let [a, b, c] = t.map(|v| tr.point(VertexId(v)));
    circumradius2(a, b, c)
}

/// Where a boundary is not a 2-manifold: per spot (a non-manifold edge or vertex), the facets
/// around it, by index into `b`; and the vertices of those edges and the vertices themselves.
/// Each subdomain's boundary must be a 2-manifold, interfaces included (where three labels meet
/// along a curve the union of the interfaces is not, and need not be, one), and so must the
/// domain's (listed under `OUTSIDE`).
fn non_manifold_spots<T: Triangulation<Point = Point3>>(
    tr: &T,
    cells: &CellLevel<'_>,
    b: &LabelBoundary,
) -> (Vec<Vec<usize>>, Vec<u32>) {
    let mut by_label: BTreeMap<SubdomainId, Vec<usize>> = BTreeMap::new();
    for (k, &label) in b.sides.iter().enumerate() {
        by_label.entry(label).or_default().push(k);
    }
    // And the boundary of the whole domain, against the outside (with one subdomain, the same).
    if by_label.len() > 1 {
        let outer = b
            .once
            .iter()
            .copied()
            .filter(|&k| {
                let f = b.facets[k];
                let n = tr.neighbor(f.cell, f.index);
                tr.is_infinite_cell(n) || cells.subdomain(n) == OUTSIDE
            })
            .collect();
        by_label.insert(OUTSIDE, outer);
    }
    let mut spots: Vec<Vec<usize>> = Vec::new();
    let mut pinched: Vec<u32> = Vec::new();
    for facets in by_label.values() {
        let soup: Vec<[u32; 3]> = facets.iter().map(|&k| b.triangles[k]).collect();
        let (edges, vertices) = non_manifold_elements(&soup);
        let mut around: BTreeMap<u32, Vec<usize>> = edges
            .iter()
            .flatten()
            .chain(&vertices)
            .map(|&v| (v, Vec::new()))
            .collect();
        if around.is_empty() {
            continue;
        }
        for &k in facets {
            for v in b.triangles[k] {
                if let Some(list) = around.get_mut(&v) {
                    list.push(k);
                }
            }
        }
        for e in &edges {
            spots.push(
                around[&e[0]]
                    .iter()
                    .copied()
                    .filter(|&k| b.triangles[k].contains(&e[1]))
                    .collect(),
            );
        }
        for v in &vertices {
            spots.push(around[v].clone());
        }
        pinched.extend(edges.iter().flatten().chain(&vertices));
    }
    (spots, pinched)
}

/// The topology rule: the surfaces between labels (each facet once) against the `input`'s
/// Euler characteristics. The gap and the warnings go into `defects`, and with `refine` the
/// biggest facets of each offending component too.
fn topology_defects<T: Triangulation<Point = Point3>>(
    tr: &T,
    b: &LabelBoundary,
    input: &[i64],
    refine: bool,
    defects: &mut Defects,
) {
    let triangles: Vec<[u32; 3]> = b.once.iter().map(|&k| b.triangles[k]).collect();
    let size = |k: usize| circumradius2_of(tr, triangles[k]);
    let (component, euler) = component_euler_characteristics(&triangles);
    let mut count = vec![0usize; euler.len()];
    for &k in &component {
        count[k as usize] += 1;
    }
    let (offending, unmatched) = match_components(input, &euler, &count);
    defects.topology_gap = (euler.iter().sum::<i64>() - input.iter().sum::<i64>()).unsigned_abs()
        + euler.len().abs_diff(input.len()) as u64;
    if refine {
        for &k in &offending {
            let facets: Vec<usize> = (0..triangles.len())
                .filter(|&f| component[f] as usize == k)
                .collect();
            let largest = facets.iter().map(|&f| size(f)).fold(0.0, f64::max);
            defects.facets.extend(
                facets
                    .into_iter()
                    .filter(|&f| size(f) >= 0.25 * largest)
                    .map(|f| b.facets[b.once[f]]),
            );
        }
    }
    let extra = offending.len().saturating_sub(unmatched.len());
    defects.extra_components = extra;
    defects.topology_warnings = unmatched
        .iter()
        .copied()
        .map(|i| {
            format!(
                "input component {} (Euler characteristic {}) is not reproduced by the mesh boundary",
                i + 1,
                input[i]
            )
        })
        .collect();
    if extra > 0 {
        defects.topology_warnings.push(format!(
            "the mesh boundary has {extra} component(s) more than the input"
        ));
    }
}

/// Match the mesh's boundary components to the input's closed components by Euler
/// characteristic, the biggest mesh components first (a spurious component is usually small):
/// `(mesh components matching none, input components matched by none)`.
fn match_components(input: &[i64], euler: &[i64], facets: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let mut wanted: BTreeMap<i64, Vec<usize>> = BTreeMap::new();
    for (i, &e) in input.iter().enumerate().rev() {
        wanted.entry(e).or_default().push(i);
    }
    let mut order: Vec<usize> = (0..euler.len()).collect();
    order.sort_by_key(|&k| (std::cmp::Reverse(facets[k]), k));
    let mut offending = Vec::new();
    for k in order {
        match wanted.get_mut(&euler[k]).and_then(|list| list.pop()) {
            Some(_) => {}
            None => offending.push(k),
        }
    }
    let mut unmatched: Vec<usize> = wanted.into_values().flatten().collect();
    unmatched.sort_unstable();
    (offending, unmatched)
}

/// Squared circumradius of a triangle (infinite for a degenerate one, refined first).
fn circumradius2(a: Point3, b: Point3, c: Point3) -> f64 {
    let (ab, ac) = (b - a, c - a);
    let n2 = ab.cross(ac).length_squared();
    if n2 == 0.0 {
        return f64::INFINITY;
    }
    ab.length_squared() * ac.length_squared() * (b - c).length_squared() / (4.0 * n2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn components_match_by_euler_characteristic() {
        // Input: a sphere and a torus. Mesh: the torus closed into a sphere, and a spurious
        // small sphere.
        let (offending, unmatched) = match_components(&[2, 0], &[2, 2, 2], &[100, 80, 3]);
        assert_eq!(offending, vec![1, 2]);
        assert_eq!(unmatched, vec![1]);
        let (offending, unmatched) = match_components(&[0, 2], &[2, 0], &[10, 10]);
        assert!(offending.is_empty() && unmatched.is_empty());
        // A missing component is named even with nothing to refine (input components of the
        // same Euler characteristic are matched lowest index first).
        let (offending, unmatched) = match_components(&[2, 2], &[2], &[10]);
        assert!(offending.is_empty());
        assert_eq!(unmatched, vec![1]);
    }

    #[test]
    fn circumradius_of_a_right_triangle_is_half_the_hypotenuse() {
        let r2 = circumradius2(Point3::ZERO, Point3::X * 2.0, Point3::Y * 2.0);
        assert!((r2 - 2.0).abs() < 1e-12);
        assert_eq!(
            circumradius2(Point3::ZERO, Point3::X, Point3::X * 2.0),
            f64::INFINITY
        );
    }
}
