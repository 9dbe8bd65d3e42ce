//! Gmsh `.msh` writer, format 4.1 (default) or 2.2, ASCII, hand-written (no maintained crate writes
//! it). Physical groups: one per subdomain (3D), patch (2D) and curve (1D), named after the label.
//!
//! Gmsh physical tags must be positive: a dimension whose labels include 0 is shifted by one (tag =
//! label + 1); otherwise tag = label. The physical name always spells the label itself.

use crate::error::Problem;
use crate::text::Exact;
use delamesh_core::mesh::{Aabb, TetMesh};
use std::io::Write;

const GMSH_LINE: u32 = 1;
const GMSH_TRIANGLE: u32 = 2;
const GMSH_TETRA: u32 = 4;

/// The elements of one dimension, grouped by label (ascending).
struct Dimension<'a> {
    dim: u32,
    kind: &'static str,
    element_type: u32,
    /// (label, element vertex lists)
    groups: Vec<(u32, Vec<&'a [u32]>)>,
    shift: u32,
}

impl<'a> Dimension<'a> {
    fn new<const N: usize>(
        dim: u32,
        kind: &'static str,
        element_type: u32,
        cells: &'a [[u32; N]],
        labels: impl Iterator<Item = u32>,
    ) -> Dimension<'a> {
        let mut by_label: std::collections::BTreeMap<u32, Vec<&[u32]>> = Default::default();
        for (c, l) in cells.iter().zip(labels) {
            by_label.entry(l).or_default().push(c.as_slice());
        }
        let shift = u32::from(by_label.contains_key(&0));
        Dimension {
            dim,
            kind,
            element_type,
            groups: by_label.into_iter().collect(),
            shift,
        }
    }

    fn tag(&self, label: u32) -> u64 {
        u64::from(label) + u64::from(self.shift)
    }
}

fn dimensions(m: &TetMesh) -> [Dimension<'_>; 3] {
    [
        Dimension::new(
            1,
            "curve",
            GMSH_LINE,
            &m.feature_edges,
            m.feature_curves.iter().map(|c| c.0),
        ),
        Dimension::new(
            2,
            "patch",
            GMSH_TRIANGLE,
            &m.boundary,
            m.boundary_patches.iter().map(|p| p.0),
        ),
        Dimension::new(
            3,
            "subdomain",
            GMSH_TETRA,
            &m.tets,
            m.subdomains.iter().map(|s| s.0),
        ),
    ]
}

fn physical_names(w: &mut dyn Write, dims: &[Dimension]) -> std::io::Result<()> {
    let n: usize = dims.iter().map(|d| d.groups.len()).sum();
    writeln!(w, "$PhysicalNames\n{n}")?;
    for d in dims {
        for (label, _) in &d.groups {
            writeln!(w, "{} {} \"{} {label}\"", d.dim, d.tag(*label), d.kind)?;
        }
    }
    writeln!(w, "$EndPhysicalNames")
}

pub(crate) fn write(w: &mut dyn Write, m: &TetMesh, v22: bool) -> Result<(), Problem> {
    let dims = dimensions(m);
    if v22 {
        write22(w, m, &dims)
    } else {
        write41(w, m, &dims)
    }?;
    Ok(())
}

fn write22(w: &mut dyn Write, m: &TetMesh, dims: &[Dimension]) -> std::io::Result<()> {
    writeln!(w, "$MeshFormat\n2.2 0 8\n$EndMeshFormat")?;
    physical_names(w, dims)?;
    writeln!(w, "$Nodes\n{}", m.positions.len())?;
    for (i, p) in m.positions.iter().enumerate() {
        writeln!(w, "{} {} {} {}", i + 1, Exact(p.x), Exact(p.y), Exact(p.z))?;
    }
    let n: usize = dims.iter().flat_map(|d| &d.groups).map(|g| g.1.len()).sum();
    writeln!(w, "$EndNodes\n$Elements\n{n}")?;
    let mut id = 0u64;
    for d in dims {
        for (label, cells) in &d.groups {
            // Two tags: physical group and elementary entity (the same here).
            let tag = d.tag(*label);
            for c in cells {
                id += 1;
                write!(w, "{id} {} 2 {tag} {tag}", d.element_type)?;
                c.iter().try_for_each(|v| write!(w, " {}", v + 1))?;
                writeln!(w)?;
            }
        }
    }
    writeln!(w, "$EndElements")
}

fn write41(w: &mut dyn Write, m: &TetMesh, dims: &[Dimension]) -> std::io::Result<()> {
    writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
    physical_names(w, dims)?;
    // One geometric entity per label and dimension, tagged like its physical group.
    let bbox = |cells: &[&[u32]]| {
        let pts: Vec<_> = cells
            .iter()
            .flat_map(|c| c.iter().map(|&v| m.positions[v as usize]))
            .collect();
        Aabb::of(&pts)
    };
    writeln!(
        w,
        "$Entities\n0 {} {} {}",
        dims[0].groups.len(),
        dims[1].groups.len(),
        dims[2].groups.len()
    )?;
    for d in dims {
        for (label, cells) in &d.groups {
            let Some(b) = bbox(cells) else { continue };
            write!(
                w,
                "{} {} {} {} {} {} {} 1 {}",
                d.tag(*label),
                Exact(b.min.x),
                Exact(b.min.y),
                Exact(b.min.z),
                Exact(b.max.x),
                Exact(b.max.y),
                Exact(b.max.z),
                d.tag(*label)
            )?;
            // No bounding entities: the mesh carries no B-rep.
            writeln!(w, " 0")?;
        }
    }
    writeln!(w, "$EndEntities")?;

    // All nodes in one block, attached to the highest-dimensional entity present.
    let (node_dim, node_tag) = dims
        .iter()
        .rev()
        .find_map(|d| d.groups.first().map(|(l, _)| (d.dim, d.tag(*l))))
        .unwrap_or((0, 0));
    let n = m.positions.len();
    writeln!(w, "$Nodes\n1 {n} 1 {n}\n{node_dim} {node_tag} 0 {n}")?;
    for i in 1..=n {
        writeln!(w, "{i}")?;
    }
    for p in &m.positions {
        writeln!(w, "{} {} {}", Exact(p.x), Exact(p.y), Exact(p.z))?;
    }
    writeln!(w, "$EndNodes")?;

    let blocks: usize = dims.iter().map(|d| d.groups.len()).sum();
    let total: usize = dims.iter().flat_map(|d| &d.groups).map(|g| g.1.len()).sum();
    writeln!(w, "$Elements\n{blocks} {total} 1 {total}")?;
    let mut id = 0u64;
    for d in dims {
        for (label, cells) in &d.groups {
            writeln!(
                w,
                "{} {} {} {}",
                d.dim,
                d.tag(*label),
                d.element_type,
                cells.len()
            )?;
            for c in cells {
                id += 1;
                write!(w, "{id}")?;
                c.iter().try_for_each(|v| write!(w, " {}", v + 1))?;
                writeln!(w)?;
            }
        }
    }
    writeln!(w, "$EndElements")
}
