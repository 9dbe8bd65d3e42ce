//! The file formats delamesh knows, chosen by extension or by name.

use std::fmt;
use std::path::Path;
use std::str::FromStr;

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// STL, ASCII or binary.
    Stl,
    /// Wavefront OBJ.
    Obj,
    /// Stanford PLY, ASCII or binary.
    Ply,
    /// Object File Format (`.off`).
    Off,
    /// glTF 2.0 JSON (`.gltf`) or binary (`.glb`); the reader tells them apart by magic.
    Gltf,
    /// Legacy VTK (`.vtk`).
    Vtk,
    /// VTK XML unstructured grid (`.vtu`).
    Vtu,
    /// VTK XML poly data (`.vtp`), read only.
    Vtp,
    /// MEDIT / INRIA `.mesh`.
    Medit,
    /// Gmsh `.msh`, written only.
    Msh,
}

/// Name, extensions; the first extension is the canonical one.
const TABLE: &[(Format, &str, &[&str])] = &[
    (Format::Stl, "stl", &["stl"]),
    (Format::Obj, "obj", &["obj"]),
    (Format::Ply, "ply", &["ply"]),
    (Format::Off, "off", &["off"]),
    (Format::Gltf, "gltf", &["gltf", "glb"]),
    (Format::Vtk, "vtk", &["vtk"]),
    (Format::Vtu, "vtu", &["vtu"]),
    (Format::Vtp, "vtp", &["vtp"]),
    (Format::Medit, "mesh", &["mesh", "medit"]),
    (Format::Msh, "msh", &["msh"]),
];

impl Format {
    /// Every format.
    pub const ALL: [Format; 10] = [
        Format::Stl,
        Format::Obj,
        Format::Ply,
        Format::Off,
        Format::Gltf,
        Format::Vtk,
        Format::Vtu,
        Format::Vtp,
        Format::Medit,
        Format::Msh,
    ];

    /// The format named by the path's extension, case-insensitively.
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        TABLE
            .iter()
            .find(|(_, _, exts)| exts.contains(&ext.as_str()))
            .map(|(f, _, _)| *f)
    }

    /// The format's name, as `--format` takes it.
    pub fn name(self) -> &'static str {
        TABLE
            .iter()
            .find(|(f, _, _)| *f == self)
            .map_or("?", |(_, n, _)| n)
    }

    /// Can hold tetrahedra (and boundary triangles with labels).
    pub fn is_volume(self) -> bool {
        matches!(
            self,
            Format::Vtk | Format::Vtu | Format::Medit | Format::Msh
        )
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown `--format` name.
#[derive(Debug, thiserror::Error)]
#[error("unknown format {0:?} (known: stl, obj, ply, off, gltf, glb, vtk, vtu, vtp, mesh, msh)")]
pub struct UnknownFormat(pub String);

impl FromStr for Format {
    type Err = UnknownFormat;

    fn from_str(s: &str) -> Result<Format, UnknownFormat> {
        let s = s.trim_start_matches('.').to_ascii_lowercase();
        TABLE
            .iter()
            .find(|(_, name, exts)| *name == s || exts.contains(&s.as_str()))
            .map(|(f, _, _)| *f)
            .ok_or(UnknownFormat(s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extension_is_case_insensitive_and_names_parse() {
        assert_eq!(Format::from_path(Path::new("a/B.STL")), Some(Format::Stl));
        assert_eq!(Format::from_path(Path::new("x.GlB")), Some(Format::Gltf));
        assert_eq!(Format::from_path(Path::new("x.mesh")), Some(Format::Medit));
        assert_eq!(Format::from_path(Path::new("x.txt")), None);
        assert_eq!(Format::from_path(Path::new("noext")), None);
        for f in Format::ALL {
            assert_eq!(f.name().parse::<Format>().ok(), Some(f));
        }
        assert!("docx".parse::<Format>().is_err());
    }
}
