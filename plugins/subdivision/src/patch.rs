//! One patch of the limit surface per face of the once-subdivided control mesh: polynomial
//! (Bézier) over regular faces, else the face's ring, evaluated exactly by subdividing it until
//! the parameter falls in a regular child (OpenSubdiv's feature-adaptive scheme, here on the
//! fly): a point at distance δ from an irregular corner needs about log₂(1/δ) steps.

use crate::Scheme;
use crate::bezier::{Affine, Bezier, Eval, child_at, child_domains};
use crate::net::Net;
use crate::regular::{child_face, regular_patch};
use glam::{DVec2, DVec3};
use std::sync::OnceLock;

/// Subdivision steps at most below an irregular corner.
pub(crate) const MAX_DEPTH: u32 = 60;
/// Below an irregular corner, a piece this small relative to its patch is evaluated as the
/// linear interpolation of its corners' limit positions: rings shrink by the subdominant
/// eigenvalue per step (0.41 at valence 3), so a fixed depth would reach rounding noise, and
/// this size keeps the position within the accuracy target and seven digits of the tangents.
pub(crate) const POINT_SIZE: f64 = 1e-9;

/// A patch's surface.
#[derive(Clone, Debug)]
// Most patches are regular: boxing their points would cost an allocation each.
#[allow(clippy::large_enum_variant)]
pub(crate) enum Surface {
    Regular(Bezier),
    Irregular(Ring),
}

/// An irregular patch: the ring of its face, and its children once made. Queries and
/// evaluations near an extraordinary vertex ask for the same children again and again, and
/// making them (a subdivision step and four ring layouts) cost more than the rest of a query.
#[derive(Clone, Debug)]
pub(crate) struct Ring {
    pub net: Net,
    lo: DVec3,
    hi: DVec3,
    children: OnceLock<Box<[(Affine, Surface); 4]>>,
}

impl Ring {
    fn new(net: Net) -> Ring {
        let (lo, hi) = crate::bezier::bounds(&net.points);
        Ring {
            net,
            lo,
            hi,
            children: OnceLock::new(),
        }
    }

    /// The four children (Catmull–Clark and Loop alike) after one step, with their domains.
    pub fn children(&self, scheme: Scheme) -> &[(Affine, Surface); 4] {
        self.children.get_or_init(|| {
            let sub = self.net.subdivide(scheme);
            let domains = child_domains(scheme);
            Box::new(std::array::from_fn(|k| {
                (
                    domains[k],
                    Surface::of_ring(scheme, sub.ring_of(child_face(scheme, 0, k))),
                )
            }))
        })
    }
}

/// One patch: its surface and the control face's group.
#[derive(Clone, Debug)]
pub(crate) struct Patch {
    pub surface: Surface,
    /// The patch id reported with hits (the control face's group, from 1).
    pub group: u32,
}

impl Surface {
    /// The surface of face 0 of `ring` (a face with its ring).
    pub fn of_ring(scheme: Scheme, ring: Net) -> Surface {
        match regular_patch(scheme, &ring) {
            Some(b) => Surface::Regular(b),
            None => Surface::Irregular(Ring::new(ring)),
        }
    }

    /// Box containing the patch: control points have the convex-hull property (subdivision
    /// weights are non-negative and sum to one).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        match self {
            Surface::Regular(b) => b.bounds(),
            Surface::Irregular(ring) => (ring.lo, ring.hi),
        }
    }

    /// Exact position and derivatives at `p` in the reference domain (within [`POINT_SIZE`] of
    /// an irregular corner: the corner's limit position, and the tangent plane beside it).
    pub fn eval(&self, scheme: Scheme, p: DVec2) -> Eval {
        let mut ring = match self {
            Surface::Regular(b) => return b.eval(p),
            Surface::Irregular(ring) => ring,
        };
        // `local` is the parameter in the current child, `to_root` the child's domain in the
        // root's.
        let (mut local, mut to_root) = (p, Affine::IDENTITY);
        let smallest = POINT_SIZE * (ring.hi - ring.lo).length();
        for _ in 0..MAX_DEPTH {
            if (ring.hi - ring.lo).length() <= smallest {
                break;
            }
            let (domain, child) = &ring.children(scheme)[child_at(scheme, local)];
            local = domain.invert(local);
            to_root = to_root.compose(domain);
            match child {
                Surface::Regular(b) => return chain(b.eval(local), &to_root),
                Surface::Irregular(r) => ring = r,
            }
        }
        // Past the last step, the position is that of the corners (a point-sized piece); the tangent
        // plane is that of a regular child one step further, as close to the corner.
        let mut e = corner_interpolation(scheme, &ring.net, local);
        for (domain, child) in ring.children(scheme) {
            if let Surface::Regular(b) = child {
                let near = b.eval(DVec2::splat(0.25));
                e.du = near.du;
                e.dv = near.dv;
                return chain(e, &to_root.compose(domain));
            }
        }
        chain(e, &to_root)
    }
}

/// Derivatives with respect to the root's parameters of a child evaluated in its own.
fn chain(e: Eval, to_root: &Affine) -> Eval {
    // Root = A·local + o, so d/d(root) = A⁻ᵀ d/d(local).
    let det = to_root.du.perp_dot(to_root.dv);
    let (a, b, c, d) = (to_root.du.x, to_root.dv.x, to_root.du.y, to_root.dv.y);
    // Inverse of [[a, b], [c, d]]: [[d, -b], [-c, a]] / det; ∂local/∂u = (d, -c)/det.
    Eval {
        point: e.point,
        du: (d * e.du - c * e.dv) / det,
        dv: (-b * e.du + a * e.dv) / det,
    }
}

/// The linear (bilinear on the square) interpolation of the face's corner limit positions.
fn corner_interpolation(scheme: Scheme, net: &Net, p: DVec2) -> Eval {
    let Ok(edges) = net.edges() else {
        let q = net.points.first().copied().unwrap_or_default();
        return Eval {
            point: q,
            du: DVec3::ZERO,
            dv: DVec3::ZERO,
        };
    };
    let c: Vec<DVec3> = net
        .face(0)
        .iter()
        .map(|&v| net.limit_position(scheme, v, &edges))
        .collect();
    match scheme {
        Scheme::CatmullClark => {
            let (u, v) = (p.x, p.y);
            Eval {
                point: (1.0 - u) * (1.0 - v) * c[0]
                    + u * (1.0 - v) * c[1]
                    + u * v * c[2]
                    + (1.0 - u) * v * c[3],
                du: (1.0 - v) * (c[1] - c[0]) + v * (c[2] - c[3]),
                dv: (1.0 - u) * (c[3] - c[0]) + u * (c[2] - c[1]),
            }
        }
        Scheme::Loop => Eval {
            point: (1.0 - p.x - p.y) * c[0] + p.x * c[1] + p.y * c[2],
            du: c[1] - c[0],
            dv: c[2] - c[0],
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn children_of_an_extraordinary_patch_are_regular_but_one() {
        // A valence-3 corner: the cube's once-subdivided corner patch.
        let cube = crate::net::Net {
            points: vec![
                DVec3::new(-1.0, -1.0, -1.0),
                DVec3::new(1.0, -1.0, -1.0),
                DVec3::new(1.0, 1.0, -1.0),
                DVec3::new(-1.0, 1.0, -1.0),
                DVec3::new(-1.0, -1.0, 1.0),
                DVec3::new(1.0, -1.0, 1.0),
                DVec3::new(1.0, 1.0, 1.0),
                DVec3::new(-1.0, 1.0, 1.0),
            ],
            corners: vec![
                0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7,
            ],
            starts: vec![0, 4, 8, 12, 16, 20, 24],
            sharp: vec![false; 24],
        };
        let base = cube.subdivide(Scheme::CatmullClark);
        let Surface::Irregular(root) = Surface::of_ring(Scheme::CatmullClark, base.ring_of(0))
        else {
            panic!("the corner patch is irregular");
        };
        let kinds: Vec<bool> = root
            .children(Scheme::CatmullClark)
            .iter()
            .map(|(_, s)| matches!(s, Surface::Regular(_)))
            .collect();
        assert_eq!(kinds, vec![false, true, true, true]);
    }
}
