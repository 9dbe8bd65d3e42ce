//! The quality 2D mesher (Ruppert's algorithm with Shewchuk's refinements, as in Triangle): a
//! conforming Delaunay triangulation of a PSLG refined by two levels — constrained sub-segments,
//! then triangles — on the refinement engine. Holes and the outside are carved by flood fill from
//! the seeds; regions carry their attribute and area bound.
//!
//! Guarantees: every input segment is the union of triangulation edges (sub-segments end
//! unencroached, hence Delaunay); every domain triangle has its smallest angle at least the bound
//! (≤ 34°), except triangles left at small input angles, where refinement would not terminate.

mod constraints;
mod segments;
mod triangles;

pub use crate::refine::RefineError;

use super::pslg::{Pslg, PslgError};
use crate::refine::{Engine, Limits};
use crate::triangulation::Triangulation;
use crate::triangulation::delaunay2::{CellId, Delaunay2, TriangulationError, VertexId};
use constraints::{Constraints, Encroachment, Label};
use segments::SegmentLevel;
use std::cell::RefCell;
use std::rc::Rc;
use triangles::{TriangleCriteria, TriangleLevel};

/// Largest angle bound accepted: beyond about 34° Delaunay refinement may not terminate.
pub const MAX_MIN_ANGLE_DEG: f64 = 34.0;

/// Options of [`mesh`].
#[derive(Clone, Debug, PartialEq)]
pub struct MeshOptions {
    /// Smallest angle of domain triangles, in degrees (0 for none).
    pub min_angle_deg: f64,
    /// Largest area of domain triangles (regions may set their own).
    pub max_area: Option<f64>,
    /// Refinement stops with an error beyond this many vertices.
    pub max_vertices: usize,
}

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions {
            min_angle_deg: 30.0,
            max_area: None,
            max_vertices: 10_000_000,
        }
    }
}

/// A triangle mesh of the domain of a PSLG.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Every vertex of the triangulation (input points first, in input order).
    pub points: Vec<glam::DVec2>,
    /// Counter-clockwise domain triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Regional attribute of each triangle (0 outside every region seed's reach).
    pub triangle_attributes: Vec<f64>,
    /// Sub-segments of the input segments, each an edge of the triangulation.
    pub segments: Vec<[u32; 2]>,
    /// The input segment each sub-segment comes from.
    pub segment_origins: Vec<u32>,
    /// Refinement points inserted.
    pub insertions: usize,
}

impl Mesh {
    /// The smallest angle of any triangle, in degrees (infinite without triangles).
    pub fn smallest_angle_deg(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.points[i as usize]);
                super::quality::min_angle_deg(a, b, c)
            })
            .fold(f64::INFINITY, f64::min)
    }
}

/// Why [`mesh`] failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum MeshError {
    #[error("invalid input")]
    Invalid(#[from] PslgError),
    #[error("invalid option: {0}")]
    Option(String),
    #[error(transparent)]
    Refine(#[from] RefineError),
    #[error("triangulation failed")]
    Triangulation(#[from] TriangulationError),
}

/// Meshes the domain of `pslg` with the quality bounds of `options`.
pub fn mesh(pslg: &Pslg, options: &MeshOptions) -> Result<Mesh, MeshError> {
    if !(0.0..=MAX_MIN_ANGLE_DEG).contains(&options.min_angle_deg) {
        return Err(MeshError::Option(format!(
            "min-angle {}° is outside [0°, {MAX_MIN_ANGLE_DEG}°]",
            options.min_angle_deg
        )));
    }
    if options.max_area.is_some_and(|a| a.is_nan() || a <= 0.0) {
        return Err(MeshError::Option("max-area must be positive".into()));
    }
    pslg.validate()?;
    if pslg.points.len() > options.max_vertices {
        return Err(RefineError::TooManyVertices {
            limit: options.max_vertices,
        }
        .into());
    }
    let (mut tr, outcomes) = Delaunay2::from_points(&pslg.points)?;
    let vid: Vec<VertexId> = outcomes.iter().map(|o| o.vertex()).collect();
    let segments = pslg
        .segments
        .iter()
        .map(|&[a, b]| [vid[a as usize], vid[b as usize]])
        .collect();
    let cons = Rc::new(RefCell::new(Constraints::new(tr.num_vertices(), segments)));
    let diag = pslg.bounds().map_or(1.0, |(lo, hi)| lo.distance(hi));
    let mut seg_level = SegmentLevel::new(cons.clone(), diag * 1e-12);

    // Phase 1: recover the segments, so that the domain can be carved along them.
    let limits = Limits {
        max_vertices: options.max_vertices,
        ..Limits::default()
    };
    let mut insertions: usize = Engine::new(limits.clone())
        .push_level(&mut seg_level)
        .refine(&mut tr, &mut |_| {})?
        .insertions
        .iter()
        .sum();
    let labels = carve(&tr, &cons.borrow(), pslg);
    set_side_labels(&tr, &mut cons.borrow_mut(), &labels);
    check_reachable(&tr, &labels, pslg, options)?;

    // Phase 2: quality refinement.
    seg_level.encroachment = Some(Encroachment::new(options.min_angle_deg));
    let global_area = options.max_area.unwrap_or(f64::INFINITY);
    let region_area = std::iter::once(global_area)
        .chain(
            pslg.regions
                .iter()
                .map(|r| r.max_area.unwrap_or(global_area)),
        )
        .collect();
    let criteria = TriangleCriteria::new(options.min_angle_deg, region_area);
    let mut tri_level = TriangleLevel::new(cons.clone(), criteria, labels);
    insertions += Engine::new(limits)
        .push_level(&mut seg_level)
        .push_level(&mut tri_level)
        .refine(&mut tr, &mut |_| {})?
        .insertions
        .iter()
        .sum::<usize>();
    tri_level.resolve_labels(&tr);

    let attributes: Vec<f64> = std::iter::once(0.0)
        .chain(pslg.regions.iter().map(|r| r.attribute))
        .collect();
    let mut out = Mesh {
        insertions,
        ..Mesh::default()
    };
    out.points = tr.vertices().map(|v| tr.point(v)).collect();
    // Input points keep their input index: reorder so that vertex `vid[i]` becomes point `i`.
    let mut index: Vec<u32> = (0..out.points.len() as u32).collect();
    let mut order: Vec<usize> = vid.iter().map(|v| v.0 as usize).collect();
    let mut is_input = vec![false; out.points.len()];
    for &v in &order {
        is_input[v] = true;
    }
    order.extend((0..out.points.len()).filter(|&v| !is_input[v]));
    for (new, &old) in order.iter().enumerate() {
        index[old] = new as u32;
    }
    out.points = order.iter().map(|&old| out.points[old]).collect();
    for c in tr.finite_cells() {
        if let Label::Region(r) = tri_level.label(c) {
            out.triangles.push(tr.cell(c).map(|v| index[v.0 as usize]));
            out.triangle_attributes.push(attributes[r as usize]);
        }
    }
    for s in cons.borrow().sorted() {
        out.segments
            .push([index[s.a.0 as usize], index[s.b.0 as usize]]);
        out.segment_origins.push(s.origin);
    }
    Ok(out)
}

/// Labels every cell: the outside (reachable from the infinite cells without crossing a
/// sub-segment) and holes are `Outside`, region seeds flood their region, the rest of the domain is
/// region 0. Requires every sub-segment to be an edge.
/// Refuses, before any quality refinement, a carved domain that is empty (holes covering it all)
/// or whose area bounds cannot be met within `max_vertices`: a domain of area `A` under an area
/// bound `a` needs at least `A / a` triangles, about twice as many as vertices.
fn check_reachable(
    tr: &Delaunay2,
    labels: &[Label],
    pslg: &Pslg,
    options: &MeshOptions,
) -> Result<(), MeshError> {
    let global = options.max_area.unwrap_or(f64::INFINITY);
    let mut inside = false;
    let mut needed = 0.0;
    for c in tr.finite_cells() {
        let Label::Region(r) = labels[c.0 as usize] else {
            continue;
        };
        inside = true;
        let bound = match r {
            0 => global,
            k => pslg
                .regions
                .get(k as usize - 1)
                .and_then(|g| g.max_area)
                .unwrap_or(global),
        };
        let [a, b, c] = tr.cell(c).map(|v| tr.point(v));
        needed += 0.5 * (b - a).perp_dot(c - a).abs() / bound;
    }
    if !inside {
        return Err(MeshError::Option(
            "the holes leave no domain to mesh (is every --hole point inside a hole?)".into(),
        ));
    }
    if needed > 2.0 * options.max_vertices as f64 {
        return Err(MeshError::Option(format!(
            "the area bounds (max-area) need about {needed:.3e} triangles, more than \
             max-vertices {} can make",
            options.max_vertices
        )));
    }
    Ok(())
}

fn carve(tr: &Delaunay2, cons: &Constraints, pslg: &Pslg) -> Vec<Label> {
    let mut labels = vec![Label::Unknown; tr.cell_capacity()];
    let flood = |labels: &mut Vec<Label>, start: CellId, label: Label| {
        if labels[start.0 as usize] != Label::Unknown {
            return;
        }
        labels[start.0 as usize] = label;
        let mut stack = vec![start];
        while let Some(c) = stack.pop() {
            let v = tr.cell(c);
            for i in 0..3 {
                let n = tr.neighbor(c, i);
                if labels[n.0 as usize] == Label::Unknown
                    && cons.get(v[(i + 1) % 3], v[(i + 2) % 3]).is_none()
                {
                    labels[n.0 as usize] = label;
                    stack.push(n);
                }
            }
        }
    };
    let infinite: Vec<CellId> = tr.cells().filter(|&c| tr.is_infinite_cell(c)).collect();
    for c in infinite {
        flood(&mut labels, c, Label::Outside);
    }
    for &h in &pslg.holes {
        if let Some(c) = tr.locate(h, None).filter(|&c| !tr.is_infinite_cell(c)) {
            flood(&mut labels, c, Label::Outside);
        }
    }
    for (k, r) in pslg.regions.iter().enumerate() {
        if let Some(c) = tr
            .locate(r.point, None)
            .filter(|&c| !tr.is_infinite_cell(c))
        {
            flood(&mut labels, c, Label::Region(k as u32 + 1));
        }
    }
    let rest: Vec<CellId> = tr.finite_cells().collect();
    for c in rest {
        flood(&mut labels, c, Label::Region(0));
    }
    labels
}

/// Records on each sub-segment the labels of the cells on its two sides.
fn set_side_labels(tr: &Delaunay2, cons: &mut Constraints, labels: &[Label]) {
    for s in cons.sorted() {
        let side = |x, y| {
            tr.edge_cell(x, y)
                .map_or(Label::Outside, |(c, _)| labels[c.0 as usize])
        };
        let left = side(s.a, s.b);
        let right = side(s.b, s.a);
        if let Some(sub) = cons.get_mut(s.a, s.b) {
            sub.left = left;
            sub.right = right;
        }
    }
}

#[cfg(test)]
mod tests;
