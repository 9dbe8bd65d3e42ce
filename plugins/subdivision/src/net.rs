//! Polygon nets with sharp edges and one step of Catmull–Clark or Loop subdivision on them, with
//! the crease rules of Hoppe et al. (sharp edges split at their midpoint, a vertex on two sharp
//! edges moves along them, a vertex on more is a corner; one sharp edge, a dart, is smooth).
//!
//! The same code subdivides the whole control mesh and the small nets around one patch: a
//! vertex whose ring of faces is complete gets its exact rule, others (the border of a local
//! net) get a value nobody reads, since the ring of a face's children lies inside the
//! subdivided ring of the face.

use crate::Scheme;
use glam::DVec3;
use std::f64::consts::PI;

/// Faces of any size over shared points; `sharp[h]` says whether the edge from corner `h` to the
/// next corner of its face is a crease.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Net {
    pub points: Vec<DVec3>,
    /// Corners of every face, face after face.
    pub corners: Vec<u32>,
    /// Face `f` is `corners[starts[f]..starts[f + 1]]`.
    pub starts: Vec<u32>,
    /// One flag per corner (half-edge).
    pub sharp: Vec<bool>,
}

/// An undirected edge and its one or two half-edges.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Edge {
    pub a: u32,
    pub b: u32,
    pub halves: [u32; 2],
    /// 1 on the border of a net, 2 inside.
    pub count: u8,
    pub sharp: bool,
}

/// Half-edge → edge, and the edges.
pub(crate) struct Edges {
    pub of_half: Vec<u32>,
    pub list: Vec<Edge>,
}

impl Net {
    /// The faces around every vertex, as offsets into one list (sorted per vertex).
    pub fn vertex_faces(&self) -> (Vec<u32>, Vec<u32>) {
        let mut offsets = vec![0u32; self.points.len() + 1];
        for &v in &self.corners {
            offsets[v as usize + 1] += 1;
        }
        for i in 0..self.points.len() {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut faces = vec![0u32; self.corners.len()];
        for f in 0..self.face_count() {
            for &v in self.face(f) {
                faces[fill[v as usize] as usize] = f as u32;
                fill[v as usize] += 1;
            }
        }
        (offsets, faces)
    }

    pub fn face_count(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    pub fn face(&self, f: usize) -> &[u32] {
        &self.corners[self.starts[f] as usize..self.starts[f + 1] as usize]
    }

    /// Half-edges of face `f`, as a range of corner slots.
    pub fn halves(&self, f: usize) -> std::ops::Range<usize> {
        self.starts[f] as usize..self.starts[f + 1] as usize
    }

    /// The corner after slot `h` in its face.
    pub fn next(&self, f: usize, h: usize) -> usize {
        let r = self.halves(f);
        if h + 1 == r.end { r.start } else { h + 1 }
    }

    /// The corner before slot `h` in its face.
    pub fn prev(&self, f: usize, h: usize) -> usize {
        let r = self.halves(f);
        if h == r.start { r.end - 1 } else { h - 1 }
    }

    /// The face of every half-edge.
    pub fn face_of_half(&self) -> Vec<u32> {
        let mut out = vec![0; self.corners.len()];
        for f in 0..self.face_count() {
            for h in self.halves(f) {
                out[h] = f as u32;
            }
        }
        out
    }

    /// Pairs half-edges into edges (sorted, so deterministic). More than two half-edges on one
    /// edge are reported as the first extra half-edge found (the caller refuses such meshes).
    pub fn edges(&self) -> Result<Edges, u32> {
        let face_of = self.face_of_half();
        let mut keys: Vec<(u32, u32, u32)> = (0..self.corners.len())
            .map(|h| {
                let f = face_of[h] as usize;
                let (a, b) = (self.corners[h], self.corners[self.next(f, h)]);
                (a.min(b), a.max(b), h as u32)
            })
            .collect();
        keys.sort_unstable();
        let mut of_half = vec![0; self.corners.len()];
        let mut list: Vec<Edge> = Vec::with_capacity(keys.len() / 2 + 1);
        for &(a, b, h) in &keys {
            match list.last_mut() {
                Some(e) if e.a == a && e.b == b => {
                    if e.count == 2 {
                        return Err(h);
                    }
                    e.halves[1] = h;
                    e.count = 2;
                    e.sharp |= self.sharp[h as usize];
                }
                _ => list.push(Edge {
                    a,
                    b,
                    halves: [h, h],
                    count: 1,
                    sharp: self.sharp[h as usize],
                }),
            }
            of_half[h as usize] = list.len() as u32 - 1;
        }
        Ok(Edges { of_half, list })
    }

    /// One subdivision step. Loop nets must be made of triangles (the caller checks).
    pub fn subdivide(&self, scheme: Scheme) -> Net {
        let Ok(edges) = self.edges() else {
            // Callers only subdivide nets whose edges they checked; an empty net is harmless.
            return Net::default();
        };
        match scheme {
            Scheme::CatmullClark => self.catmull_clark(&edges),
            Scheme::Loop => self.loop_step(&edges),
        }
    }

    /// Per vertex: incident edge count, sharp (or border) neighbours (up to two are kept), and
    /// the sum of the other ends of its edges.
    fn vertex_stars(&self, edges: &Edges) -> Vec<Star> {
        let mut stars = vec![Star::default(); self.points.len()];
        for e in &edges.list {
            let crease = e.sharp || e.count == 1;
            for (v, w) in [(e.a, e.b), (e.b, e.a)] {
                let s = &mut stars[v as usize];
                s.valence += 1;
                s.neighbours += self.points[w as usize];
                if crease {
                    if s.creases < 2 {
                        s.crease_ends[s.creases as usize] = self.points[w as usize];
                    }
                    s.creases += 1;
                }
            }
        }
        stars
    }

    fn catmull_clark(&self, edges: &Edges) -> Net {
        let (nv, ne, nf) = (self.points.len(), edges.list.len(), self.face_count());
        let face_of = self.face_of_half();
        let face_points: Vec<DVec3> = (0..nf)
            .map(|f| {
                let c = self.face(f);
                c.iter().map(|&v| self.points[v as usize]).sum::<DVec3>() / c.len() as f64
            })
            .collect();
        let edge_points: Vec<DVec3> = edges
            .list
            .iter()
            .map(|e| {
                let mid = 0.5 * (self.points[e.a as usize] + self.points[e.b as usize]);
                if e.sharp || e.count == 1 {
                    mid
                } else {
                    let [f, g] = e.halves.map(|h| face_points[face_of[h as usize] as usize]);
                    0.5 * mid + 0.25 * (f + g)
                }
            })
            .collect();
        let stars = self.vertex_stars(edges);
        let mut face_sums = vec![(DVec3::ZERO, 0u32); nv];
        for (f, &fp) in face_points.iter().enumerate() {
            for &v in self.face(f) {
                face_sums[v as usize].0 += fp;
                face_sums[v as usize].1 += 1;
            }
        }
        let mut points = Vec::with_capacity(nv + ne + nf);
        for (v, s) in stars.iter().enumerate() {
            let p = self.points[v];
            points.push(match s.creases {
                0 | 1 if s.valence > 0 && face_sums[v].1 > 0 => {
                    let n = s.valence as f64;
                    let q = face_sums[v].0 / face_sums[v].1 as f64;
                    // Average of edge midpoints: (p + neighbour) / 2 each.
                    let r = 0.5 * (p + s.neighbours / n);
                    (q + 2.0 * r + (n - 3.0) * p) / n
                }
                2 => 0.125 * (s.crease_ends[0] + s.crease_ends[1]) + 0.75 * p,
                _ => p,
            });
        }
        points.extend(edge_points);
        points.extend(face_points);
        let mut net = Net {
            points,
            corners: Vec::with_capacity(4 * self.corners.len()),
            starts: Vec::with_capacity(self.corners.len() + 1),
            sharp: Vec::with_capacity(4 * self.corners.len()),
        };
        net.starts.push(0);
        for f in 0..nf {
            for h in self.halves(f) {
                let before = self.prev(f, h);
                let (e, e_before) = (edges.of_half[h], edges.of_half[before]);
                net.corners.extend([
                    self.corners[h],
                    (nv as u32) + e,
                    (nv + ne + f) as u32,
                    (nv as u32) + e_before,
                ]);
                net.sharp.extend([
                    edges.list[e as usize].sharp,
                    false,
                    false,
                    edges.list[e_before as usize].sharp,
                ]);
                net.starts.push(net.corners.len() as u32);
            }
        }
        net
    }

    fn loop_step(&self, edges: &Edges) -> Net {
        let (nv, nf) = (self.points.len(), self.face_count());
        let face_of = self.face_of_half();
        let opposite = |h: u32| {
            let f = face_of[h as usize] as usize;
            self.points[self.corners[self.prev(f, h as usize)] as usize]
        };
        let stars = self.vertex_stars(edges);
        let mut points = Vec::with_capacity(nv + edges.list.len());
        for (v, s) in stars.iter().enumerate() {
            let p = self.points[v];
            points.push(match s.creases {
                0 | 1 if s.valence > 0 => {
                    let beta = loop_beta(s.valence);
                    (1.0 - s.valence as f64 * beta) * p + beta * s.neighbours
                }
                2 => 0.125 * (s.crease_ends[0] + s.crease_ends[1]) + 0.75 * p,
                _ => p,
            });
        }
        points.extend(edges.list.iter().map(|e| {
            let (a, b) = (self.points[e.a as usize], self.points[e.b as usize]);
            if e.sharp || e.count == 1 {
                0.5 * (a + b)
            } else {
                0.375 * (a + b) + 0.125 * (opposite(e.halves[0]) + opposite(e.halves[1]))
            }
        }));
        let mut net = Net {
            points,
            corners: Vec::with_capacity(4 * self.corners.len()),
            starts: Vec::with_capacity(4 * nf + 1),
            sharp: Vec::with_capacity(4 * self.corners.len()),
        };
        net.starts.push(0);
        for f in 0..nf {
            let hs: Vec<usize> = self.halves(f).collect();
            let mid = |h: usize| nv as u32 + edges.of_half[h];
            let sharp = |h: usize| edges.list[edges.of_half[h] as usize].sharp;
            for k in 0..hs.len() {
                let (h, before) = (hs[k], hs[(k + hs.len() - 1) % hs.len()]);
                net.corners.extend([self.corners[h], mid(h), mid(before)]);
                net.sharp.extend([sharp(h), false, sharp(before)]);
                net.starts.push(net.corners.len() as u32);
            }
            net.corners.extend(hs.iter().map(|&h| mid(h)));
            net.sharp.extend(hs.iter().map(|_| false));
            net.starts.push(net.corners.len() as u32);
        }
        net
    }

    /// The limit position of vertex `v`, whose ring must be complete and made of quads
    /// (Catmull–Clark after one step) or triangles (Loop): the eigenvector masks.
    pub fn limit_position(&self, scheme: Scheme, v: u32, edges: &Edges) -> DVec3 {
        let p = self.points[v as usize];
        let mut star = Star::default();
        let mut diagonal = DVec3::ZERO;
        let face_of = self.face_of_half();
        for e in &edges.list {
            let w = if e.a == v {
                e.b
            } else if e.b == v {
                e.a
            } else {
                continue;
            };
            star.valence += 1;
            star.neighbours += self.points[w as usize];
            if e.sharp || e.count == 1 {
                if star.creases < 2 {
                    star.crease_ends[star.creases as usize] = self.points[w as usize];
                }
                star.creases += 1;
            }
        }
        if scheme == Scheme::CatmullClark {
            // The corner of each incident quad opposite `v`.
            for (h, &c) in self.corners.iter().enumerate() {
                if c == v {
                    let f = face_of[h] as usize;
                    let opposite = self.next(f, self.next(f, h));
                    diagonal += self.points[self.corners[opposite] as usize];
                }
            }
        }
        limit_mask(scheme, &star, diagonal, p)
    }

    /// [`Net::limit_position`] of every vertex at once (all rings complete: a closed mesh).
    pub fn limit_positions(&self, scheme: Scheme) -> Vec<DVec3> {
        let Ok(edges) = self.edges() else {
            return self.points.clone();
        };
        let stars = self.vertex_stars(&edges);
        let mut diagonals = vec![DVec3::ZERO; self.points.len()];
        if scheme == Scheme::CatmullClark {
            for f in 0..self.face_count() {
                for h in self.halves(f) {
                    let opposite = self.next(f, self.next(f, h));
                    diagonals[self.corners[h] as usize] +=
                        self.points[self.corners[opposite] as usize];
                }
            }
        }
        stars
            .iter()
            .zip(&diagonals)
            .zip(&self.points)
            .map(|((s, &diagonal), &p)| limit_mask(scheme, s, diagonal, p))
            .collect()
    }

    /// The faces incident to any vertex of face `f`, face `f` first, renumbered compactly (its
    /// ring: all the children's rings need after one more step).
    pub fn ring_of(&self, f: usize) -> Net {
        let centre = self.face(f);
        let others: Vec<usize> = (0..self.face_count())
            .filter(|&g| g != f && self.face(g).iter().any(|v| centre.contains(v)))
            .collect();
        self.ring_from(f, &others)
    }

    /// [`Net::ring_of`] with the faces around `f` already known (`others`: sorted, without
    /// `f`), for large nets.
    pub fn ring_from(&self, f: usize, others: &[usize]) -> Net {
        let keep = std::iter::once(f).chain(others.iter().copied());
        let mut index = vec![u32::MAX; self.points.len()];
        let mut net = Net {
            starts: vec![0],
            ..Net::default()
        };
        for g in keep {
            for h in self.halves(g) {
                let v = self.corners[h] as usize;
                if index[v] == u32::MAX {
                    index[v] = net.points.len() as u32;
                    net.points.push(self.points[v]);
                }
                net.corners.push(index[v]);
                net.sharp.push(self.sharp[h]);
            }
            net.starts.push(net.corners.len() as u32);
        }
        net
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct Star {
    valence: u32,
    creases: u32,
    crease_ends: [DVec3; 2],
    neighbours: DVec3,
}

/// The limit position of a vertex at `p` with this star (and, for Catmull–Clark quads, the sum
/// of the corners diagonally opposite in its faces).
fn limit_mask(scheme: Scheme, star: &Star, diagonal: DVec3, p: DVec3) -> DVec3 {
    let n = star.valence as f64;
    match star.creases {
        0 | 1 if star.valence > 0 => match scheme {
            Scheme::CatmullClark => {
                (n * n * p + 4.0 * star.neighbours + diagonal) / (n * (n + 5.0))
            }
            Scheme::Loop => {
                let chi = 1.0 / (3.0 / (8.0 * loop_beta(star.valence)) + n);
                (1.0 - n * chi) * p + chi * star.neighbours
            }
        },
        2 => (star.crease_ends[0] + star.crease_ends[1] + 4.0 * p) / 6.0,
        _ => p,
    }
}

/// Loop's smooth vertex weight for valence `n`.
pub(crate) fn loop_beta(n: u32) -> f64 {
    let n = n as f64;
    let c = 0.375 + 0.25 * (2.0 * PI / n).cos();
    (0.625 - c * c) / n
}
