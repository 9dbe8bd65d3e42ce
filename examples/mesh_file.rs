//! Meshes the inside of a closed surface file: `cargo run --release --example mesh_file -- IN OUT`.
use delamesh::{MeshSettings, Mesher};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let [_, input, output] = &std::env::args().collect::<Vec<_>>()[..] else {
        return Err("usage: mesh_file IN.stl OUT.vtu".into());
    };
    let settings = MeshSettings::builder().facet_angle(25.0).build()?;
    let mut meshed = Mesher::new(settings).mesh_file(input.as_ref())?;
    meshed.write(output.as_ref(), &Default::default())?;
    let report = meshed.report();
    let (tets, angle) = (report.counts.tets, report.quality.min_dihedral_deg);
    println!("{output}: {tets} tetrahedra, smallest dihedral angle {angle:.1}°");
    Ok(())
}
