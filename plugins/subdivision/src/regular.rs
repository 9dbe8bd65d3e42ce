//! Regular faces: those whose limit patch is one polynomial, found by laying their ring out on
//! the regular lattice (square grid for Catmull–Clark, triangular for Loop), and the matrices
//! turning the ring's control points into the patch's Bézier points.
//!
//! The matrices are not typed in: they are computed once from the subdivision rules
//! themselves, on the canonical ring, as exact limit values at dyadic nodes (by subdividing and
//! applying the limit masks) fitted by the interpolation of [`crate::bezier`]. A configuration
//! is used only if the fit reproduces the exact limit at a finer set of nodes, which proves the
//! patch polynomial: smooth rings (the uniform B-spline and box-spline cases) and rings crossed
//! by one straight crease along an edge of the face.

use crate::Scheme;
use crate::bezier::{Bezier, bezier_len, child_at, child_domains, fit_nodes, reference_corners};
use crate::net::Net;
use glam::{DVec2, DVec3, IVec2};
use std::sync::OnceLock;

type Coord = IVec2;

/// What crosses the ring of a regular face: nothing, or a straight crease along face edge `r`
/// (from corner `r` to corner `r + 1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Config {
    Smooth,
    Crease(usize),
}

/// The lattice rotation by one step around a vertex: 90° on the grid, 60° on the triangular
/// lattice (axial coordinates).
fn rotate(scheme: Scheme, d: Coord) -> Coord {
    match scheme {
        Scheme::CatmullClark => IVec2::new(-d.y, d.x),
        Scheme::Loop => IVec2::new(-d.y, d.x + d.y),
    }
}

/// The lattice positions of the face's corners.
fn face_coords(scheme: Scheme) -> &'static [Coord] {
    const SQUARE: [Coord; 4] = [
        IVec2::new(1, 1),
        IVec2::new(2, 1),
        IVec2::new(2, 2),
        IVec2::new(1, 2),
    ];
    const TRIANGLE: [Coord; 3] = [IVec2::new(0, 0), IVec2::new(1, 0), IVec2::new(0, 1)];
    match scheme {
        Scheme::CatmullClark => &SQUARE,
        Scheme::Loop => &TRIANGLE,
    }
}

/// The canonical ring: its faces as lattice corner lists, the face first, and its vertices in
/// sorted order (the order of the control points the matrices take).
struct Canonical {
    faces: Vec<Vec<Coord>>,
    vertices: Vec<Coord>,
}

fn canonical(scheme: Scheme) -> &'static Canonical {
    static CACHE: [OnceLock<Canonical>; 2] = [OnceLock::new(), OnceLock::new()];
    CACHE[scheme as usize].get_or_init(|| {
        let centre = face_coords(scheme);
        let mut faces = vec![centre.to_vec()];
        for a in -2..4 {
            for b in -2..4 {
                let o = IVec2::new(a, b);
                let cells: Vec<Vec<Coord>> = match scheme {
                    Scheme::CatmullClark => {
                        vec![vec![o, o + IVec2::X, o + IVec2::ONE, o + IVec2::Y]]
                    }
                    Scheme::Loop => vec![
                        vec![o, o + IVec2::X, o + IVec2::Y],
                        vec![o + IVec2::X, o + IVec2::ONE, o + IVec2::Y],
                    ],
                };
                for f in cells {
                    let touches = f.iter().any(|c| centre.contains(c));
                    if touches && f.as_slice() != centre {
                        faces.push(f);
                    }
                }
            }
        }
        let mut vertices: Vec<Coord> = faces.iter().flatten().copied().collect();
        vertices.sort_by_key(|c| (c.y, c.x));
        vertices.dedup();
        Canonical { faces, vertices }
    })
}

/// The sharp edges a configuration puts on the ring, as sorted coordinate pairs.
fn config_edges(scheme: Scheme, config: Config) -> Vec<(Coord, Coord)> {
    let Config::Crease(r) = config else {
        return Vec::new();
    };
    let c = face_coords(scheme);
    let (a, b) = (c[r], c[(r + 1) % c.len()]);
    let d = b - a;
    let mut edges: Vec<(Coord, Coord)> = [(a - d, a), (a, b), (b, b + d)]
        .iter()
        .map(|&(p, q)| sorted(p, q))
        .collect();
    edges.sort_by_key(|&(p, q)| (p.y, p.x, q.y, q.x));
    edges
}

fn sorted(p: Coord, q: Coord) -> (Coord, Coord) {
    if (p.y, p.x) <= (q.y, q.x) {
        (p, q)
    } else {
        (q, p)
    }
}

/// The canonical ring's net for a configuration, with `data` at its vertices.
fn canonical_net(scheme: Scheme, config: Config, data: &[DVec3]) -> Net {
    let can = canonical(scheme);
    let sharp = config_edges(scheme, config);
    let mut net = Net {
        points: data.to_vec(),
        starts: vec![0],
        ..Net::default()
    };
    for f in &can.faces {
        for (k, &c) in f.iter().enumerate() {
            let next = f[(k + 1) % f.len()];
            net.corners.push(
                can.vertices
                    .binary_search_by_key(&(c.y, c.x), |v| (v.y, v.x))
                    .unwrap_or(0) as u32,
            );
            net.sharp.push(sharp.contains(&sorted(c, next)));
        }
        net.starts.push(net.corners.len() as u32);
    }
    net
}

/// The exact limit position at a dyadic parameter `p` of the net's face 0, found by
/// subdividing `levels` times (the point must be a corner of a face at that level).
pub(crate) fn limit_at_dyadic(scheme: Scheme, net: &Net, p: DVec2, levels: u32) -> DVec3 {
    let mut net = net.clone();
    let mut p = p;
    let children = child_domains(scheme);
    for _ in 0..levels {
        let k = child_at(scheme, p);
        let sub = net.subdivide(scheme);
        net = sub.ring_of(child_face(scheme, 0, k));
        p = children[k].invert(p);
    }
    let corner = reference_corners(scheme)
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.distance(p).total_cmp(&b.1.distance(p)))
        .map_or(0, |(k, _)| k);
    let v = net.face(0)[corner];
    match net.edges() {
        Ok(edges) => net.limit_position(scheme, v, &edges),
        Err(_) => net.points[v as usize],
    }
}

/// Index, in the subdivided net, of child `k` of face `f` (the order [`Net::subdivide`] makes
/// them in): for Catmull–Clark one per corner slot of the face, for Loop four per triangle.
pub(crate) fn child_face(scheme: Scheme, face_start: usize, k: usize) -> usize {
    match scheme {
        Scheme::CatmullClark => face_start + k,
        Scheme::Loop => face_start / 3 * 4 + k,
    }
}

/// Bézier point `b` of a configuration's patch as weights of the canonical control points:
/// `matrix[b][c]`; `None` if the fit does not reproduce the limit (not polynomial).
fn conversion(scheme: Scheme, config: Config) -> Option<&'static Vec<Vec<f64>>> {
    type Matrices = Vec<Option<Vec<Vec<f64>>>>;
    static CACHE: [OnceLock<Matrices>; 2] = [OnceLock::new(), OnceLock::new()];
    let all = CACHE[scheme as usize].get_or_init(|| {
        let n = face_coords(scheme).len();
        std::iter::once(Config::Smooth)
            .chain((0..n).map(Config::Crease))
            .map(|config| compute_conversion(scheme, config))
            .collect()
    });
    let index = match config {
        Config::Smooth => 0,
        Config::Crease(r) => 1 + r,
    };
    all.get(index)?.as_ref()
}

fn compute_conversion(scheme: Scheme, config: Config) -> Option<Vec<Vec<f64>>> {
    let controls = canonical(scheme).vertices.len();
    let nodes = fit_nodes(scheme);
    // Column c: the Bézier points of basis function c.
    let mut columns = Vec::with_capacity(controls);
    for c in 0..controls {
        let data: Vec<DVec3> = (0..controls)
            .map(|i| DVec3::new(f64::from(u8::from(i == c)), 0.0, 0.0))
            .collect();
        let net = canonical_net(scheme, config, &data);
        let values: Vec<DVec3> = nodes
            .iter()
            .map(|&p| limit_at_dyadic(scheme, &net, p, 2))
            .collect();
        columns.push(Bezier::fit(scheme, &values));
    }
    let matrix: Vec<Vec<f64>> = (0..bezier_len(scheme))
        .map(|b| columns.iter().map(|col| col.points[b].x).collect())
        .collect();
    // Proof of polynomiality: generic control points, exact limit at eighth nodes.
    let data: Vec<DVec3> = (0..controls)
        .map(|i| {
            let x = i as f64;
            DVec3::new((1.3 * x).sin(), (0.7 * x + 0.2).cos(), 0.05 * x * x)
        })
        .collect();
    let net = canonical_net(scheme, config, &data);
    let patch = apply(scheme, matrix.as_slice(), &data);
    for j in 0..=8 {
        for i in 0..=8 {
            let p = DVec2::new(i as f64, j as f64) / 8.0;
            if scheme == Scheme::Loop && i + j > 8 {
                continue;
            }
            let exact = limit_at_dyadic(scheme, &net, p, 3);
            if exact.distance(patch.eval(p).point) > 1e-11 {
                return None;
            }
        }
    }
    Some(matrix)
}

fn apply(scheme: Scheme, matrix: &[Vec<f64>], controls: &[DVec3]) -> Bezier {
    let mut points = [DVec3::ZERO; 16];
    for (b, row) in matrix.iter().enumerate() {
        points[b] = row.iter().zip(controls).map(|(&w, &p)| w * p).sum();
    }
    Bezier { scheme, points }
}

/// The polynomial patch of the net's face 0 if its ring is regular (lattice layout, complete
/// rings of regular valence, creases only in a supported configuration).
pub(crate) fn regular_patch(scheme: Scheme, net: &Net) -> Option<Bezier> {
    let can = canonical(scheme);
    let arity = face_coords(scheme).len();
    if net.face_count() != can.faces.len() || net.points.len() != can.vertices.len() {
        return None;
    }
    if (0..net.face_count()).any(|f| net.face(f).len() != arity) {
        return None;
    }
    let mut coords: Vec<Option<Coord>> = vec![None; net.points.len()];
    for (k, &v) in net.face(0).iter().enumerate() {
        coords[v as usize] = Some(face_coords(scheme)[k]);
    }
    let mut placed = vec![false; net.face_count()];
    placed[0] = true;
    for _ in 0..net.face_count() {
        let mut progress = false;
        for (f, done) in placed.iter_mut().enumerate().skip(1) {
            if *done {
                continue;
            }
            let face = net.face(f);
            let Some(k) = (0..arity).find(|&k| {
                coords[face[k] as usize].is_some()
                    && coords[face[(k + 1) % arity] as usize].is_some()
            }) else {
                continue;
            };
            let a = coords[face[k] as usize]?;
            let b = coords[face[(k + 1) % arity] as usize]?;
            let step = rotate(scheme, b - a);
            let expected: Vec<Coord> = match scheme {
                Scheme::CatmullClark => vec![b + step, a + step],
                Scheme::Loop => vec![a + step],
            };
            for (m, &c) in expected.iter().enumerate() {
                let v = face[(k + 2 + m) % arity] as usize;
                match coords[v] {
                    Some(old) if old != c => return None,
                    _ => coords[v] = Some(c),
                }
            }
            *done = true;
            progress = true;
        }
        if !progress {
            break;
        }
    }
    if placed.iter().any(|&p| !p) {
        return None;
    }
    let mut controls = vec![DVec3::ZERO; can.vertices.len()];
    let mut seen = vec![false; can.vertices.len()];
    for (v, c) in coords.iter().enumerate() {
        let c = (*c)?;
        let i = can
            .vertices
            .binary_search_by_key(&(c.y, c.x), |w| (w.y, w.x))
            .ok()?;
        if std::mem::replace(&mut seen[i], true) {
            return None;
        }
        controls[i] = net.points[v];
    }
    // Every face must be a face of the canonical ring, corners in order: the layout is then an
    // isomorphism (a ring of other valences can place its faces without a conflicting vertex).
    for f in 0..net.face_count() {
        let face: Vec<Coord> = net
            .face(f)
            .iter()
            .map(|&v| coords[v as usize])
            .collect::<Option<_>>()?;
        let matches = can
            .faces
            .iter()
            .any(|g| (0..arity).any(|r| (0..arity).all(|k| g[(k + r) % arity] == face[k])));
        if !matches {
            return None;
        }
    }
    let config = ring_config(scheme, net, &coords)?;
    conversion(scheme, config).map(|m| apply(scheme, m, &controls))
}

/// Which configuration the ring's sharp edges at the face's corners make, if any.
fn ring_config(scheme: Scheme, net: &Net, coords: &[Option<Coord>]) -> Option<Config> {
    let centre = face_coords(scheme);
    let mut sharp = Vec::new();
    for f in 0..net.face_count() {
        for h in net.halves(f) {
            if !net.sharp[h] {
                continue;
            }
            let (a, b) = (
                net.corners[h] as usize,
                net.corners[net.next(f, h)] as usize,
            );
            let (a, b) = (coords[a]?, coords[b]?);
            if centre.contains(&a) || centre.contains(&b) {
                sharp.push(sorted(a, b));
            }
        }
    }
    sharp.sort_by_key(|&(p, q)| (p.y, p.x, q.y, q.x));
    sharp.dedup();
    if sharp.is_empty() {
        return Some(Config::Smooth);
    }
    (0..centre.len())
        .map(Config::Crease)
        .find(|&c| config_edges(scheme, c) == sharp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn canonical_rings_have_the_regular_sizes() {
        let cc = canonical(Scheme::CatmullClark);
        assert_eq!((cc.faces.len(), cc.vertices.len()), (9, 16));
        let lp = canonical(Scheme::Loop);
        assert_eq!((lp.faces.len(), lp.vertices.len()), (13, 12));
    }

    #[test]
    fn smooth_catmull_clark_matrix_is_the_uniform_b_spline_to_bezier_change_of_basis() {
        // 1D: Bézier points of a uniform cubic B-spline segment over P0..P3.
        let m1 = [
            [1.0, 4.0, 1.0, 0.0],
            [0.0, 4.0, 2.0, 0.0],
            [0.0, 2.0, 4.0, 0.0],
            [0.0, 1.0, 4.0, 1.0],
        ];
        let m = conversion(Scheme::CatmullClark, Config::Smooth).expect("polynomial");
        let can = canonical(Scheme::CatmullClark);
        for b in 0..16 {
            for (c, coord) in can.vertices.iter().enumerate() {
                let expected = m1[b % 4][coord.x as usize] * m1[b / 4][coord.y as usize] / 36.0;
                assert!((m[b][c] - expected).abs() < 1e-12, "{b} {c}: {}", m[b][c]);
            }
        }
    }

    #[test]
    fn smooth_and_straight_crease_rings_are_polynomial() {
        for scheme in [Scheme::CatmullClark, Scheme::Loop] {
            assert!(conversion(scheme, Config::Smooth).is_some(), "{scheme:?}");
            for r in 0..face_coords(scheme).len() {
                let ok = conversion(scheme, Config::Crease(r)).is_some();
                assert!(ok || scheme == Scheme::Loop, "{scheme:?} crease {r}");
            }
        }
    }
}
