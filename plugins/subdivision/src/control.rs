//! The control mesh: checked (closed, oriented 2-manifold, no degenerate face), its creases
//! tagged (group borders, user polylines along control edges, a crease angle), and its scheme.

use crate::net::Net;
use crate::{Scheme, SubdivisionError, SubdivisionOptions};
use delamesh_core::mesh::newell_normal;
use delamesh_formats::PolygonMesh;
use delamesh_piecewise_smooth::{Polyline, SNAP_TOLERANCE};
use glam::DVec3;

/// A checked control mesh with its sharp edges.
pub(crate) struct ControlMesh {
    pub net: Net,
    pub scheme: Scheme,
    /// Group (from 1) of every face.
    pub groups: Vec<u32>,
    /// Sharp edges as sorted vertex pairs, sorted.
    pub creases: Vec<[u32; 2]>,
}

impl ControlMesh {
    pub fn new(
        mesh: &PolygonMesh,
        options: &SubdivisionOptions,
        polylines: &[Polyline],
    ) -> Result<ControlMesh, SubdivisionError> {
        if mesh.faces.is_empty() {
            return Err(SubdivisionError::Empty);
        }
        let all_triangles = mesh.faces.iter().all(|f| f.len() == 3);
        let scheme = options.scheme.unwrap_or(if all_triangles {
            Scheme::Loop
        } else {
            Scheme::CatmullClark
        });
        if scheme == Scheme::Loop && !all_triangles {
            let f = mesh.faces.iter().position(|f| f.len() != 3).unwrap_or(0);
            return Err(SubdivisionError::LoopNeedsTriangles {
                face: f,
                corners: mesh.faces[f].len(),
            });
        }
        let mut net = Net {
            points: mesh.positions.clone(),
            starts: vec![0],
            ..Net::default()
        };
        let diagonal = bounding_diagonal(&mesh.positions);
        for (f, face) in mesh.faces.iter().enumerate() {
            let n = face.len();
            let mut sorted = face.clone();
            sorted.sort_unstable();
            if sorted.windows(2).any(|w| w[0] == w[1]) {
                return Err(SubdivisionError::Degenerate { face: f });
            }
            // Newell's normal: zero for a face whose corners are all on one line.
            let normal = newell_normal(&mesh.positions, face);
            if normal.length() <= 1e-12 * diagonal * diagonal {
                return Err(SubdivisionError::Degenerate { face: f });
            }
            net.corners.extend(face);
            net.sharp.extend(std::iter::repeat_n(false, n));
            net.starts.push(net.corners.len() as u32);
        }
        let groups: Vec<u32> = mesh.groups.iter().map(|g| g.0 + 1).collect();
        check_manifold(&net)?;
        let mut creases = Vec::new();
        let edges = net.edges().map_err(|h| non_manifold_edge(&net, h))?;
        let face_of = net.face_of_half();
        for e in &edges.list {
            let [f, g] = e.halves.map(|h| face_of[h as usize] as usize);
            let by_group = options.group_creases && groups[f] != groups[g];
            let by_angle = options.crease_angle_deg.is_some_and(|limit| {
                let (nf, ng) = (face_normal(&net, f), face_normal(&net, g));
                nf.angle_between(ng).to_degrees() > limit
            });
            if by_group || by_angle {
                creases.push([e.a, e.b]);
            }
        }
        let mut control_edges: Vec<[u32; 2]> = edges.list.iter().map(|e| [e.a, e.b]).collect();
        control_edges.sort_unstable();
        for polyline in polylines {
            for e in snap_polyline(&net.points, polyline, diagonal)? {
                if control_edges.binary_search(&e).is_err() {
                    return Err(SubdivisionError::Polyline {
                        line: polyline.line,
                        problem: format!("vertices {} and {} share no control edge", e[0], e[1]),
                    });
                }
                creases.push(e);
            }
        }
        creases.sort_unstable();
        creases.dedup();
        for f in 0..net.face_count() {
            for h in net.halves(f) {
                let (a, b) = (net.corners[h], net.corners[net.next(f, h)]);
                net.sharp[h] = creases.binary_search(&[a.min(b), a.max(b)]).is_ok();
            }
        }
        Ok(ControlMesh {
            net,
            scheme,
            groups,
            creases,
        })
    }
}

fn bounding_diagonal(points: &[DVec3]) -> f64 {
    let (lo, hi) = crate::bezier::bounds(points);
    (hi - lo).length()
}

fn face_normal(net: &Net, f: usize) -> DVec3 {
    newell_normal(&net.points, net.face(f)).normalize_or_zero()
}

fn non_manifold_edge(net: &Net, h: u32) -> SubdivisionError {
    let face_of = net.face_of_half();
    let f = face_of[h as usize] as usize;
    let (a, b) = (
        net.corners[h as usize],
        net.corners[net.next(f, h as usize)],
    );
    SubdivisionError::NonManifoldEdge { a, b }
}

/// Every edge in exactly two faces, in opposite directions; every vertex in one fan of faces.
fn check_manifold(net: &Net) -> Result<(), SubdivisionError> {
    let edges = net.edges().map_err(|h| non_manifold_edge(net, h))?;
    let face_of = net.face_of_half();
    let ends = |h: u32| {
        let f = face_of[h as usize] as usize;
        (
            net.corners[h as usize],
            net.corners[net.next(f, h as usize)],
        )
    };
    for e in &edges.list {
        if e.count == 1 {
            return Err(SubdivisionError::Open { a: e.a, b: e.b });
        }
        if ends(e.halves[0]) == ends(e.halves[1]) {
            return Err(SubdivisionError::Orientation { a: e.a, b: e.b });
        }
    }
    // The fan around each vertex: from a half-edge leaving v, the previous half-edge of its
    // face arrives at v; its twin leaves v in the next face of the fan.
    let twin = |h: usize| {
        let e = &edges.list[edges.of_half[h] as usize];
        if e.halves[0] as usize == h {
            e.halves[1] as usize
        } else {
            e.halves[0] as usize
        }
    };
    let mut leaving = vec![0u32; net.points.len()];
    let mut first = vec![usize::MAX; net.points.len()];
    for (h, &v) in net.corners.iter().enumerate() {
        leaving[v as usize] += 1;
        if first[v as usize] == usize::MAX {
            first[v as usize] = h;
        }
    }
    for v in 0..net.points.len() {
        if first[v] == usize::MAX {
            continue;
        }
        let (start, mut h, mut steps) = (first[v], first[v], 0u32);
        loop {
            let prev = net.prev(face_of[h] as usize, h);
            h = twin(prev);
            steps += 1;
            if h == start || steps > leaving[v] {
                break;
            }
        }
        if steps != leaving[v] {
            return Err(SubdivisionError::NonManifoldVertex { vertex: v as u32 });
        }
    }
    Ok(())
}

/// The control edges a user polyline runs along (its points must be control vertices).
fn snap_polyline(
    points: &[DVec3],
    polyline: &Polyline,
    diagonal: f64,
) -> Result<Vec<[u32; 2]>, SubdivisionError> {
    let tol = SNAP_TOLERANCE * diagonal;
    let snap = |p: DVec3| {
        points
            .iter()
            .enumerate()
            .map(|(i, q)| (q.distance(p), i as u32))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .filter(|&(d, _)| d <= tol)
            .map(|(_, i)| i)
            .ok_or(SubdivisionError::Polyline {
                line: polyline.line,
                problem: format!("point {p} is not a control vertex"),
            })
    };
    let ids = polyline
        .points
        .iter()
        .map(|&p| snap(p))
        .collect::<Result<Vec<u32>, _>>()?;
    Ok(ids
        .windows(2)
        .filter(|w| w[0] != w[1])
        .map(|w| [w[0].min(w[1]), w[0].max(w[1])])
        .collect())
}
