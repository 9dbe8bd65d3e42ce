//! Meshing through a plugin loaded at run time gives exactly the mesh of the same oracle linked
//! statically: the C ABI changes nothing but the call path.

mod plugins_support;
use plugins_support as common;

use delamesh::core::complex::MeshComplex;
use delamesh::core::oracle::Oracle;
use delamesh::core::plugin::{PluginLibrary, PluginOracle};
use delamesh::core::refine::criteria::{MeshCriteria, Sizing};
use delamesh::core::refine::{MeshOptions, mesh_domain};
use delamesh_implicit::ImplicitOracle;

/// Coarse criteria so the test stays fast; the comparison does not depend on resolution.
fn options(oracle: &dyn Oracle) -> MeshOptions {
    let mut criteria = MeshCriteria::default_for(&oracle.bounding_box());
    let d = oracle.bounding_box().diagonal();
    criteria.facet.size = Sizing::Constant(d / 8.0);
    criteria.facet.distance = Sizing::Constant(d / 100.0);
    criteria.cell.size = Sizing::Constant(d / 8.0);
    MeshOptions {
        criteria,
        limits: Default::default(),
        keep_partial: false,
        validity: Default::default(),
        optimize: delamesh_core::optimize::OptimizeOptions::default(),
    }
}

fn mesh(oracle: &dyn Oracle) -> MeshComplex {
    mesh_domain(oracle, &options(oracle), &mut |_| {})
        .expect("the domain meshes")
        .complex
}

#[test]
fn implicit_plugin_meshes_bit_for_bit_like_the_static_oracle() {
    let library =
        PluginLibrary::open(&common::implicit_plugin()).expect("the example plugin loads");
    for config in ["shape=sphere radius=1", "shape=torus major=1 minor=0.4"] {
        let direct = ImplicitOracle::from_config(config).expect("valid config");
        let loaded = library.create(config).expect("valid config");
        let (a, b) = (mesh(&direct), mesh(&loaded));
        loaded.check().expect("no plugin fault while meshing");
        assert!(
            !a.tets.is_empty() && !a.facets.is_empty(),
            "{config}: the mesh must not be empty"
        );
        let bits = |c: &MeshComplex| {
            c.points
                .iter()
                .flat_map(|p| p.to_array().map(f64::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&a), bits(&b), "{config}: vertices");
        assert_eq!(
            (&a.tets, &a.tet_subdomain),
            (&b.tets, &b.tet_subdomain),
            "{config}: tetrahedra"
        );
        assert_eq!(
            (&a.facets, &a.facet_patch),
            (&b.facets, &b.facet_patch),
            "{config}: boundary facets"
        );
    }
}

/// A unit cube, outward-oriented triangles, as OFF.
const CUBE_OFF: &str = "OFF\n8 12 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n\
    3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n";

fn delamesh() -> assert_cmd::Command {
    let mut command = assert_cmd::Command::new(common::delamesh_bin());
    command
        .env_remove("DELAMESH_PLUGIN_PATH")
        .arg("mesh")
        .arg("--quiet");
    command
}

#[test]
fn polyhedral_plugin_library_writes_the_bytes_of_the_built_in_oracle() {
    let library = common::rust_plugin("delamesh-polyhedral", "delamesh_polyhedral", &["cdylib"]);
    let dir = tempfile::tempdir().expect("temporary directory");
    let cube = dir.path().join("cube.off");
    std::fs::write(&cube, CUBE_OFF).expect("write the cube");
    let (built_in, loaded) = (
        dir.path().join("built-in.vtu"),
        dir.path().join("loaded.vtu"),
    );
    // The polyhedral oracle is the smooth one: the cube's edges are no features.
    delamesh()
        .arg(&cube)
        .arg("--no-features")
        .arg("-o")
        .arg(&built_in)
        .assert()
        .success();
    delamesh()
        .arg("--plugin")
        .arg(&library)
        .arg("--plugin-config")
        .arg(&cube)
        .arg("-o")
        .arg(&loaded)
        .assert()
        .success();
    let (a, b) = (
        std::fs::read(&built_in).expect("static output"),
        std::fs::read(&loaded).expect("dynamic output"),
    );
    assert!(!a.is_empty());
    assert!(a == b, "static and dynamic meshes of the same cube differ");
}

#[test]
fn piecewise_smooth_plugin_library_writes_the_bytes_of_the_default_oracle() {
    let library = common::rust_plugin(
        "delamesh-piecewise-smooth",
        "delamesh_piecewise_smooth",
        &["cdylib"],
    );
    let dir = tempfile::tempdir().expect("temporary directory");
    let cube = dir.path().join("cube.off");
    std::fs::write(&cube, CUBE_OFF).expect("write the cube");
    let (built_in, loaded) = (
        dir.path().join("built-in.vtu"),
        dir.path().join("loaded.vtu"),
    );
    delamesh()
        .arg(&cube)
        .args(["--feature-angle", "45"])
        .arg("-o")
        .arg(&built_in)
        .assert()
        .success();
    delamesh()
        .arg("--plugin")
        .arg(&library)
        .arg("--plugin-config")
        .arg(format!("{}\nfeature-angle=45", cube.display()))
        .arg("-o")
        .arg(&loaded)
        .assert()
        .success();
    let (a, b) = (
        std::fs::read(&built_in).expect("static output"),
        std::fs::read(&loaded).expect("dynamic output"),
    );
    assert!(!a.is_empty());
    assert!(a == b, "static and dynamic meshes of the same cube differ");
    // A bad configuration is reported, naming the problem.
    let bad = delamesh()
        .arg("--plugin")
        .arg(&library)
        .arg("--plugin-config")
        .arg(format!("{}\nfeature-angle=wide", cube.display()))
        .arg("-o")
        .arg(dir.path().join("bad.vtu"))
        .assert()
        .failure()
        .get_output()
        .stderr
        .clone();
    let bad = String::from_utf8_lossy(&bad);
    assert!(bad.contains("feature-angle"), "{bad}");
}

#[test]
fn c_plugin_meshes_its_ball_from_the_command_line() {
    let library = common::c_plugin("examples/plugins/c-sphere/sphere.c", &[]);
    let dir = tempfile::tempdir().expect("temporary directory");
    let output = dir.path().join("ball.vtu");
    delamesh()
        .arg("--plugin")
        .arg(&library)
        .args(["--plugin-config", "radius=2 center=1,0,0", "-o"])
        .arg(&output)
        .assert()
        .success();
    let mesh = delamesh::formats::read_tet_mesh(&output, None).expect("the output reads back");
    let center = delamesh::core::kernel::Point3::X;
    assert!(!mesh.tets.is_empty());
    assert!(
        mesh.positions
            .iter()
            .all(|p| p.distance(center) <= 2.0 * (1.0 + 1e-9)),
        "vertices outside the ball"
    );
    let volume: f64 = mesh
        .tets
        .iter()
        .map(|t| {
            let [a, b, c, d] = t.map(|v| mesh.positions[v as usize]);
            let six_volume = (b - a).cross(c - a).dot(d - a);
            assert!(
                six_volume > 0.0,
                "tetrahedron {t:?} is not positively oriented"
            );
            six_volume / 6.0
        })
        .sum();
    let ball = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
    // An inscribed polyhedron: less than the ball, and close to it at the default resolution.
    assert!(
        volume < ball && volume > 0.9 * ball,
        "volume {volume} vs ball {ball}"
    );
}

#[test]
fn a_fault_in_the_middle_of_meshing_fails_without_writing() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let output = dir.path().join("never.vtu");
    let run = delamesh()
        .arg("--plugin")
        .arg(common::faulty_plugin())
        .args(["--plugin-config", "fault=panic-after-200", "-o"])
        .arg(&output)
        .output()
        .expect("delamesh runs");
    assert_eq!(run.status.code(), Some(1), "{run:?}");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("`faulty`")
            && stderr.contains("after 200 points")
            && stderr.contains("nothing was written"),
        "{stderr}"
    );
    assert!(!output.exists(), "a faulty run must not leave an output");
}
