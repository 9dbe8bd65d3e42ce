//! VTK XML UnstructuredGrid (`.vtu`) writer: raw binary appended data by default (compact, exact, what
//! ParaView writes itself), or ASCII. Hand-written because vtkio's writer cannot emit appended raw
//! data; vtkio reads these files back in the tests.

use crate::error::Problem;
use crate::text::Exact;
use crate::vtk_cells::CellTable;
use delamesh_core::mesh::TetMesh;
use std::io::Write;

/// One DataArray: its XML attributes and its values.
enum Values<'a> {
    F64(&'a [f64]),
    I64(Vec<i64>),
    I32(&'a [i32]),
    U8(&'a [u8]),
}

impl Values<'_> {
    fn vtk_type(&self) -> &'static str {
        match self {
            Values::F64(_) => "Float64",
            Values::I64(_) => "Int64",
            Values::I32(_) => "Int32",
            Values::U8(_) => "UInt8",
        }
    }

    fn byte_len(&self) -> usize {
        match self {
            Values::F64(v) => v.len() * 8,
            Values::I64(v) => v.len() * 8,
            Values::I32(v) => v.len() * 4,
            Values::U8(v) => v.len(),
        }
    }

    fn write_raw(&self, w: &mut dyn Write) -> std::io::Result<()> {
        w.write_all(&(self.byte_len() as u64).to_le_bytes())?;
        match self {
            Values::F64(v) => v.iter().try_for_each(|x| w.write_all(&x.to_le_bytes())),
            Values::I64(v) => v.iter().try_for_each(|x| w.write_all(&x.to_le_bytes())),
            Values::I32(v) => v.iter().try_for_each(|x| w.write_all(&x.to_le_bytes())),
            Values::U8(v) => w.write_all(v),
        }
    }

    fn write_ascii(&self, w: &mut dyn Write) -> std::io::Result<()> {
        fn lines<T>(w: &mut dyn Write, v: &[T], f: impl Fn(&T) -> String) -> std::io::Result<()> {
            for chunk in v.chunks(9) {
                let row: Vec<String> = chunk.iter().map(&f).collect();
                writeln!(w, "          {}", row.join(" "))?;
            }
            Ok(())
        }
        match self {
            Values::F64(v) => lines(w, v, |x| Exact(*x).to_string()),
            Values::I64(v) => lines(w, v, i64::to_string),
            Values::I32(v) => lines(w, v, i32::to_string),
            Values::U8(v) => lines(w, v, u8::to_string),
        }
    }
}

struct Array<'a> {
    name: String,
    components: usize,
    values: Values<'a>,
}

pub(crate) fn write(w: &mut dyn Write, m: &TetMesh, ascii: bool) -> Result<(), Problem> {
    let cells = CellTable::new(m);
    let points: Vec<f64> = m.positions.iter().flat_map(|p| p.to_array()).collect();
    let points = Array {
        name: "Points".into(),
        components: 3,
        values: Values::F64(&points),
    };
    let topology = [
        Array {
            name: "connectivity".into(),
            components: 1,
            values: Values::I64(cells.connectivity.iter().map(|&v| i64::from(v)).collect()),
        },
        Array {
            name: "offsets".into(),
            components: 1,
            values: Values::I64(cells.offsets.iter().map(|&o| o as i64).collect()),
        },
        Array {
            name: "types".into(),
            components: 1,
            values: Values::U8(&cells.types),
        },
    ];
    let data: Vec<Array> = cells
        .ints
        .iter()
        .map(|a| Array {
            name: a.name.into(),
            components: 1,
            values: Values::I32(&a.values),
        })
        .chain(cells.floats.iter().map(|a| Array {
            name: a.name.clone(),
            components: 1,
            values: Values::F64(&a.values),
        }))
        .collect();

    let mut offset = 0usize;
    let mut header = |w: &mut dyn Write, a: &Array, indent: &str| -> std::io::Result<()> {
        write!(
            w,
            "{indent}<DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" ",
            a.values.vtk_type(),
            xml_escape(&a.name),
            a.components
        )?;
        if ascii {
            writeln!(w, "format=\"ascii\">")?;
            a.values.write_ascii(w)?;
            writeln!(w, "{indent}</DataArray>")
        } else {
            writeln!(w, "format=\"appended\" offset=\"{offset}\"/>")?;
            offset += 8 + a.values.byte_len();
            Ok(())
        }
    };
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    )?;
    writeln!(w, "  <UnstructuredGrid>")?;
    writeln!(
        w,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        m.positions.len(),
        cells.len()
    )?;
    writeln!(w, "      <Points>")?;
    header(w, &points, "        ")?;
    writeln!(w, "      </Points>\n      <Cells>")?;
    for a in &topology {
        header(w, a, "        ")?;
    }
    writeln!(w, "      </Cells>\n      <CellData Scalars=\"subdomain\">")?;
    for a in &data {
        header(w, a, "        ")?;
    }
    writeln!(w, "      </CellData>\n    </Piece>\n  </UnstructuredGrid>")?;
    if !ascii {
        write!(w, "  <AppendedData encoding=\"raw\">\n   _")?;
        for a in std::iter::once(&points).chain(&topology).chain(&data) {
            a.values.write_raw(w)?;
        }
        writeln!(w, "\n  </AppendedData>")?;
    }
    writeln!(w, "</VTKFile>")?;
    Ok(())
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
