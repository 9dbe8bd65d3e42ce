//! A background tetrahedral mesh with a size at every node.

use super::{SizingError, SizingField, check_value, show};
use crate::kernel::Point3;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{AABB, RTree};

type TetBox = GeomWithData<Rectangle<[f64; 3]>, u32>;
type Node = GeomWithData<[f64; 3], u32>;

/// Barycentric coordinates may be this much below zero (relative) and still count as inside:
/// points on a shared face belong to both tets, whichever is found first.
const INSIDE_TOLERANCE: f64 = 1e-9;

/// Sizes at the nodes of a tetrahedral mesh: linear interpolation in the tet containing the
/// point (found through an R*-tree of the tets' boxes), the nearest node's value outside every
/// tet. Flat tets are never "containing": their neighbours or the nearest node answer.
pub struct BackgroundMesh {
    positions: Vec<Point3>,
    tets: Vec<[u32; 4]>,
    values: Vec<f64>,
    cells: RTree<TetBox>,
    nodes: RTree<Node>,
    smallest: f64,
}

impl BackgroundMesh {
    /// A background mesh; refuses a value count other than the node count, a value that is not
    /// finite and positive (naming its node), a tet naming a missing node, and a mesh without
    /// tets.
    pub fn new(
        positions: Vec<Point3>,
        tets: Vec<[u32; 4]>,
        values: Vec<f64>,
    ) -> Result<BackgroundMesh, SizingError> {
        if values.len() != positions.len() {
            return Err(SizingError(format!(
                "{} values for {} nodes",
                values.len(),
                positions.len()
            )));
        }
        if tets.is_empty() {
            return Err(SizingError("no tetrahedra".into()));
        }
        for (n, &v) in values.iter().enumerate() {
            check_value(v, || format!("node {n} {}", show(positions[n])))?;
        }
        let mut boxes = Vec::with_capacity(tets.len());
        for (t, tet) in tets.iter().enumerate() {
            let mut corners = [Point3::ZERO; 4];
            for (c, &v) in corners.iter_mut().zip(tet) {
                *c = *positions.get(v as usize).ok_or_else(|| {
                    SizingError(format!(
                        "tetrahedron {t} names node {v}, there are {}",
                        positions.len()
                    ))
                })?;
            }
            let lo = corners.iter().fold(corners[0], |a, &b| a.min(b));
            let hi = corners.iter().fold(corners[0], |a, &b| a.max(b));
            let rect = Rectangle::from_corners(lo.to_array(), hi.to_array());
            boxes.push(GeomWithData::new(rect, t as u32));
        }
        let nodes = positions
            .iter()
            .enumerate()
            .map(|(n, p)| GeomWithData::new(p.to_array(), n as u32))
            .collect();
        let smallest = values.iter().copied().fold(f64::INFINITY, f64::min);
        Ok(BackgroundMesh {
            cells: RTree::bulk_load(boxes),
            nodes: RTree::bulk_load(nodes),
            positions,
            tets,
            values,
            smallest,
        })
    }

    /// The barycentric coordinates of `p` in tet `t`, if it contains `p`.
    fn barycentric(&self, t: u32, p: Point3) -> Option<[f64; 4]> {
        let [a, b, c, d] = self.tets[t as usize].map(|v| self.positions[v as usize]);
        let volume = |a: Point3, b: Point3, c: Point3, d: Point3| (b - a).dot((c - a).cross(d - a));
        let total = volume(a, b, c, d);
        if total == 0.0 || !total.is_finite() {
            return None;
        }
        let l = [
            volume(p, b, c, d) / total,
            volume(a, p, c, d) / total,
            volume(a, b, p, d) / total,
            volume(a, b, c, p) / total,
        ];
        l.iter().all(|&x| x >= -INSIDE_TOLERANCE).then_some(l)
    }

    /// The containing tet and the coordinates of `p` in it.
    fn locate(&self, p: Point3) -> Option<(u32, [f64; 4])> {
        let q = AABB::from_point(p.to_array());
        self.cells
            .locate_in_envelope_intersecting(q)
            .find_map(|b| self.barycentric(b.data, p).map(|l| (b.data, l)))
    }

    /// Whether some tet contains `p`.
    pub fn covers(&self, p: Point3) -> bool {
        self.locate(p).is_some()
    }

    /// The distance from `p` to the nearest tet's bounding box (0 inside
    /// one), a cheap lower bound of the distance to the mesh for the check that it covers a
    /// domain up to the gap between a curved surface and its chords.
    pub fn box_distance(&self, p: Point3) -> f64 {
        use rstar::PointDistance;
        self.cells
            .nearest_neighbor(p.to_array())
            .map_or(f64::INFINITY, |b| b.geom().distance_2(&p.to_array()).sqrt())
    }

    /// The value at `p` (see the type's documentation).
    pub fn at(&self, p: Point3) -> f64 {
        if let Some((t, l)) = self.locate(p) {
            let tet = self.tets[t as usize];
            return (0..4).map(|k| l[k] * self.values[tet[k] as usize]).sum();
        }
        match self.nodes.nearest_neighbor(p.to_array()) {
            Some(n) => self.values[n.data as usize],
            None => self.smallest,
        }
    }
}

impl SizingField for BackgroundMesh {
    fn size_at(&self, p: Point3, _label: u32) -> f64 {
        self.at(p)
    }
    fn smallest(&self) -> Option<f64> {
        Some(self.smallest)
    }
}
