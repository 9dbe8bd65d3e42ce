//! `delamesh mesh IMAGE` end to end: a segmented image made here, recognised by its extension,
//! meshed with defaults drawn from its size; bad images and options refused without output.

mod cli_support;

use cli_support::delamesh;
use std::io::Write;
use std::path::Path;

/// The labels of two nested balls (2 inside 5, background 0) in a 20³ grid, x fastest.
fn nested_balls() -> Vec<u8> {
    let n = 20usize;
    let mut labels = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let d = [i, j, k].map(|v| v as f64 - 9.5);
                let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                labels.push(if r < 4.0 {
                    2
                } else if r < 8.0 {
                    5
                } else {
                    0
                });
            }
        }
    }
    labels
}

/// A gzipped INR image of [`nested_balls`] with voxels of 0.5.
fn write_nested_balls(path: &Path) {
    let n = 20usize;
    let mut bytes = format!(
        "#INRIMAGE-4#{{\nXDIM={n}\nYDIM={n}\nZDIM={n}\nVDIM=1\nTYPE=unsigned fixed\nPIXSIZE=8 bits\nCPU=decm\nVX=0.5\nVY=0.5\nVZ=0.5\n"
    )
    .into_bytes();
    bytes.resize(252, b'\n');
    bytes.extend_from_slice(b"##}\n");
    bytes.extend(nested_balls());
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(&bytes).expect("in memory");
    std::fs::write(path, gz.finish().expect("in memory")).expect("write image");
}

/// What `delamesh info --json` says of `path`.
fn info_json(path: &Path) -> serde_json::Value {
    let out = delamesh()
        .args(["info", "--json"])
        .arg(path)
        .assert()
        .success();
    serde_json::from_slice(&out.get_output().stdout).expect("JSON")
}

#[test]
fn info_describes_an_image_grid_and_its_labels() {
    let dir = tempfile::tempdir().expect("temp dir");
    let image = dir.path().join("balls.inr.gz");
    write_nested_balls(&image);
    let info = info_json(&image);
    assert_eq!(info["kind"], "image");
    assert_eq!(info["dimensions"], serde_json::json!([20, 20, 20]));
    assert_eq!(info["voxel_size"], serde_json::json!([0.5, 0.5, 0.5]));
    assert_eq!(info["voxel_type"], "uint8");
    assert_eq!(
        info["bounding_box"]["max"],
        serde_json::json!([9.5, 9.5, 9.5])
    );
    let labels = nested_balls();
    let listed = info["labels"].as_array().expect("a label map");
    assert_eq!(listed.len(), 3);
    for (entry, value) in listed.iter().zip([0u8, 2, 5]) {
        let count = labels.iter().filter(|&&l| l == value).count() as u64;
        assert_eq!(entry["value"], u64::from(value));
        assert_eq!(entry["voxels"], count);
        assert_eq!(entry["volume"].as_f64(), Some(count as f64 * 0.125));
    }
    // The text form says the same, and gray levels are told apart from labels.
    let text = delamesh()
        .arg("info")
        .arg(&image)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let text = String::from_utf8(text).expect("UTF-8");
    assert!(
        text.contains("20 x 20 x 20") && text.contains("label 5: "),
        "{text}"
    );
    let gray = dir.path().join("ramp.nrrd");
    let mut bytes =
        b"NRRD0004\ntype: float\ndimension: 3\nsizes: 3 3 3\nencoding: raw\nendian: little\n\n"
            .to_vec();
    for i in 0..27 {
        bytes.extend_from_slice(&(0.25 + 0.5 * i as f32).to_le_bytes());
    }
    std::fs::write(&gray, bytes).expect("write image");
    let info = info_json(&gray);
    assert_eq!(info["labels"], serde_json::Value::Null);
    assert_eq!(info["values"]["max"], 13.25);
    // Negative integers are no labels to the mesher either: gray levels, as `mesh` refuses them.
    let signed = dir.path().join("signed.nrrd");
    let mut bytes =
        b"NRRD0004\ntype: short\ndimension: 3\nsizes: 3 3 3\nencoding: raw\nendian: little\n\n"
            .to_vec();
    for i in 0..27i16 {
        bytes.extend_from_slice(&(i % 5 - 2).to_le_bytes());
    }
    std::fs::write(&signed, bytes).expect("write image");
    assert_eq!(info_json(&signed)["labels"], serde_json::Value::Null);
    delamesh()
        .arg("mesh")
        .arg(&signed)
        .arg("-o")
        .arg(dir.path().join("signed.vtu"))
        .assert()
        .failure();
}

#[test]
fn an_image_is_meshed_with_its_label_values_as_subdomains() {
    let dir = tempfile::tempdir().expect("temp dir");
    let image = dir.path().join("balls.inr.gz");
    write_nested_balls(&image);
    let out = dir.path().join("balls.mesh");
    let report = dir.path().join("balls.json");
    delamesh()
        .args(["mesh", "-q"])
        .arg(&image)
        .arg("-o")
        .arg(&out)
        .args(["--cell-size-per-label", "2=0.8", "--report"])
        .arg(&report)
        .assert()
        .success();
    // The report gives each label's volume: balls of 4 and 8 voxels of 0.5 (the shell is the
    // big ball less the small one), to a tenth (the interpolation and the facets cut the
    // corners of a ball four voxels wide); no input surface to compare with.
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&report).expect("report written")).expect("JSON");
    let ball = |radius: f64| 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    let volumes: Vec<(u64, f64)> = r["subdomains"]
        .as_array()
        .expect("subdomains")
        .iter()
        .map(|s| {
            (
                s["subdomain"].as_u64().expect("label"),
                s["volume"].as_f64().expect("volume"),
            )
        })
        .collect();
    assert_eq!(volumes.iter().map(|v| v.0).collect::<Vec<_>>(), [2, 5]);
    // They are the written mesh's: its tets of each label, summed here.
    let mesh = delamesh_formats::read_tet_mesh(&out, None).expect("mesh readable");
    for &(label, volume) in &volumes {
        let summed: f64 = (0..mesh.tets.len())
            .filter(|&t| u64::from(mesh.subdomains[t].0) == label)
            .map(|t| mesh.tet_volume(t))
            .sum();
        assert!(
            (summed - volume).abs() <= 1e-9 * volume,
            "{summed} vs {volume}"
        );
    }
    for ((_, volume), expected) in volumes.iter().zip([ball(2.0), ball(4.0) - ball(2.0)]) {
        assert!(
            (volume / expected - 1.0).abs() < 0.1,
            "{volume} vs {expected}"
        );
    }
    assert!(r.get("approximation").is_none());
    assert_eq!(r["boundary"]["closed"], true);
    assert_eq!(r["quality"]["inverted_tets"], 0);
    let text = std::fs::read_to_string(&out).expect("output written");
    // MEDIT tetrahedra lines end with their subdomain: the labels 2 and 5 themselves.
    let tets = text.split("Tetrahedra").nth(1).expect("tetrahedra");
    let mut labels: Vec<&str> = tets
        .lines()
        .skip(2)
        .take_while(|l| l.split_whitespace().count() == 5)
        .filter_map(|l| l.split_whitespace().last())
        .collect();
    labels.sort_unstable();
    labels.dedup();
    assert_eq!(labels, ["2", "5"]);
}

#[test]
fn the_built_in_image_plugin_loads_by_name_and_meshes_the_labels() {
    let dir = tempfile::tempdir().expect("temp dir");
    let image = dir.path().join("balls.inr.gz");
    write_nested_balls(&image);
    let out = dir.path().join("balls.mesh");
    delamesh()
        .args(["mesh", "-q", "--plugin", "image-label", "--plugin-config"])
        .arg(&image)
        .arg("-o")
        .arg(&out)
        .args(["--cell-size", "1.5", "--facet-size", "1.5"])
        .assert()
        .success();
    let mesh = delamesh_formats::read_tet_mesh(&out, None).expect("mesh readable");
    let mut labels: Vec<u32> = mesh.subdomains.iter().map(|s| s.0).collect();
    labels.sort_unstable();
    labels.dedup();
    assert_eq!(labels, [2, 5]);
}

#[test]
fn bad_images_and_options_fail_with_one_line_and_no_output() {
    let dir = tempfile::tempdir().expect("temp dir");
    let good = dir.path().join("balls.inr.gz");
    write_nested_balls(&good);
    let truncated = dir.path().join("short.inr");
    std::fs::write(
        &truncated,
        b"#INRIMAGE-4#{\nXDIM=900000\nYDIM=900000\nZDIM=900000\n",
    )
    .expect("write");
    let empty = dir.path().join("empty.nrrd");
    std::fs::write(
        &empty,
        b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n\0\0\0\0\0\0\0\0",
    )
    .expect("write");
    // Specks of one voxel, 6 apart: real labels, all thinner than the default sizes resolve.
    let specks = dir.path().join("specks.nrrd");
    let mut bytes =
        b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 20 20 20\nencoding: raw\n\n".to_vec();
    bytes.extend((0..8000).map(|v: usize| {
        let speck = [v % 20, v / 20 % 20, v / 400].iter().all(|&i| i % 6 == 1);
        u8::from(speck)
    }));
    std::fs::write(&specks, bytes).expect("write");
    let cases: [(&Path, &[&str], &str); 5] = [
        (&truncated, &[], "##}"),
        (&empty, &[], "nothing to mesh"),
        (&specks, &[], "thinner than the criteria resolve"),
        (
            &good,
            &["--cell-size-per-label", "2=-1"],
            "--cell-size-per-label",
        ),
        (&good, &["--isovalue", "nan"], "isovalue"),
    ];
    for (input, extra, message) in cases {
        let out = dir.path().join("out.vtu");
        let assert = delamesh()
            .args(["mesh", "-q"])
            .arg(input)
            .arg("-o")
            .arg(&out)
            .args(extra)
            .assert()
            .code(1);
        let stderr = String::from_utf8_lossy(&assert.get_output().stderr).into_owned();
        assert!(stderr.contains(message), "{stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(!out.exists(), "output left behind for {}", input.display());
    }
}
