//! The cell table that both VTK writers emit: tetrahedra, then boundary triangles, then feature edges,
//! with one value per cell for every cell-data array.

use delamesh_core::mesh::TetMesh;

pub(crate) const VTK_LINE: u8 = 3;
pub(crate) const VTK_TRIANGLE: u8 = 5;
pub(crate) const VTK_TETRA: u8 = 10;

/// An integer cell-data array; `-1` marks cells the label does not apply to.
pub(crate) struct IntArray {
    pub name: &'static str,
    pub values: Vec<i32>,
}

/// A float cell-data array; NaN on cells other than tetrahedra.
pub(crate) struct FloatArray {
    pub name: String,
    pub values: Vec<f64>,
}

pub(crate) struct CellTable {
    pub connectivity: Vec<u32>,
    /// End of each cell in `connectivity`.
    pub offsets: Vec<u64>,
    pub types: Vec<u8>,
    pub ints: Vec<IntArray>,
    pub floats: Vec<FloatArray>,
}

/// Labels are u32 in the model and Int32 in files; the rare label above `i32::MAX` saturates.
fn label(x: u32) -> i32 {
    i32::try_from(x).unwrap_or(i32::MAX)
}

impl CellTable {
    pub(crate) fn new(m: &TetMesh) -> CellTable {
        let (nt, nb, ne) = (m.tets.len(), m.boundary.len(), m.feature_edges.len());
        let n = nt + nb + ne;
        let mut c = CellTable {
            connectivity: Vec::with_capacity(4 * nt + 3 * nb + 2 * ne),
            offsets: Vec::with_capacity(n),
            types: Vec::with_capacity(n),
            ints: Vec::new(),
            floats: Vec::new(),
        };
        let push = |c: &mut CellTable, verts: &[u32], ty: u8| {
            c.connectivity.extend_from_slice(verts);
            c.offsets.push(c.connectivity.len() as u64);
            c.types.push(ty);
        };
        m.tets.iter().for_each(|t| push(&mut c, t, VTK_TETRA));
        m.boundary
            .iter()
            .for_each(|t| push(&mut c, t, VTK_TRIANGLE));
        m.feature_edges
            .iter()
            .for_each(|e| push(&mut c, e, VTK_LINE));
        let none = |k: usize| std::iter::repeat_n(-1, k);
        c.ints.push(IntArray {
            name: "subdomain",
            values: m
                .subdomains
                .iter()
                .map(|s| label(s.0))
                .chain(none(nb + ne))
                .collect(),
        });
        c.ints.push(IntArray {
            name: "patch",
            values: none(nt)
                .chain(m.boundary_patches.iter().map(|p| label(p.0)))
                .chain(none(ne))
                .collect(),
        });
        if ne > 0 {
            c.ints.push(IntArray {
                name: "curve",
                values: none(nt + nb)
                    .chain(m.feature_curves.iter().map(|k| label(k.0)))
                    .collect(),
            });
        }
        for f in &m.cell_fields {
            c.floats.push(FloatArray {
                // Legacy VTK names cannot hold whitespace.
                name: f.name.split_whitespace().collect::<Vec<_>>().join("_"),
                values: f
                    .values
                    .iter()
                    .copied()
                    .chain(std::iter::repeat_n(f64::NAN, nb + ne))
                    .collect(),
            });
        }
        c
    }

    pub(crate) fn len(&self) -> usize {
        self.types.len()
    }
}
