//! `delamesh info IN [--json]`: counts, bounding box, labels and the topology of a mesh's surface,
//! or the grid, values and labels of a 3D image (the description is the library's
//! [`delamesh::info`]; this module prints it).

use super::output::outln;
use anyhow::Result;
use delamesh_core::mesh::Topology;
use delamesh_formats::Format;
use serde_json::Value;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct InfoArgs {
    /// Mesh or 3D image to describe
    input: PathBuf,
    /// Input format, when the extension does not say it
    #[arg(long, value_name = "F")]
    format: Option<Format>,
    /// Print a JSON object instead of text
    #[arg(long)]
    json: bool,
}

pub fn run(args: InfoArgs) -> Result<()> {
    let info = delamesh::info::describe(&args.input, args.format)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&info.json)?)?;
    } else {
        match &info.topology {
            Some(topology) => print_text(&info.json, topology)?,
            None => print_image(&info.json)?,
        }
    }
    Ok(())
}

fn print_image(r: &Value) -> std::io::Result<()> {
    let d = &r["dimensions"];
    outln!("{} (image)", r["file"].as_str().unwrap_or_default())?;
    outln!(
        "  dimensions: {} x {} x {} ({} voxels of {})",
        d[0],
        d[1],
        d[2],
        r["voxels"],
        r["voxel_type"].as_str().unwrap_or_default()
    )?;
    outln!(
        "  voxel size: {}   origin: {}",
        r["voxel_size"],
        r["origin"]
    )?;
    if let Some(b) = r["bounding_box"].as_object() {
        outln!(
            "  bounding box (voxel centres): {} .. {}",
            b["min"],
            b["max"]
        )?;
    }
    if let Some(v) = r["values"].as_object() {
        outln!("  values: {} .. {}", v["min"], v["max"])?;
    }
    match r["labels"].as_array() {
        Some(labels) => {
            outln!(
                "  labels: {} (0 is the background by default)",
                labels.len()
            )?;
            for l in labels {
                outln!(
                    "    label {}: {} voxels, volume {}",
                    l["value"],
                    l["voxels"],
                    l["volume"]
                )?;
            }
        }
        None => outln!("  gray levels, not labels: mesh them with --isovalue V")?,
    }
    Ok(())
}

fn print_text(r: &Value, t: &Topology) -> std::io::Result<()> {
    let yes = |b: bool| if b { "yes" } else { "no" };
    outln!(
        "{} ({})",
        r["file"].as_str().unwrap_or_default(),
        r["kind"].as_str().unwrap_or_default()
    )?;
    outln!(
        "  vertices: {} (welded {})",
        r["vertices"],
        r["welded_vertices"]
    )?;
    outln!("  triangles: {}", r["triangles"])?;
    if let Some(v) = r["volume_mesh"].as_object() {
        outln!(
            "  tetrahedra: {} ({} inverted)",
            v["tetrahedra"],
            v["inverted_tetrahedra"]
        )?;
        outln!("  feature edges: {}", v["feature_edges"])?;
        for s in v["subdomains"].as_array().into_iter().flatten() {
            outln!(
                "    subdomain {}: {} tetrahedra, volume {}",
                s["id"],
                s["tetrahedra"],
                s["volume"]
            )?;
        }
    }
    if let Some(b) = r["bounding_box"].as_object() {
        outln!("  bounding box: {} .. {}", b["min"], b["max"])?;
    }
    for p in r["patches"].as_array().into_iter().flatten() {
        outln!(
            "    patch {} {}: {} triangles",
            p["id"],
            p["name"],
            p["triangles"]
        )?;
    }
    outln!(
        "  closed: {}   manifold: {}   consistently oriented: {}",
        yes(t.closed),
        yes(t.manifold),
        yes(t.orientation_consistent)
    )?;
    for d in t.defects() {
        outln!("    {d}")?;
    }
    let genus = t
        .genus
        .map_or("undefined (not a closed oriented manifold)".into(), |g| {
            g.to_string()
        });
    outln!(
        "  components: {}   Euler characteristic: {}   genus: {genus}",
        t.components,
        t.euler_characteristic
    )?;
    outln!(
        "  signed volume: {}   degenerate triangles: {}",
        t.signed_volume,
        t.degenerate_triangles
    )?;
    if let Some(f) = r["features"].as_object() {
        outln!(
            "  features at {}°: {} curves ({} closed), {} corners, {} patches",
            f["angle_deg"],
            f["curves"],
            f["closed_curves"],
            f["corners"],
            f["patches"]
        )?;
    }
    if let Some(rep) = r["repairs"].as_object() {
        println!(
            "  self-intersecting triangles: {}   duplicate triangles: {}",
            rep["self_intersecting_triangles"], rep["duplicate_triangles"]
        );
        let summary: Vec<&str> = rep["summary"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|x| x.as_str())
            .collect();
        if !summary.is_empty() {
            println!(
                "  mesh repairs (refused with --strict): {}",
                summary.join("; ")
            );
        }
    }
    for w in r["warnings"].as_array().into_iter().flatten() {
        outln!("  warning: {}", w.as_str().unwrap_or_default())?;
    }
    Ok(())
}
