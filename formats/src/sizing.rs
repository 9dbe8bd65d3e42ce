//! Background meshes of sizing fields: a tetrahedral mesh with a scalar at every node.

use crate::error::{Error, Problem, Result};
use crate::format::Format;
use delamesh_core::mesh::{CellField, TetMesh};
use std::path::Path;

/// A tetrahedral mesh and one of its point fields.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeField {
    /// The mesh (its tets locate points; boundary and labels are unused).
    pub mesh: TetMesh,
    /// The field's name in the file.
    pub name: String,
    /// One value per node of `mesh` (NaN where a piece of the file lacks the field).
    pub values: Vec<f64>,
}

/// Reads a tetrahedral mesh with a one-component point field: the field named `name`, or the
/// only one when `name` is `None`. Errors name the fields the file has. The fields are the point
/// arrays of `.vtu` and `.vtk` files, the one-component `$NodeData` of Gmsh `.msh` files (2.2
/// and 4.1, ASCII or binary), and for a MEDIT `.mesh` the scalar `SolAtVertices` solutions of
/// the `.sol` file of the same name next to it, named `1`, `2`... by position.
pub fn read_node_field(path: &Path, name: Option<&str>) -> Result<NodeField> {
    let run = || -> Result<NodeField, Problem> {
        let format = Format::from_path(path);
        if !matches!(
            format,
            Some(Format::Vtu | Format::Vtk | Format::Msh | Format::Medit)
        ) {
            return Err(unsupported());
        }
        if path.is_dir() {
            return Err(Problem::Unsupported(
                "is a directory, not a mesh file".into(),
            ));
        }
        let bytes = std::fs::read(path)?;
        if bytes.is_empty() {
            return Err(Problem::bad("the file is empty"));
        }
        let (mesh, fields) = match format {
            Some(Format::Msh) => crate::msh_read::read(&bytes)?,
            Some(Format::Medit) => {
                let (mesh, _) = crate::medit::read(&bytes)?;
                let fields = solution_next_to(path, mesh.positions.len())?;
                (mesh, fields)
            }
            Some(f @ (Format::Vtu | Format::Vtk)) => {
                let (mesh, fields, _, _) = crate::vtk::read_cells_and_point_fields(&bytes, f)?;
                (mesh, fields)
            }
            _ => return Err(unsupported()),
        };
        if mesh.tets.is_empty() {
            return Err(Problem::Unsupported("the file holds no tetrahedra".into()));
        }
        mesh.validate()?;
        let names: Vec<&str> = fields.iter().map(|f| f.name.as_str()).collect();
        let listed = if names.is_empty() {
            "none".to_string()
        } else {
            names.join(", ")
        };
        let chosen = match name {
            Some(name) => fields.iter().find(|f| f.name == name).ok_or_else(|| {
                Problem::bad(format!(
                    "has no point field named {name:?} (its scalar point fields: {listed})"
                ))
            })?,
            None if fields.len() == 1 => &fields[0],
            None => {
                return Err(Problem::bad(format!(
                    "needs the name of its size field: it has {} scalar point fields ({listed})",
                    fields.len()
                )));
            }
        };
        Ok(NodeField {
            name: chosen.name.clone(),
            values: chosen.values.clone(),
            mesh,
        })
    };
    run().map_err(|p| Error::new(path, p))
}

fn unsupported() -> Problem {
    Problem::Unsupported(
        "a background mesh with a point field is read from .vtu, .vtk, .msh or .mesh files".into(),
    )
}

/// The scalar solutions of the `.sol` next to the MEDIT mesh `path`, one value per node.
fn solution_next_to(path: &Path, nodes: usize) -> Result<Vec<CellField>, Problem> {
    let sol = path.with_extension("sol");
    let name = sol.display();
    let bytes = std::fs::read(&sol).map_err(|e| {
        Problem::Unsupported(format!(
            "a MEDIT background mesh takes its sizes from {name} (SolAtVertices), which cannot \
             be read: {e}"
        ))
    })?;
    let fields = crate::sol::read(&bytes).map_err(|p| Problem::bad(format!("{name}: {p}")))?;
    if let Some(f) = fields.iter().find(|f| f.values.len() != nodes) {
        return Err(Problem::bad(format!(
            "{name}: {} values for the mesh's {nodes} vertices",
            f.values.len()
        )));
    }
    Ok(fields)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One tet with the point arrays `fields` (name, four values).
    fn legacy_vtk(fields: &[(&str, [f64; 4])]) -> String {
        let mut s = String::from(
            "# vtk DataFile Version 3.0\nbg\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n\
             0 0 0\n1 0 0\n0 1 0\n0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n",
        );
        if !fields.is_empty() {
            s += "POINT_DATA 4\n";
        }
        for (name, v) in fields {
            s += &format!(
                "SCALARS {name} double 1\nLOOKUP_TABLE default\n{} {} {} {}\n",
                v[0], v[1], v[2], v[3]
            );
        }
        s
    }

    fn read(text: &str, name: Option<&str>) -> Result<NodeField> {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("bg.vtk");
        std::fs::write(&path, text).expect("written");
        read_node_field(&path, name)
    }

    #[test]
    fn the_only_field_or_the_named_one_is_read() {
        let one = read(&legacy_vtk(&[("h", [1.0, 2.0, 3.0, 4.0])]), None).expect("one field");
        assert_eq!(one.name, "h");
        assert_eq!(one.values, vec![1.0, 2.0, 3.0, 4.0]);
        assert_eq!(one.mesh.tets.len(), 1);
        let two = legacy_vtk(&[("a", [1.0; 4]), ("b", [2.0; 4])]);
        assert_eq!(read(&two, Some("b")).expect("named").values, vec![2.0; 4]);
        let e = read(&two, None)
            .expect_err("two fields, no name")
            .to_string();
        assert!(e.contains("bg.vtk") && e.contains("a, b"), "{e}");
        let e = read(&two, Some("c")).expect_err("missing name").to_string();
        assert!(e.contains("\"c\"") && e.contains("a, b"), "{e}");
        let e = read(&legacy_vtk(&[]), None)
            .expect_err("no field")
            .to_string();
        assert!(e.contains("none"), "{e}");
    }
}
