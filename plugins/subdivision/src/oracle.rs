//! `SubdivisionOracle`: the domain bounded by the limit surface of a closed control mesh.

use crate::bezier::{Bezier, reference_corners};
use crate::control::ControlMesh;
use crate::crease::{CreasePiece, nearest};
use crate::intersect::{Crossing, NEWTON_DEPTH, Query, crossings};
use crate::net::Net;
use crate::patch::{Patch, Surface};
use crate::{Scheme, SubdivisionError, SubdivisionOptions};
use delamesh_core::mesh::component_euler_characteristics;
use delamesh_core::oracle::{
    Aabb, CurveId, FeatureCurve, OUTSIDE, Oracle, PatchId, SubdomainId, SurfaceHit, SurfacePoint,
};
use delamesh_formats::PolygonMesh;
use delamesh_piecewise_smooth::{Polyline, chain};
use delamesh_polyhedral::{Occupancy, TriangleTree};
use glam::{DVec2, DVec3};

/// Points along a crease curve: bisected until the chord is within this × the diagonal of the
/// curve (at most [`CURVE_LEVELS`] times per control half-edge).
const CURVE_TOLERANCE: f64 = 1e-7;
const CURVE_LEVELS: u32 = 10;
/// A point is projected onto the crease borders whose samples come within this × the diagonal
/// of the nearest sample: more than the samples' chords leave the curve by.
const CREASE_SLACK: f64 = 1e-5;
/// The projection onto a crease stops when a step moves the point by this × the diagonal.
const CREASE_TOLERANCE: f64 = 1e-13;
/// The most initial points handed to the mesher.
const MAX_INITIAL_POINTS: usize = 4096;
/// Steps of subdivision applied ahead to irregular patches for the queries.
const PRESPLIT: u32 = 3;

/// The domain inside the limit surface of a Loop or Catmull–Clark control mesh.
pub struct SubdivisionOracle {
    scheme: Scheme,
    patches: Vec<Patch>,
    /// What segment queries search: the patches, irregular ones split [`PRESPLIT`] times ahead
    /// (their rings' boxes are loose), then every regular piece [`NEWTON_DEPTH`] times (queries
    /// split them that often before Newton's method, and the tree prunes by the smaller boxes).
    pieces: Vec<Patch>,
    /// The box of each piece.
    bounds: Vec<(DVec3, DVec3)>,
    /// Over the pieces' boxes, each given as the degenerate triangle `(lo, hi, hi)`.
    tree: TriangleTree,
    /// The cells no piece's box reaches lie in one subdomain each: found once by ray parity,
    /// then read (most cells' circumcentres are far from the surface); a point near the surface
    /// is compared with such cells through short segments.
    occupancy: Occupancy,
    bbox: Aabb,
    initial: Vec<SurfacePoint>,
    curves: Vec<FeatureCurve>,
    /// The patch borders each curve is made of (by curve), for the exact projection.
    creases: Vec<(CurveId, Vec<CreasePiece>)>,
    corners: Vec<DVec3>,
    /// Euler characteristic of each connected component of the control mesh.
    euler: Vec<i64>,
    /// The control mesh once subdivided (Catmull–Clark), or as given (Loop): one patch per face.
    base: Net,
}

impl SubdivisionOracle {
    /// The oracle of a control mesh; `polylines` are more creases along control edges.
    pub fn new(
        mesh: &PolygonMesh,
        options: &SubdivisionOptions,
        polylines: &[Polyline],
    ) -> Result<Self, SubdivisionError> {
        let control = ControlMesh::new(mesh, options, polylines)?;
        let scheme = control.scheme;
        // Catmull–Clark patches are quads: one step first turns every face into quads.
        let (base, groups) = match scheme {
            Scheme::CatmullClark => {
                let groups = (0..control.net.face_count())
                    .flat_map(|f| std::iter::repeat_n(control.groups[f], control.net.face(f).len()))
                    .collect();
                (control.net.subdivide(scheme), groups)
            }
            Scheme::Loop => (control.net.clone(), control.groups.clone()),
        };
        let (offsets, faces) = base.vertex_faces();
        let mut patches = Vec::with_capacity(base.face_count());
        let mut around = Vec::new();
        for (f, &group) in groups.iter().enumerate() {
            around.clear();
            for &v in base.face(f) {
                around.extend_from_slice(
                    &faces[offsets[v as usize] as usize..offsets[v as usize + 1] as usize],
                );
            }
            around.sort_unstable();
            around.dedup();
            let others: Vec<usize> = around
                .iter()
                .map(|&g| g as usize)
                .filter(|&g| g != f)
                .collect();
            let ring = base.ring_from(f, &others);
            patches.push(Patch {
                surface: Surface::of_ring(scheme, ring),
                group,
            });
        }
        let mut pieces = Vec::with_capacity(patches.len());
        for p in &patches {
            presplit(scheme, p.surface.clone(), p.group, PRESPLIT, &mut pieces);
        }
        let bounds: Vec<(DVec3, DVec3)> = pieces.iter().map(|p| p.surface.bounds()).collect();
        let boxes: Vec<[DVec3; 3]> = bounds.iter().map(|&(lo, hi)| [lo, hi, hi]).collect();
        // The pieces' boxes hug the limit surface, which lies well inside the control mesh's
        // box (a Loop icosahedron's limit spans 18 % less): the defaults drawn from the box
        // must be those of the shape meshed.
        let (lo, hi) = boxes.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), b| (lo.min(b[0]), hi.max(b[1])),
        );
        let bbox = Aabb { min: lo, max: hi };
        let occupancy = Occupancy::new(lo, hi, &boxes);
        let mut oracle = SubdivisionOracle {
            scheme,
            tree: TriangleTree::new(&boxes),
            occupancy,
            patches,
            pieces,
            bounds,
            bbox,
            initial: Vec::new(),
            curves: Vec::new(),
            creases: Vec::new(),
            corners: Vec::new(),
            euler: component_euler_characteristics(&mesh.triangulated().triangles).1,
            base,
        };
        oracle.initial = oracle.patch_centres();
        oracle.add_creases(&control);
        Ok(oracle)
    }

    /// Euler characteristic of each connected component of the control mesh, which the limit
    /// surface shares.
    pub fn euler_characteristics(&self) -> &[i64] {
        &self.euler
    }

    /// The subdivision scheme in use.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }

    /// Number of patches (faces of the once-subdivided control mesh for Catmull–Clark, control
    /// triangles for Loop).
    pub fn patch_count(&self) -> usize {
        self.patches.len()
    }

    /// The exact limit position and unit normal of patch `patch` at `(u, v)` of its reference
    /// domain (unit square or triangle), if the patch exists. Patches are the faces of the base
    /// mesh: for Catmull–Clark the control mesh once subdivided, whose face `h` is the child of
    /// control corner `h` (corners numbered face after face), with corner 0 at the control
    /// vertex, corner 1 at the middle of the edge to the next vertex, corner 3 at the middle of
    /// the edge from the previous one; for Loop the control triangles, `u` towards the second
    /// corner and `v` towards the third.
    pub fn evaluate(&self, patch: usize, u: f64, v: f64) -> Option<(DVec3, DVec3)> {
        let e = self
            .patches
            .get(patch)?
            .surface
            .eval(self.scheme, DVec2::new(u, v));
        Some((e.point, e.du.cross(e.dv).normalize_or_zero()))
    }

    /// The base mesh (see [`SubdivisionOracle::evaluate`]) after `levels` more steps of
    /// subdivision (at most 8), its vertices moved to their limit positions, as a polygon
    /// mesh: a dense approximation with its vertices exactly on the surface (tests, and the
    /// comparison with meshing a subdivided mesh).
    pub fn subdivided(&self, levels: u32) -> PolygonMesh {
        let mut net = self.base.clone();
        for _ in 0..levels.min(8) {
            net = net.subdivide(self.scheme);
        }
        let faces: Vec<Vec<u32>> = (0..net.face_count())
            .map(|f| net.face(f).to_vec())
            .collect();
        PolygonMesh {
            positions: net.limit_positions(self.scheme),
            groups: vec![Default::default(); faces.len()],
            faces,
            group_names: vec!["surface".into()],
        }
    }

    fn patch_centres(&self) -> Vec<SurfacePoint> {
        let centre = match self.scheme {
            Scheme::CatmullClark => DVec2::splat(0.5),
            Scheme::Loop => DVec2::splat(1.0 / 3.0),
        };
        let stride = self.patches.len().div_ceil(MAX_INITIAL_POINTS).max(1);
        self.patches
            .iter()
            .step_by(stride)
            .map(|p| SurfacePoint {
                point: p.surface.eval(self.scheme, centre).point,
                patch: PatchId(p.group),
            })
            .collect()
    }

    /// Creases: chained between corners; each control half-edge's limit curve is the border of
    /// one or two base patches.
    fn add_creases(&mut self, control: &ControlMesh) {
        if control.creases.is_empty() {
            return;
        }
        let chains = chain(&control.net.points, &control.creases, &[], 180.0);
        let half_of = |a: u32, b: u32| -> Option<(usize, bool)> {
            (0..control.net.face_count()).find_map(|f| {
                control.net.halves(f).find_map(|h| {
                    let (p, q) = (
                        control.net.corners[h],
                        control.net.corners[control.net.next(f, h)],
                    );
                    if (p, q) == (a, b) {
                        Some((h, false))
                    } else if (p, q) == (b, a) {
                        Some((h, true))
                    } else {
                        None
                    }
                })
            })
        };
        let diagonal = self.bbox.diagonal();
        for (i, c) in chains.curves.iter().enumerate() {
            let mut points: Vec<DVec3> = Vec::new();
            let mut borders = Vec::new();
            let mut vertices = c.vertices.clone();
            if c.closed {
                vertices.push(c.vertices[0]);
            }
            for w in vertices.windows(2) {
                let Some((h, reversed)) = half_of(w[0], w[1]) else {
                    continue;
                };
                let pieces = self.half_edge_curve(control, h, diagonal);
                let mut along: Vec<DVec3> = Vec::new();
                for piece in &pieces {
                    along.extend(piece.points().skip(usize::from(!along.is_empty())));
                }
                if reversed {
                    along.reverse();
                }
                if !points.is_empty() {
                    along.remove(0);
                }
                points.extend(along);
                borders.extend(pieces);
            }
            if c.closed {
                points.pop();
            }
            if points.len() >= 2 {
                let id = CurveId(i as u32 + 1);
                self.curves.push(FeatureCurve {
                    id,
                    points,
                    closed: c.closed,
                });
                self.creases.push((id, borders));
            }
        }
        self.corners = chains
            .corners
            .iter()
            .map(|&v| self.limit_of_control_vertex(control, v))
            .collect();
    }

    /// The limit position of control vertex `v`: a corner of its base patches.
    fn limit_of_control_vertex(&self, control: &ControlMesh, v: u32) -> DVec3 {
        for f in 0..control.net.face_count() {
            for h in control.net.halves(f) {
                if control.net.corners[h] == v {
                    let (patch, corner) = self.patch_at_control_corner(control, f, h);
                    let p = reference_corners(self.scheme)[corner];
                    return self.patches[patch].surface.eval(self.scheme, p).point;
                }
            }
        }
        control.net.points[v as usize]
    }

    /// The base patch holding control corner slot `h` of face `f`, and which of its corners.
    fn patch_at_control_corner(&self, control: &ControlMesh, f: usize, h: usize) -> (usize, usize) {
        match self.scheme {
            Scheme::CatmullClark => (h, 0),
            Scheme::Loop => (f, h - control.net.halves(f).start),
        }
    }

    /// The limit curve of control half-edge `h` as patch borders sampled on the limit, from its
    /// first vertex to its second.
    fn half_edge_curve(&self, control: &ControlMesh, h: usize, diagonal: f64) -> Vec<CreasePiece> {
        let c = reference_corners(self.scheme);
        // Pieces (patch, parameter segment) in order along the edge.
        let pieces: Vec<(usize, DVec2, DVec2)> = match self.scheme {
            Scheme::CatmullClark => {
                let face_of = control.net.face_of_half();
                let next = control.net.next(face_of[h] as usize, h);
                vec![(h, c[0], c[1]), (next, c[3], c[0])]
            }
            Scheme::Loop => {
                let face_of = control.net.face_of_half();
                let f = face_of[h] as usize;
                let k = h - control.net.halves(f).start;
                vec![(f, c[k], c[(k + 1) % 3])]
            }
        };
        pieces
            .into_iter()
            .map(|(patch, from, to)| {
                let surface = &self.patches[patch].surface;
                let at = |s: f64| surface.eval(self.scheme, from + s * (to - from)).point;
                let mut samples = vec![(0.0, at(0.0))];
                bisect(
                    &at,
                    (0.0, at(0.0)),
                    (1.0, at(1.0)),
                    CURVE_TOLERANCE * diagonal,
                    CURVE_LEVELS,
                    &mut samples,
                );
                CreasePiece::new(patch, from, to, samples)
            })
            .collect()
    }

    fn hits(&self, a: DVec3, b: DVec3, out: &mut Vec<SurfaceHit>) {
        let q = Query {
            a,
            d: b - a,
            slack: 1e-12 * self.bbox.diagonal().max(1e-300),
            point_size: 1e-10 * self.bbox.diagonal(),
        };
        let mut found: Vec<(Crossing, u32)> = Vec::new();
        let mut buffer = Vec::new();
        self.occupancy.for_each_near_segment(&self.tree, a, b, |p| {
            let patch = &self.pieces[p as usize];
            buffer.clear();
            crossings(
                self.scheme,
                &patch.surface,
                self.bounds[p as usize],
                &q,
                &mut buffer,
            );
            found.extend(buffer.iter().map(|&c| (c, patch.group)));
        });
        found.sort_by(|x, y| x.0.t.total_cmp(&y.0.t).then(x.1.cmp(&y.1)));
        // Pieces sharing a border both find a crossing on it.
        let same = 1e-9 * self.bbox.diagonal();
        let start = out.len();
        for (c, group) in found {
            if out[start..]
                .last()
                .is_some_and(|h: &SurfaceHit| h.point.distance(c.point) <= same)
            {
                continue;
            }
            out.push(SurfaceHit {
                point: c.point.clamp(self.bbox.min, self.bbox.max),
                t: c.t,
                patch: PatchId(group),
            });
        }
    }

    /// Ray parity: crossings of rays out of the box along fixed directions (for the empty
    /// cells' centres, each asked once).
    fn subdomain_by_rays(&self, p: DVec3) -> SubdomainId {
        majority(|dir| self.parity(p, dir))
    }

    /// The side of a point near the surface, by the crossings of the segment from it to the
    /// first empty cell along each direction, whose side is known: a few pieces instead of a
    /// ray's.
    fn subdomain_near_surface(&self, p: DVec3) -> SubdomainId {
        majority(|dir| {
            match self
                .occupancy
                .first_empty_along(p, dir, |c| self.subdomain_by_rays(c))
            {
                Some((c, side)) => {
                    let mut hits = Vec::new();
                    self.hits(p, c, &mut hits);
                    (side != OUTSIDE) != (hits.len() % 2 == 1)
                }
                None => self.parity(p, dir),
            }
        })
    }

    /// Crossings of the segment from `p` out of the box in direction `dir`.
    fn parity(&self, p: DVec3, dir: DVec3) -> bool {
        let reach = 2.0 * (self.bbox.diagonal() + (p - self.bbox.center()).length());
        let mut hits = Vec::new();
        self.hits(p, p + reach * dir, &mut hits);
        hits.len() % 2 == 1
    }
}

/// Inside when two of three parity tests along fixed directions agree on it (a test grazing the
/// surface miscounts; two agreeing decide).
fn majority(inside: impl Fn(DVec3) -> bool) -> SubdomainId {
    // Off every symmetry axis of simple models, so that rays rarely meet a vertex.
    const DIRECTIONS: [DVec3; 3] = [
        DVec3::new(0.571, 0.583, 0.577),
        DVec3::new(-0.267, 0.802, -0.535),
        DVec3::new(0.816, -0.409, -0.407),
    ];
    let (first, second) = (inside(DIRECTIONS[0]), inside(DIRECTIONS[1]));
    let inside = if first == second {
        first
    } else {
        inside(DIRECTIONS[2])
    };
    if inside { SubdomainId(1) } else { OUTSIDE }
}

/// `surface` as pieces: its regular children, split `levels` times while irregular, regular
/// ones split [`NEWTON_DEPTH`] times.
fn presplit(scheme: Scheme, surface: Surface, group: u32, levels: u32, out: &mut Vec<Patch>) {
    match surface {
        Surface::Irregular(ring) if levels > 0 => {
            for (_, child) in ring.children(scheme) {
                presplit(scheme, child.clone(), group, levels - 1, out);
            }
        }
        Surface::Regular(b) => split_regular(b, group, NEWTON_DEPTH, out),
        surface => out.push(Patch { surface, group }),
    }
}

fn split_regular(b: Bezier, group: u32, levels: u32, out: &mut Vec<Patch>) {
    if levels == 0 {
        out.push(Patch {
            surface: Surface::Regular(b),
            group,
        });
        return;
    }
    for (_, child) in b.children() {
        split_regular(child, group, levels - 1, out);
    }
}

/// Adds the points of `at` on `(s0, s1]` to `out`, halving while the midpoint is farther than
/// `tol` from the chord (`levels` times at most, and at least twice).
fn bisect(
    at: &dyn Fn(f64) -> DVec3,
    (s0, p0): (f64, DVec3),
    (s1, p1): (f64, DVec3),
    tol: f64,
    levels: u32,
    out: &mut Vec<(f64, DVec3)>,
) {
    let sm = 0.5 * (s0 + s1);
    let pm = at(sm);
    let flat = pm.distance(0.5 * (p0 + p1)) <= tol;
    if levels == 0 || (flat && levels + 2 <= CURVE_LEVELS) {
        out.push((s1, p1));
        return;
    }
    bisect(at, (s0, p0), (sm, pm), tol, levels - 1, out);
    bisect(at, (sm, pm), (s1, p1), tol, levels - 1, out);
}

impl Oracle for SubdivisionOracle {
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }

    /// Read from the cell's known subdomain when no patch comes near the cell, else by the
    /// parity of short segments to such cells.
    fn subdomain(&self, p: DVec3) -> SubdomainId {
        self.occupancy.subdomain(
            p,
            |c| self.subdomain_by_rays(c),
            |p| self.subdomain_near_surface(p),
        )
    }

    fn segment_hits(&self, a: DVec3, b: DVec3, out: &mut Vec<SurfaceHit>) {
        self.hits(a, b, out);
    }

    fn ray_hits(&self, origin: DVec3, dir: DVec3, out: &mut Vec<SurfaceHit>) {
        let len = dir.length();
        if !(len > 0.0 && len.is_finite()) {
            return;
        }
        let reach = 2.0 * (self.bbox.diagonal() + (origin - self.bbox.center()).length()) / len;
        let start = out.len();
        self.hits(origin, origin + reach * dir, out);
        for h in &mut out[start..] {
            h.t *= reach;
        }
    }

    fn initial_points(&self) -> Vec<SurfacePoint> {
        self.initial.clone()
    }

    fn feature_curves(&self) -> Vec<FeatureCurve> {
        self.curves.clone()
    }

    /// The nearest point of the limit crease: Newton's method on the exact patch borders it
    /// is made of, from the nearest of their samples.
    fn project_to_curve(&self, curve: CurveId, p: DVec3) -> DVec3 {
        let Some((_, pieces)) = self.creases.iter().find(|(id, _)| *id == curve) else {
            return p;
        };
        let d = self.bbox.diagonal();
        nearest(
            self.scheme,
            &self.patches,
            pieces,
            p,
            CREASE_SLACK * d,
            CREASE_TOLERANCE * d,
        )
        .filter(|q| q.is_finite())
        .unwrap_or(p)
    }

    fn corners(&self) -> Vec<DVec3> {
        self.corners.clone()
    }
}
