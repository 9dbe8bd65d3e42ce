//! glTF reader on files generated here: node hierarchies with rotated and scaled parents, several
//! primitives, strips and fans, u8/u16/u32 and no indices, `.gltf` + `.bin`, data URIs and `.glb`.

use delamesh_core::mesh::SurfaceMesh;
use delamesh_formats::{AnyMesh, Format, read, read_bytes};
use glam::{DMat4, DQuat, DVec3};
use serde_json::{Value, json};

/// Accumulates one binary buffer with its views and accessors.
#[derive(Default)]
struct Bin {
    data: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    fn push(&mut self, bytes: &[u8], accessor: Value, target: u32) -> usize {
        while self.data.len() % 4 != 0 {
            self.data.push(0);
        }
        self.views.push(json!({"buffer": 0, "byteOffset": self.data.len(), "byteLength": bytes.len(), "target": target}));
        self.data.extend_from_slice(bytes);
        let mut a = accessor;
        a["bufferView"] = json!(self.views.len() - 1);
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = p.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let min: Vec<f32> = (0..3)
            .map(|i| p.iter().map(|v| v[i]).fold(f32::INFINITY, f32::min))
            .collect();
        let max: Vec<f32> = (0..3)
            .map(|i| p.iter().map(|v| v[i]).fold(f32::NEG_INFINITY, f32::max))
            .collect();
        self.push(&bytes, json!({"componentType": 5126, "count": p.len(), "type": "VEC3", "min": min, "max": max}), 34962)
    }

    /// Indices stored with `width` bytes each (1, 2 or 4).
    fn indices(&mut self, idx: &[u32], width: usize) -> usize {
        let bytes: Vec<u8> = idx
            .iter()
            .flat_map(|&i| i.to_le_bytes()[..width].to_vec())
            .collect();
        let ty = match width {
            1 => 5121,
            2 => 5123,
            _ => 5125,
        };
        self.push(
            &bytes,
            json!({"componentType": ty, "count": idx.len(), "type": "SCALAR"}),
            34963,
        )
    }

    fn document(&self, nodes: Value, meshes: Value, buffer_uri: Option<String>) -> Value {
        let mut buffer = json!({"byteLength": self.data.len()});
        if let Some(uri) = buffer_uri {
            buffer["uri"] = json!(uri);
        }
        json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": nodes,
            "meshes": meshes,
            "buffers": [buffer],
            "bufferViews": self.views,
            "accessors": self.accessors,
        })
    }
}

fn glb(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json = serde_json::to_vec(doc).unwrap();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(0x4E4F_534Au32.to_le_bytes());
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(0x004E_4942u32.to_le_bytes());
    out.extend(bin);
    out
}

/// Unit cube corners and its 12 outward triangles.
fn cube() -> (Vec<[f32; 3]>, Vec<u32>) {
    let cube = SurfaceMesh::cuboid(DVec3::ZERO, DVec3::ONE);
    let p = cube
        .positions
        .iter()
        .map(|v| v.as_vec3().to_array())
        .collect();
    (p, cube.triangles.concat())
}

/// A scene exercising everything: root (rotated 90° about z, scaled 2) → child (translated) holding
/// a mesh of four primitives: u16 triangles, u8 strip, non-indexed fan, u32 triangles; plus a
/// primitive of lines (skipped with a warning).
struct Scene {
    doc: Value,
    bin: Vec<u8>,
    root: DMat4,
    child: DMat4,
}

fn scene(buffer_uri: Option<String>) -> Scene {
    let mut b = Bin::default();
    let tri = b.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let tri_idx = b.indices(&[0, 1, 2], 2);
    let strip = b.positions(&[
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [0.0, 1.0, 1.0],
        [1.0, 1.0, 1.0],
    ]);
    let strip_idx = b.indices(&[0, 1, 2, 3], 1);
    let fan = b.positions(&[
        [0.0, 0.0, 2.0],
        [1.0, 0.0, 2.0],
        [1.0, 1.0, 2.0],
        [0.0, 1.0, 2.0],
    ]);
    let (cp, ct) = cube();
    let cube_pos = b.positions(&cp);
    let cube_idx = b.indices(&ct, 4);
    let nodes = json!([
        {"name": "root", "rotation": [0.0, 0.0, std::f64::consts::FRAC_1_SQRT_2, std::f64::consts::FRAC_1_SQRT_2], "scale": [2.0, 2.0, 2.0], "children": [1]},
        {"name": "child", "translation": [10.0, 0.0, 0.0], "mesh": 0}
    ]);
    let meshes = json!([{"name": "parts", "primitives": [
        {"attributes": {"POSITION": tri}, "indices": tri_idx, "mode": 4},
        {"attributes": {"POSITION": strip}, "indices": strip_idx, "mode": 5},
        {"attributes": {"POSITION": fan}, "mode": 6},
        {"attributes": {"POSITION": cube_pos}, "indices": cube_idx},
        {"attributes": {"POSITION": tri}, "mode": 1}
    ]}]);
    let doc = b.document(nodes, meshes, buffer_uri);
    let root = DMat4::from_scale_rotation_translation(
        DVec3::splat(2.0),
        DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2),
        DVec3::ZERO,
    );
    let child = DMat4::from_translation(DVec3::new(10.0, 0.0, 0.0));
    Scene {
        doc,
        bin: b.data,
        root,
        child,
    }
}

fn check(s: &SurfaceMesh, warnings: &[String], sc: &Scene) {
    let world = sc.root * sc.child;
    // The lines primitive (index 4) is skipped: no patch for it.
    assert_eq!(s.patch_names, ["parts/0", "parts/1", "parts/2", "parts/3"]);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    // 1 + 2 (strip) + 2 (fan) + 12 (cube) triangles.
    assert_eq!(s.triangles.len(), 17);
    let corners = |t: usize| s.triangles[t].map(|v| s.positions[v as usize]);
    // glTF transforms are f32: compare to f32 precision.
    let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-5;
    let expect = |p: [f64; 3]| world.transform_point3(DVec3::from_array(p));
    let [a, b, c] = corners(0);
    assert!(
        close(a, expect([0.0, 0.0, 0.0]))
            && close(b, expect([1.0, 0.0, 0.0]))
            && close(c, expect([0.0, 1.0, 0.0]))
    );
    // The child at x = 10 lands, after the 90° turn and ×2, at y = 20.
    assert!(close(a, DVec3::new(0.0, 20.0, 0.0)), "{a}");
    // Strip: second triangle reversed so both face +z (before transform), i.e. the same way.
    let normal = |t: usize| {
        let [a, b, c] = corners(t);
        (b - a).cross(c - a).normalize()
    };
    let up = world.transform_vector3(DVec3::Z).normalize();
    for t in 0..5 {
        assert!(close(normal(t), up), "triangle {t} faces {}", normal(t));
    }
    // The cube comes out closed, outward, with volume scaled by 2³.
    let cube = SurfaceMesh {
        positions: s.positions.clone(),
        triangles: s.triangles[5..].to_vec(),
        patches: s.patches[5..].to_vec(),
        patch_names: s.patch_names.clone(),
    };
    let topo = cube.topology();
    assert!(topo.closed && topo.manifold && topo.orientation_consistent);
    assert!(
        (topo.signed_volume - 8.0).abs() < 1e-4,
        "{}",
        topo.signed_volume
    );
}

fn surface(r: delamesh_formats::MeshRead) -> (SurfaceMesh, Vec<String>) {
    match r.mesh {
        AnyMesh::Surface(s) => (s, r.warnings),
        AnyMesh::Volume(_) => panic!("glTF holds surfaces"),
    }
}

#[test]
fn gltf_with_external_bin() {
    let sc = scene(Some("my%20parts.bin".into()));
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("my parts.bin"), &sc.bin).unwrap();
    let path = dir.path().join("scene.GLTF");
    std::fs::write(&path, serde_json::to_vec(&sc.doc).unwrap()).unwrap();
    let (s, w) = surface(read(&path, None).unwrap());
    check(&s, &w, &sc);
    // Without the .bin the error names the missing buffer.
    std::fs::remove_file(dir.path().join("my parts.bin")).unwrap();
    let err = read(&path, None).unwrap_err().to_string();
    assert!(
        err.contains("scene.GLTF") && err.contains("my parts.bin"),
        "{err}"
    );
}

#[test]
fn gltf_with_data_uri() {
    use base64::Engine;
    let plain = scene(None);
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&plain.bin)
    );
    let sc = scene(Some(uri));
    let (s, w) =
        surface(read_bytes(&serde_json::to_vec(&sc.doc).unwrap(), Format::Gltf, None).unwrap());
    check(&s, &w, &sc);
}

#[test]
fn glb_with_binary_chunk_and_welding() {
    let sc = scene(None);
    let r = read_bytes(&glb(&sc.doc, &sc.bin), Format::Gltf, None).unwrap();
    // The triangle's 3 corners and the strip's 4 are also cube corners: welding merges them.
    assert_eq!(r.welded_vertices, 7);
    let (s, w) = surface(r);
    check(&s, &w, &sc);
}

#[test]
fn per_face_vertices_are_welded_closed() {
    let (p, t) = cube();
    let soup: Vec<[f32; 3]> = t.iter().map(|&i| p[i as usize]).collect();
    let mut b = Bin::default();
    let pos = b.positions(&soup);
    let doc = b.document(
        json!([{"mesh": 0}]),
        json!([{"primitives": [{"attributes": {"POSITION": pos}}]}]),
        None,
    );
    let r = read_bytes(&glb(&doc, &b.data), Format::Gltf, None).unwrap();
    assert_eq!(r.welded_vertices, 36 - 8);
    let (s, _) = surface(r);
    assert!(s.topology().closed);
    assert_eq!(s.topology().genus, Some(0));
}

#[test]
fn malformed_accessors_are_errors_not_panics() {
    let mut b = Bin::default();
    let pos = b.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    // Claim more vertices than the view holds.
    b.accessors[pos]["count"] = json!(1000);
    let doc = b.document(
        json!([{"mesh": 0}]),
        json!([{"primitives": [{"attributes": {"POSITION": pos}}]}]),
        None,
    );
    let err = read_bytes(&glb(&doc, &b.data), Format::Gltf, None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("runs past"), "{err}");
    // Out-of-range index.
    let mut b = Bin::default();
    let pos = b.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let idx = b.indices(&[0, 1, 7], 2);
    let doc = b.document(
        json!([{"mesh": 0}]),
        json!([{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}]),
        None,
    );
    let err = read_bytes(&glb(&doc, &b.data), Format::Gltf, None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("index 7 out of range"), "{err}");
}

#[test]
fn mirroring_node_keeps_the_surface_outward() {
    let (p, t) = cube();
    let mut b = Bin::default();
    let pos = b.positions(&p);
    let idx = b.indices(&t, 2);
    let nodes = json!([{"scale": [-1.0, 1.0, 1.0], "mesh": 0}]);
    let meshes = json!([{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}]);
    let doc = b.document(nodes, meshes, None);
    let (s, _) = surface(read_bytes(&glb(&doc, &b.data), Format::Gltf, None).unwrap());
    assert!(s.positions.iter().all(|p| p.x <= 0.0));
    let topo = s.topology();
    assert!(topo.is_watertight());
    assert!(
        (topo.signed_volume - 1.0).abs() < 1e-12,
        "{}",
        topo.signed_volume
    );
}
