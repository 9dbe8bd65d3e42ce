//! Legacy VTK (`.vtk`) writer, version 4.2 (read by VTK ≥ 5, ParaView and meshio), binary (big-endian,
//! as the format prescribes) by default or ASCII. Hand-written for the same control as the `.vtu` writer.

use crate::error::Problem;
use crate::text::Exact;
use crate::vtk_cells::CellTable;
use delamesh_core::mesh::TetMesh;
use std::io::Write;

pub(crate) fn write(w: &mut dyn Write, m: &TetMesh, ascii: bool) -> Result<(), Problem> {
    let cells = CellTable::new(m);
    let too_big = || {
        Problem::Unsupported(
            "more than 2^31 vertices or cell entries: too large for legacy VTK".into(),
        )
    };
    let n = i32::try_from(cells.len()).map_err(|_| too_big())?;
    let list_size = i32::try_from(cells.connectivity.len() + cells.len()).map_err(|_| too_big())?;
    i32::try_from(m.positions.len()).map_err(|_| too_big())?;

    writeln!(w, "# vtk DataFile Version 4.2\ndelamesh tetrahedral mesh")?;
    writeln!(w, "{}", if ascii { "ASCII" } else { "BINARY" })?;
    write_points(w, m, ascii)?;
    write_cells(w, &cells, n, list_size, ascii)?;
    write_cell_data(w, &cells, n, ascii)
}

/// The `POINTS` section.
fn write_points(w: &mut dyn Write, m: &TetMesh, ascii: bool) -> Result<(), Problem> {
    writeln!(
        w,
        "DATASET UNSTRUCTURED_GRID\nPOINTS {} double",
        m.positions.len()
    )?;
    if ascii {
        for p in &m.positions {
            writeln!(w, "{} {} {}", Exact(p.x), Exact(p.y), Exact(p.z))?;
        }
    } else {
        for p in &m.positions {
            for x in p.to_array() {
                w.write_all(&x.to_be_bytes())?;
            }
        }
        writeln!(w)?;
    }
    Ok(())
}

/// The `CELLS` and `CELL_TYPES` sections.
fn write_cells(
    w: &mut dyn Write,
    cells: &CellTable,
    n: i32,
    list_size: i32,
    ascii: bool,
) -> Result<(), Problem> {
    writeln!(w, "CELLS {n} {list_size}")?;
    let mut start = 0usize;
    for &end in &cells.offsets {
        let verts = &cells.connectivity[start..end as usize];
        if ascii {
            let ids: Vec<String> = verts.iter().map(u32::to_string).collect();
            writeln!(w, "{} {}", verts.len(), ids.join(" "))?;
        } else {
            w.write_all(&(verts.len() as i32).to_be_bytes())?;
            for &v in verts {
                w.write_all(&(v as i32).to_be_bytes())?;
            }
        }
        start = end as usize;
    }
    if !ascii {
        writeln!(w)?;
    }

    writeln!(w, "CELL_TYPES {n}")?;
    if ascii {
        for t in &cells.types {
            writeln!(w, "{t}")?;
        }
    } else {
        for &t in &cells.types {
            w.write_all(&i32::from(t).to_be_bytes())?;
        }
        writeln!(w)?;
    }
    Ok(())
}

/// The `CELL_DATA` section: one active SCALARS array (what every VTK reader keeps), the rest as
/// FIELD arrays, which VTK's reader keeps all of (it drops extra SCALARS unless told to read them).
fn write_cell_data(
    w: &mut dyn Write,
    cells: &CellTable,
    n: i32,
    ascii: bool,
) -> Result<(), Problem> {
    writeln!(w, "CELL_DATA {n}")?;
    let (first, rest) = cells
        .ints
        .split_first()
        .ok_or_else(|| Problem::bad("no cell data"))?;
    writeln!(w, "SCALARS {} int 1\nLOOKUP_TABLE default", first.name)?;
    write_ints(w, &first.values, ascii)?;
    writeln!(w, "FIELD FieldData {}", rest.len() + cells.floats.len())?;
    for a in rest {
        writeln!(w, "{} 1 {n} int", a.name)?;
        write_ints(w, &a.values, ascii)?;
    }
    for a in &cells.floats {
        writeln!(w, "{} 1 {n} double", a.name)?;
        if ascii {
            for &v in &a.values {
                // Spelled the way C's strtod and VTK's reader accept.
                writeln!(
                    w,
                    "{}",
                    if v.is_nan() {
                        "nan".to_owned()
                    } else {
                        Exact(v).to_string()
                    }
                )?;
            }
        } else {
            a.values
                .iter()
                .try_for_each(|v| w.write_all(&v.to_be_bytes()))?;
            writeln!(w)?;
        }
    }
    Ok(())
}

fn write_ints(w: &mut dyn Write, values: &[i32], ascii: bool) -> std::io::Result<()> {
    if ascii {
        values.iter().try_for_each(|v| writeln!(w, "{v}"))
    } else {
        values
            .iter()
            .try_for_each(|v| w.write_all(&v.to_be_bytes()))?;
        writeln!(w)
    }
}
