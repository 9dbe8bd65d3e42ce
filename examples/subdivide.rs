//! Writes a control mesh subdivided `STEPS` times, its vertices at their limit positions, as a
//! triangle surface: the dense approximation `benches/subdivision_vs_polyhedral.py` meshes with
//! the polyhedral plugin and measures against.
//! `cargo run --release --example subdivide -- CONTROL.off STEPS OUT.off [loop|catmull-clark]`.
use delamesh::formats::{read_polygons, write_surface};
use delamesh::subdivision::{Scheme, SubdivisionOptions, SubdivisionOracle};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (input, steps, output) = match &args[..] {
        [_, i, s, o] | [_, i, s, o, _] => (i, s.parse::<u32>()?, o),
        _ => return Err("usage: subdivide CONTROL STEPS OUT.off [loop|catmull-clark]".into()),
    };
    let scheme = args.get(4).map(|s| s.parse::<Scheme>()).transpose()?;
    let (mesh, _) = read_polygons(input.as_ref(), None)?;
    let options = SubdivisionOptions {
        scheme,
        ..Default::default()
    };
    let oracle = SubdivisionOracle::new(&mesh, &options, &[])?;
    // Catmull–Clark patches are the faces of the control mesh once subdivided already.
    let levels = match oracle.scheme() {
        Scheme::CatmullClark => steps.saturating_sub(1),
        Scheme::Loop => steps,
    };
    let dense = oracle.subdivided(levels).triangulated();
    write_surface(output.as_ref(), &dense, &Default::default())?;
    println!("{output}: {} triangles", dense.triangles.len());
    Ok(())
}
