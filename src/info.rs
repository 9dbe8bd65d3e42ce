//! What `delamesh info --json` prints about a mesh file: counts, bounding box, patches, the
//! topology of its surface, labels of a volume mesh, and what `mesh` would find (sharp
//! features) or repair; about a 3D image: its grid, voxel size, values and labels. Shared by the
//! command line and the bindings (feature `json`).

use crate::error::Error;
use delamesh_core::mesh::{Aabb, SurfaceMesh, TetMesh, Topology};
use delamesh_formats::image::{Image, ScalarType, Voxels, is_image_path, read_image};
use delamesh_formats::{AnyMesh, Format};
use delamesh_image_label::label_value;
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::path::Path;

/// The description of one mesh file.
pub struct Info {
    /// The JSON object of `delamesh info --json`.
    pub json: Value,
    /// The topology of the file's surface (a volume mesh's boundary), for a text summary; none
    /// for an image.
    pub topology: Option<Topology>,
}

/// Reads the mesh or 3D image in `path` (`format` when the extension does not say it) and
/// describes it.
pub fn describe(path: &Path, format: Option<Format>) -> Result<Info, Error> {
    if format.is_none() && is_image_path(path) {
        return Ok(describe_image(path, &read_image(path)?));
    }
    let read = delamesh_formats::read(path, format)?;
    let (surface, volume, kind) = match &read.mesh {
        AnyMesh::Surface(s) => (s.clone(), None, "surface"),
        AnyMesh::Volume(v) => {
            let mut boundary = v.clone();
            if boundary.boundary.is_empty() {
                boundary.boundary = v.exterior_faces();
                boundary.boundary_patches = vec![Default::default(); boundary.boundary.len()];
            }
            (boundary.boundary_surface(), Some(v), "volume")
        }
    };
    let topology = surface.topology();
    let json = json!({
        "file": path.display().to_string(),
        "kind": kind,
        "vertices": surface.positions.len(),
        "triangles": surface.triangles.len(),
        "welded_vertices": read.welded_vertices,
        "bounding_box": bbox_json(surface.bounding_box()),
        "patches": patches_json(&surface),
        "topology": topology_json(&topology),
        "volume_mesh": volume.map_or(Value::Null, volume_json),
        "features": if volume.is_none() { features_json(&surface) } else { Value::Null },
        "repairs": if volume.is_none() { repairs_json(&surface) } else { Value::Null },
        "warnings": read.warnings,
    });
    Ok(Info {
        json,
        topology: Some(topology),
    })
}

/// Distinct values past which an image is described as gray levels rather than labels: the
/// mesher's limit on labels, plus the background.
const MAX_LISTED_LABELS: usize = delamesh_image_label::MAX_LABELS + 1;

/// The grid, voxel size, value range and (for integer values) labels of an image.
fn describe_image(path: &Path, image: &Image) -> Info {
    let m = image.index_to_world;
    let voxel_volume = m.matrix3.determinant().abs();
    let [nx, ny, nz] = image.dims.map(|n| n.saturating_sub(1) as f64);
    let corners: Vec<glam::DVec3> = (0..8)
        .map(|k| {
            let pick = |bit: usize, n: f64| if k & bit == 0 { 0.0 } else { n };
            m.transform_point3(glam::DVec3::new(pick(1, nx), pick(2, ny), pick(4, nz)))
        })
        .collect();
    let bbox = Aabb::of(&corners);
    let values = &image.voxels;
    let (min, max) = (0..values.len())
        .map(|i| values.value(i))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    let labels = label_counts(values, min, max).map(|counts| {
        counts
            .into_iter()
            .map(|(value, voxels)| {
                json!({"value": value, "voxels": voxels, "volume": voxels as f64 * voxel_volume})
            })
            .collect::<Vec<_>>()
    });
    let json = json!({
        "file": path.display().to_string(),
        "kind": "image",
        "dimensions": image.dims,
        "voxels": values.len(),
        "voxel_type": scalar_name(values.scalar_type()),
        "voxel_size": image.spacing().to_array(),
        "origin": m.translation.to_array(),
        "bounding_box": bbox_json(bbox),
        "values": if values.is_empty() { Value::Null } else { json!({"min": min, "max": max}) },
        "labels": labels,
    });
    Info {
        json,
        topology: None,
    }
}

/// The voxel count of each value, when the image is a label map as `delamesh mesh` reads one
/// (non-negative integers below 2³², at most [`MAX_LISTED_LABELS`] distinct ones); `None` for
/// gray levels. `min` and `max` are the values' range.
fn label_counts(values: &Voxels, min: f64, max: f64) -> Option<BTreeMap<u32, u64>> {
    let (lo, hi) = (label_value(min)?, label_value(max)?);
    if values.is_empty() {
        return None;
    }
    let mut counts = BTreeMap::new();
    if ((hi - lo) as usize) < 2 * MAX_LISTED_LABELS {
        // A table over the range (at most 2 × MAX_LISTED_LABELS entries), then its non-zero entries.
        let mut table = vec![0u64; (hi - lo) as usize + 1];
        for i in 0..values.len() {
            table[(label_value(values.value(i))? - lo) as usize] += 1;
        }
        let present = table.iter().enumerate().filter(|&(_, &n)| n > 0);
        counts.extend(present.map(|(k, &n)| (lo + k as u32, n)));
    } else {
        for i in 0..values.len() {
            if counts.len() > MAX_LISTED_LABELS {
                return None;
            }
            *counts.entry(label_value(values.value(i))?).or_insert(0) += 1;
        }
    }
    (counts.len() <= MAX_LISTED_LABELS).then_some(counts)
}

fn scalar_name(t: ScalarType) -> &'static str {
    match t {
        ScalarType::U8 => "uint8",
        ScalarType::I8 => "int8",
        ScalarType::U16 => "uint16",
        ScalarType::I16 => "int16",
        ScalarType::U32 => "uint32",
        ScalarType::I32 => "int32",
        ScalarType::F32 => "float32",
        ScalarType::F64 => "float64",
    }
}

fn bbox_json(b: Option<Aabb>) -> Value {
    b.map_or(
        Value::Null,
        |b| json!({"min": b.min.to_array(), "max": b.max.to_array()}),
    )
}

fn topology_json(t: &Topology) -> Value {
    json!({
        "closed": t.closed,
        "manifold": t.manifold,
        "orientation_consistent": t.orientation_consistent,
        "watertight": t.is_watertight(),
        "boundary_edges": t.boundary_edges,
        "non_manifold_edges": t.non_manifold_edges,
        "non_manifold_vertices": t.non_manifold_vertices,
        "misoriented_edges": t.misoriented_edges,
        "edges": t.edges,
        "components": t.components,
        "euler_characteristic": t.euler_characteristic,
        "genus": t.genus,
        "signed_volume": t.signed_volume,
        "degenerate_triangles": t.degenerate_triangles,
        "unused_vertices": t.unused_vertices,
    })
}

/// Triangle count per patch, with names.
fn patches_json(s: &SurfaceMesh) -> Value {
    let mut count = vec![0usize; s.patch_names.len()];
    for p in &s.patches {
        if let Some(c) = count.get_mut(p.0 as usize) {
            *c += 1;
        }
    }
    Value::Array(
        s.patch_names
            .iter()
            .zip(count)
            .enumerate()
            .filter(|(_, (_, n))| *n > 0)
            .map(|(id, (name, n))| json!({"id": id, "name": name, "triangles": n}))
            .collect(),
    )
}

fn volume_json(v: &TetMesh) -> Value {
    let mut per_subdomain: BTreeMap<u32, (usize, f64)> = BTreeMap::new();
    let mut inverted = 0;
    for (t, s) in v.subdomains.iter().enumerate() {
        let vol = v.tet_volume(t);
        inverted += usize::from(vol <= 0.0);
        let e = per_subdomain.entry(s.0).or_default();
        e.0 += 1;
        e.1 += vol;
    }
    let subdomains: Vec<Value> = per_subdomain
        .into_iter()
        .map(|(id, (n, vol))| json!({"id": id, "tetrahedra": n, "volume": vol}))
        .collect();
    let fields: Vec<&str> = v.cell_fields.iter().map(|f| f.name.as_str()).collect();
    json!({
        "tetrahedra": v.tets.len(),
        "boundary_triangles": v.boundary.len(),
        "feature_edges": v.feature_edges.len(),
        "subdomains": subdomains,
        "inverted_tetrahedra": inverted,
        "cell_fields": fields,
    })
}

/// Sharp features at the default angle, as `delamesh mesh` would find them (surfaces only).
fn features_json(s: &SurfaceMesh) -> Value {
    use delamesh_piecewise_smooth::{DEFAULT_FEATURE_ANGLE_DEG, FeatureOptions, Features};
    match Features::extract(s, &FeatureOptions::default(), &[]) {
        Ok(f) => json!({
            "angle_deg": DEFAULT_FEATURE_ANGLE_DEG,
            "curves": f.curves.len(),
            "closed_curves": f.curves.iter().filter(|c| c.closed).count(),
            "corners": f.corners.len(),
            "patches": f.num_patches,
        }),
        Err(_) => Value::Null,
    }
}

/// What `mesh` would repair or reinterpret (the classes `--strict` refuses), for a surface.
fn repairs_json(s: &SurfaceMesh) -> Value {
    let n = s.positions.len();
    if s.triangles.iter().flatten().any(|&v| v as usize >= n) {
        return Value::Null;
    }
    let r = delamesh_polyhedral::diagnose(&s.positions, &s.triangles);
    json!({
        "zero_area_triangles": r.degenerate_dropped,
        "duplicate_triangles": r.duplicates_dropped,
        "triangles_to_reorient": r.flipped,
        "border_edges": r.border_edges,
        "non_manifold_edges": r.non_manifold_edges,
        "self_intersecting_triangles": r.crossing_triangles,
        "summary": r.describe(),
    })
}
