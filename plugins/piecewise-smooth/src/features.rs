//! Sharp features of a triangle surface: feature edges, chained into curves between corners, and
//! the patches they cut the surface into.

use crate::chain::{Chain, chain};
use crate::edges::EdgeIncidence;
use crate::polylines::Polyline;
use delamesh_core::mesh::{MeshError, SurfaceMesh, weld_exact};
use delamesh_core::oracle::{CurveId, FeatureCurve, PatchId};
use delamesh_core::union_find::UnionFind;
use glam::DVec3;
use std::collections::BTreeMap;

/// CGAL's `detect_features` default: edges whose triangles' normals differ by more than 60°.
pub const DEFAULT_FEATURE_ANGLE_DEG: f64 = 60.0;

/// User polyline points snap to surface vertices this close, relative to the bounding-box diagonal.
pub const SNAP_TOLERANCE: f64 = 1e-6;

/// How features are detected.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeatureOptions {
    /// An edge is sharp when the normals of its two triangles differ by more than this (degrees);
    /// a curve has a corner where it turns by more than this.
    pub angle_deg: f64,
}

impl Default for FeatureOptions {
    fn default() -> Self {
        FeatureOptions {
            angle_deg: DEFAULT_FEATURE_ANGLE_DEG,
        }
    }
}

/// Why features cannot be extracted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum FeatureError {
    #[error("the feature angle must be between 0 and 180 degrees, got {0}")]
    Angle(f64),
    #[error(transparent)]
    Surface(#[from] MeshError),
    #[error(
        "polyline of line {line}: point {point} ({x} {y} {z}) is not a vertex of the surface \
         (user polylines must follow edges of the surface)"
    )]
    PolylineOffSurface {
        line: usize,
        point: usize,
        x: f64,
        y: f64,
        z: f64,
    },
    #[error(
        "polyline of line {line}: segment {segment} does not follow edges of the surface \
         (user polylines must follow edges of the surface)"
    )]
    PolylineOffEdges { line: usize, segment: usize },
}

/// A feature curve: a polyline along surface edges, between two corners or closed.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// The curve's label, numbered from 1.
    pub id: CurveId,
    /// Indices into [`Features::positions`]; a closed curve does not repeat its first vertex.
    pub vertices: Vec<u32>,
    /// The input coordinates of `vertices`, bit for bit.
    pub points: Vec<DVec3>,
    /// The last point joins the first. A closed curve through a corner starts at that corner.
    pub closed: bool,
    /// The patches on either side (one for a border, more at a non-manifold edge), sorted.
    pub patches: Vec<PatchId>,
}

impl Curve {
    /// Arc length at each point (0 at the first); a closed curve has one more entry, its length.
    pub fn arc_lengths(&self) -> Vec<f64> {
        let mut s = vec![0.0];
        let closing = self
            .closed
            .then(|| [self.points.last(), self.points.first()]);
        let pairs = self
            .points
            .windows(2)
            .map(|w| [Some(&w[0]), Some(&w[1])])
            .chain(closing);
        for [a, b] in pairs {
            if let (Some(a), Some(b)) = (a, b) {
                s.push(s[s.len() - 1] + a.distance(*b));
            }
        }
        s
    }

    /// Total length (including the closing segment of a closed curve).
    pub fn length(&self) -> f64 {
        self.arc_lengths().last().copied().unwrap_or(0.0)
    }

    /// The point at arc length `s` from the first point, clamped to the curve (wrapped around
    /// for a closed curve). Vertices are returned exactly.
    pub fn point_at(&self, s: f64) -> DVec3 {
        let lengths = self.arc_lengths();
        let total = lengths.last().copied().unwrap_or(0.0);
        let Some(&first) = self.points.first() else {
            return DVec3::ZERO;
        };
        if total <= 0.0 || !s.is_finite() {
            return first;
        }
        let s = if self.closed {
            s.rem_euclid(total)
        } else {
            s.clamp(0.0, total)
        };
        let i = lengths
            .partition_point(|&l| l <= s)
            .clamp(1, lengths.len() - 1);
        let a = self.points[i - 1];
        let b = self.points[i % self.points.len()];
        let span = lengths[i] - lengths[i - 1];
        if s <= lengths[i - 1] || span <= 0.0 {
            return a;
        }
        if s >= lengths[i] {
            return b;
        }
        a + (s - lengths[i - 1]) / span * (b - a)
    }
}

/// A vertex the mesh must contain: where other than two feature edges meet, where a curve turns
/// sharply, or at an end of a user polyline.
#[derive(Clone, Debug, PartialEq)]
pub struct Corner {
    /// Index into [`Features::positions`].
    pub vertex: u32,
    /// The input coordinates, bit for bit.
    pub point: DVec3,
    /// The curves ending here, sorted (a closed curve through the corner counts once).
    pub curves: Vec<CurveId>,
}

/// The sharp features of a surface and the patches they bound.
#[derive(Clone, Debug, PartialEq)]
pub struct Features {
    /// The surface's positions, welded by exact coordinates.
    pub positions: Vec<DVec3>,
    /// The surface's triangles over `positions`, in input order.
    pub triangles: Vec<[u32; 3]>,
    /// Patch of each input triangle, numbered from 1: connected regions across non-feature edges,
    /// numbered in order of their first triangle. Both copies of a shared face get one patch.
    pub triangle_patches: Vec<PatchId>,
    /// The number of patches.
    pub num_patches: u32,
    /// Numbered from 1, in order of their first corner (then loops by smallest vertex).
    pub curves: Vec<Curve>,
    /// Sorted by vertex.
    pub corners: Vec<Corner>,
    /// Pairs of input triangles with the same vertices in opposite orientations: a face shared
    /// by two closed components (an interface between two subdomains).
    pub shared_faces: Vec<[u32; 2]>,
}

impl Features {
    /// Detects the features of `surface`, adding the user `polylines` (which must follow surface
    /// edges: their points snap to vertices within [`SNAP_TOLERANCE`] × the bounding-box
    /// diagonal, and a segment may run along several collinear edges).
    ///
    /// Feature edges: edges whose two triangles' normals differ by more than the feature angle,
    /// border edges, non-manifold edges (three triangles or more, a shared face counting once),
    /// edges between different input patches, and edges of user polylines.
    pub fn extract(
        surface: &SurfaceMesh,
        options: &FeatureOptions,
        polylines: &[Polyline],
    ) -> Result<Features, FeatureError> {
        let angle = options.angle_deg;
        if !(0.0..=180.0).contains(&angle) {
            return Err(FeatureError::Angle(angle));
        }
        surface.validate()?;
        let mut positions = surface.positions.clone();
        let mut triangles = surface.triangles.clone();
        weld_exact(&mut positions, &mut triangles);

        let shared_faces = shared_faces(&triangles);
        // The second copy of a shared face plays no part in features and patches.
        let mut copy_of: Vec<Option<u32>> = vec![None; triangles.len()];
        for &[a, b] in &shared_faces {
            copy_of[b as usize] = Some(a);
        }
        let incidence = EdgeIncidence::new(&triangles, |t| copy_of[t].is_none());
        let normal = |t: u32| {
            let [a, b, c] = triangles[t as usize].map(|v| positions[v as usize]);
            (b - a).cross(c - a)
        };
        let mut is_feature: Vec<bool> = (0..incidence.edges.len())
            .map(|e| match incidence.uses(e) {
                [u, w] => {
                    let (nu, nw) = (normal(u.triangle), normal(w.triangle));
                    // Consistently oriented neighbours run through the edge in opposite directions.
                    let nw = if u.forward == w.forward { -nw } else { nw };
                    let between = nu.cross(nw).length().atan2(nu.dot(nw)).to_degrees();
                    surface.patches[u.triangle as usize] != surface.patches[w.triangle as usize]
                        || between > angle
                }
                _ => true,
            })
            .collect();
        let forced = mark_polylines(&positions, &incidence, polylines, &mut is_feature)?;

        let (triangle_patches, num_patches) =
            patches(&triangles, &incidence, &is_feature, &copy_of);
        let feature_edges: Vec<[u32; 2]> = incidence
            .edges
            .iter()
            .zip(&is_feature)
            .filter(|(_, f)| **f)
            .map(|(e, _)| *e)
            .collect();
        let chains = chain(&positions, &feature_edges, &forced, angle);

        let curves = curves_of(chains.curves, &positions, &incidence, &triangle_patches);
        let corners = corners_of(&chains.corners, &positions, &curves);
        Ok(Features {
            positions,
            triangles,
            triangle_patches,
            num_patches,
            curves,
            corners,
            shared_faces,
        })
    }

    /// The curves as the `Oracle` trait gives them.
    pub fn feature_curves(&self) -> Vec<FeatureCurve> {
        self.curves
            .iter()
            .map(|c| FeatureCurve {
                id: c.id,
                points: c.points.clone(),
                closed: c.closed,
            })
            .collect()
    }

    /// No feature curve: the surface is smooth at this feature angle.
    pub fn is_smooth(&self) -> bool {
        self.curves.is_empty()
    }
}

/// The curves of `chains`, numbered from 1, each with the patches along it.
fn curves_of(
    chains: Vec<Chain>,
    positions: &[DVec3],
    incidence: &EdgeIncidence,
    triangle_patches: &[PatchId],
) -> Vec<Curve> {
    chains
        .into_iter()
        .enumerate()
        .map(|(i, c)| {
            let n = c.vertices.len();
            let segments = if c.closed { n } else { n - 1 };
            let mut patches: Vec<PatchId> = (0..segments)
                .filter_map(|k| incidence.find(c.vertices[k], c.vertices[(k + 1) % n]))
                .flat_map(|e| incidence.uses(e))
                .map(|u| triangle_patches[u.triangle as usize])
                .collect();
            patches.sort_unstable();
            patches.dedup();
            Curve {
                id: CurveId(i as u32 + 1),
                points: c.vertices.iter().map(|&v| positions[v as usize]).collect(),
                vertices: c.vertices,
                closed: c.closed,
                patches,
            }
        })
        .collect()
}

/// The corners at `vertices` (sorted), each with the curves that end there.
fn corners_of(vertices: &[u32], positions: &[DVec3], curves: &[Curve]) -> Vec<Corner> {
    let mut corners: Vec<Corner> = vertices
        .iter()
        .map(|&v| Corner {
            vertex: v,
            point: positions[v as usize],
            curves: Vec::new(),
        })
        .collect();
    for c in curves {
        let ends = [c.vertices.first(), c.vertices.last()];
        for v in ends.into_iter().flatten() {
            if let Ok(k) = corners.binary_search_by_key(v, |k| k.vertex) {
                corners[k].curves.push(c.id);
            }
        }
    }
    for k in &mut corners {
        k.curves.dedup();
    }
    corners
}

/// Pairs `[first, second]` of triangles with the same three vertices in opposite orientations,
/// sorted. Three copies or more, or copies with the same orientation, are left alone (they are
/// defects the polyhedral oracle reports).
fn shared_faces(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut keyed: Vec<([u32; 3], u32)> = triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            let mut k = *tri;
            k.sort_unstable();
            (k, t as u32)
        })
        .collect();
    keyed.sort_unstable();
    keyed
        .chunk_by(|x, y| x.0 == y.0)
        .filter_map(|run| match *run {
            [(_, a), (_, b)] => {
                let [x, y, z] = triangles[a as usize];
                let reversed = [[x, z, y], [z, y, x], [y, x, z]];
                reversed.contains(&triangles[b as usize]).then_some([a, b])
            }
            _ => None,
        })
        .collect()
}

/// Marks the edges of the user polylines as features; returns the vertices at the ends of open
/// polylines, which become corners.
fn mark_polylines(
    positions: &[DVec3],
    incidence: &EdgeIncidence,
    polylines: &[Polyline],
    is_feature: &mut [bool],
) -> Result<Vec<u32>, FeatureError> {
    if polylines.is_empty() {
        return Ok(Vec::new());
    }
    let diagonal = delamesh_core::mesh::Aabb::of(positions).map_or(0.0, |b| b.diagonal());
    let tol = SNAP_TOLERANCE * diagonal;
    let key = |p: DVec3| {
        [
            (p.x + 0.0).to_bits(),
            (p.y + 0.0).to_bits(),
            (p.z + 0.0).to_bits(),
        ]
    };
    let exact: BTreeMap<[u64; 3], u32> = positions
        .iter()
        .enumerate()
        .rev()
        .map(|(v, &p)| (key(p), v as u32))
        .collect();
    let (offsets, adj) = incidence.neighbours(positions.len());
    let mut forced = Vec::new();
    for pl in polylines {
        let snapped = pl
            .points
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                exact
                    .get(&key(p))
                    .copied()
                    .or_else(|| nearest_within(positions, p, tol))
                    .ok_or(FeatureError::PolylineOffSurface {
                        line: pl.line,
                        point: i + 1,
                        x: p.x,
                        y: p.y,
                        z: p.z,
                    })
            })
            .collect::<Result<Vec<u32>, _>>()?;
        for (s, w) in snapped.windows(2).enumerate() {
            let path = straight_path(positions, &offsets, &adj, w[0], w[1], tol).ok_or(
                FeatureError::PolylineOffEdges {
                    line: pl.line,
                    segment: s + 1,
                },
            )?;
            for e in path.windows(2).filter_map(|p| incidence.find(p[0], p[1])) {
                is_feature[e] = true;
            }
        }
        if let (Some(&first), Some(&last)) = (snapped.first(), snapped.last())
            && first != last
        {
            forced.extend([first, last]);
        }
    }
    forced.sort_unstable();
    forced.dedup();
    Ok(forced)
}

fn nearest_within(positions: &[DVec3], p: DVec3, tol: f64) -> Option<u32> {
    positions
        .iter()
        .enumerate()
        .map(|(v, q)| (q.distance(p), v as u32))
        .filter(|(d, _)| *d <= tol)
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
        .map(|(_, v)| v)
}

/// Vertices from `a` to `b` along surface edges lying on the segment `[a, b]` (within `tol`),
/// each step going as far along the segment as an edge allows (straight to `b` when they are
/// neighbours).
fn straight_path(
    positions: &[DVec3],
    offsets: &[usize],
    adj: &[u32],
    a: u32,
    b: u32,
    tol: f64,
) -> Option<Vec<u32>> {
    let (pa, pb) = (positions[a as usize], positions[b as usize]);
    let d = pb - pa;
    let len2 = d.length_squared();
    if a == b || len2 == 0.0 {
        return None;
    }
    let along = |v: u32| (positions[v as usize] - pa).dot(d) / len2;
    let off_line = |v: u32| {
        let q = positions[v as usize];
        (q - (pa + along(v).clamp(0.0, 1.0) * d)).length()
    };
    let mut path = vec![a];
    let mut cur = a;
    while cur != b {
        let here = along(cur);
        let next = adj[offsets[cur as usize]..offsets[cur as usize + 1]]
            .iter()
            .copied()
            .filter(|&w| w == b || (along(w) > here && along(w) < 1.0 && off_line(w) <= tol))
            .max_by(|&x, &y| along(x).total_cmp(&along(y)).then(y.cmp(&x)))?;
        path.push(next);
        cur = next;
    }
    Some(path)
}

/// Connected regions of triangles across non-feature edges, numbered from 1 in order of their first
/// triangle; the second copy of a shared face (`copy_of`) takes the patch of the first.
fn patches(
    triangles: &[[u32; 3]],
    incidence: &EdgeIncidence,
    is_feature: &[bool],
    copy_of: &[Option<u32>],
) -> (Vec<PatchId>, u32) {
    let mut sets = UnionFind::new(triangles.len());
    for (e, feature) in is_feature.iter().enumerate() {
        if let (false, [u, w]) = (feature, incidence.uses(e)) {
            sets.union(u.triangle, w.triangle);
        }
    }
    let mut label = vec![PatchId(0); triangles.len()];
    let mut next = 0;
    for t in 0..triangles.len() {
        if copy_of[t].is_some() {
            continue;
        }
        let root = sets.find(t as u32) as usize;
        if label[root] == PatchId(0) {
            next += 1;
            label[root] = PatchId(next);
        }
        label[t] = label[root];
    }
    for t in 0..triangles.len() {
        if let Some(original) = copy_of[t] {
            label[t] = label[original as usize];
        }
    }
    (label, next)
}
