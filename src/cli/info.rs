//! `delamesh info IN [--json]`: counts, bounding box, labels and the topology of a mesh's surface.

use anyhow::Result;
use delamesh_core::mesh::{Aabb, SurfaceMesh, TetMesh, Topology};
use delamesh_formats::{AnyMesh, Format};
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct InfoArgs {
    /// Mesh to describe
    input: PathBuf,
    /// Input format, when the extension does not say it
    #[arg(long, value_name = "F")]
    format: Option<Format>,
    /// Print a JSON object instead of text
    #[arg(long)]
    json: bool,
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

pub fn run(args: InfoArgs) -> Result<()> {
    let read = delamesh_formats::read(&args.input, args.format)?;
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
    let topo = surface.topology();
    let report = json!({
        "file": args.input.display().to_string(),
        "kind": kind,
        "vertices": surface.positions.len(),
        "triangles": surface.triangles.len(),
        "welded_vertices": read.welded_vertices,
        "bounding_box": bbox_json(surface.bounding_box()),
        "patches": patches_json(&surface),
        "topology": topology_json(&topo),
        "volume_mesh": volume.map_or(Value::Null, volume_json),
        "features": if volume.is_none() { features_json(&surface) } else { Value::Null },
        "warnings": read.warnings,
    });
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_text(&report, &topo);
    }
    Ok(())
}

fn print_text(r: &Value, t: &Topology) {
    let yes = |b: bool| if b { "yes" } else { "no" };
    println!(
        "{} ({})",
        r["file"].as_str().unwrap_or_default(),
        r["kind"].as_str().unwrap_or_default()
    );
    println!(
        "  vertices: {} (welded {})",
        r["vertices"], r["welded_vertices"]
    );
    println!("  triangles: {}", r["triangles"]);
    if let Some(v) = r["volume_mesh"].as_object() {
        println!(
            "  tetrahedra: {} ({} inverted)",
            v["tetrahedra"], v["inverted_tetrahedra"]
        );
        println!("  feature edges: {}", v["feature_edges"]);
        for s in v["subdomains"].as_array().into_iter().flatten() {
            println!(
                "    subdomain {}: {} tetrahedra, volume {}",
                s["id"], s["tetrahedra"], s["volume"]
            );
        }
    }
    if let Some(b) = r["bounding_box"].as_object() {
        println!("  bounding box: {} .. {}", b["min"], b["max"]);
    }
    for p in r["patches"].as_array().into_iter().flatten() {
        println!(
            "    patch {} {}: {} triangles",
            p["id"], p["name"], p["triangles"]
        );
    }
    println!(
        "  closed: {}   manifold: {}   consistently oriented: {}",
        yes(t.closed),
        yes(t.manifold),
        yes(t.orientation_consistent)
    );
    for d in t.defects() {
        println!("    {d}");
    }
    let genus = t
        .genus
        .map_or("undefined (not a closed oriented manifold)".into(), |g| {
            g.to_string()
        });
    println!(
        "  components: {}   Euler characteristic: {}   genus: {genus}",
        t.components, t.euler_characteristic
    );
    println!(
        "  signed volume: {}   degenerate triangles: {}",
        t.signed_volume, t.degenerate_triangles
    );
    if let Some(f) = r["features"].as_object() {
        println!(
            "  features at {}°: {} curves ({} closed), {} corners, {} patches",
            f["angle_deg"], f["curves"], f["closed_curves"], f["corners"], f["patches"]
        );
    }
    for w in r["warnings"].as_array().into_iter().flatten() {
        println!("  warning: {}", w.as_str().unwrap_or_default());
    }
}
