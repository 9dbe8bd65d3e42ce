//! Background meshes of sizing fields: a tetrahedral mesh with a scalar at every node.

use crate::error::{Error, Problem, Result};
use crate::format::Format;
use delamesh_core::mesh::TetMesh;
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

/// Reads a tetrahedral mesh with a one-component point field (`.vtu`, `.vtk`): the field named
/// `name`, or the only one when `name` is `None`. Errors name the fields the file has.
pub fn read_node_field(path: &Path, name: Option<&str>) -> Result<NodeField> {
    let run = || -> Result<NodeField, Problem> {
        let format = Format::from_path(path);
        let format = match format {
            Some(f @ (Format::Vtu | Format::Vtk)) => f,
            _ => {
                return Err(Problem::Unsupported(
                    "a background mesh with a point field is read from .vtu or .vtk files".into(),
                ));
            }
        };
        if path.is_dir() {
            return Err(Problem::Unsupported(
                "is a directory, not a mesh file".into(),
            ));
        }
        let bytes = std::fs::read(path)?;
        if bytes.is_empty() {
            return Err(Problem::bad("the file is empty"));
        }
        let (mesh, fields, _, _) = crate::vtk::read_cells_and_point_fields(&bytes, format)?;
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
