//! Oracle over the exact limit surface of a subdivision control mesh: Loop for triangle meshes,
//! Catmull–Clark for polygon meshes, with sharp creases (Hoppe et al.'s rules), so that a model
//! made with subdivision surfaces is meshed as the surface itself, not a dense approximation.
//!
//! Evaluation is exact and patch-based, as OpenSubdiv's feature-adaptive scheme: every face of
//! the once-subdivided control mesh (Catmull–Clark) or every control triangle (Loop) is a
//! patch; a regular patch is one polynomial (bicubic, or quartic box spline), turned into Bézier
//! form by a matrix derived from the subdivision rules themselves ([`regular`]); near an
//! extraordinary vertex, a dart or a crease corner the patch is subdivided on the fly until the
//! parameter falls in a regular child. Segment queries split patches while the box of their
//! control points meets the segment, then run Newton's method on the exact polynomial; the
//! inside test is ray parity on the same queries. Patch ids are the control faces' groups (from
//! 1), curve ids the crease chains between corners: the mesher protects them as polylines
//! sampled on the limit, and every vertex it puts on one is projected onto the limit crease
//! ([`crease`]: Newton's method on the patch borders the crease is made of).
//!
//! The control mesh must be a closed, consistently oriented 2-manifold without degenerate faces;
//! anything else is refused with an error naming the edge, vertex or face.

mod bezier;
mod control;
mod crease;
mod intersect;
mod net;
mod oracle;
mod patch;
mod plugin_export;
mod regular;

pub use oracle::SubdivisionOracle;

use std::fmt;
use std::str::FromStr;

/// The subdivision rules.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scheme {
    /// Catmull–Clark: any polygons; the limit is bicubic away from extraordinary vertices.
    CatmullClark = 0,
    /// Loop: triangles only; the limit is a quartic box spline away from extraordinary vertices.
    Loop = 1,
}

impl FromStr for Scheme {
    type Err = String;
    fn from_str(s: &str) -> Result<Scheme, String> {
        match s {
            "catmull-clark" | "cc" => Ok(Scheme::CatmullClark),
            "loop" => Ok(Scheme::Loop),
            _ => Err(format!(
                "unknown subdivision scheme {s:?} (expected loop or catmull-clark)"
            )),
        }
    }
}

impl fmt::Display for Scheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Scheme::CatmullClark => "catmull-clark",
            Scheme::Loop => "loop",
        })
    }
}

/// How a control mesh becomes a limit surface.
#[derive(Clone, Debug, PartialEq)]
pub struct SubdivisionOptions {
    /// The rules; `None` chooses by face type (Loop when every face is a triangle).
    pub scheme: Option<Scheme>,
    /// Edges between faces of different groups (OBJ `g` / `o`, PLY `patch`) are creases.
    pub group_creases: bool,
    /// Control edges whose faces' normals differ by more than this many degrees are creases.
    pub crease_angle_deg: Option<f64>,
}

impl Default for SubdivisionOptions {
    fn default() -> Self {
        SubdivisionOptions {
            scheme: None,
            group_creases: true,
            crease_angle_deg: None,
        }
    }
}

/// Why a control mesh cannot be meshed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SubdivisionError {
    /// No face.
    #[error("the control mesh has no faces")]
    Empty,
    /// Loop subdivision asked for a mesh with other polygons.
    #[error(
        "Loop subdivision needs triangles, but face {face} has {corners} corners (use catmull-clark)"
    )]
    LoopNeedsTriangles {
        /// The face.
        face: usize,
        /// Its corner count.
        corners: usize,
    },
    /// A face with a repeated vertex or all corners on one line.
    #[error("control face {face} is degenerate (repeated vertex or zero area)")]
    Degenerate {
        /// The face.
        face: usize,
    },
    /// An edge in one face only: the limit surface would not bound a volume.
    #[error("the control mesh is open: edge {a}–{b} is in one face only")]
    Open {
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
    },
    /// An edge in more than two faces.
    #[error("the control mesh is not a 2-manifold: edge {a}–{b} is in more than two faces")]
    NonManifoldEdge {
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
    },
    /// A vertex whose faces make several fans.
    #[error("the control mesh is not a 2-manifold at vertex {vertex} (several fans of faces)")]
    NonManifoldVertex {
        /// The vertex.
        vertex: u32,
    },
    /// Two faces running through an edge in the same direction.
    #[error("the control mesh is not consistently oriented at edge {a}–{b}")]
    Orientation {
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
    },
    /// A crease polyline that does not follow control edges.
    #[error("feature polyline on line {line}: {problem}")]
    Polyline {
        /// Its line in the file.
        line: usize,
        /// What is wrong.
        problem: String,
    },
}
