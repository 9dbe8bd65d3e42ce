//! Sizing fields through the facade and the command line: meshes follow the field given as an
//! expression, a background mesh, a size image or a closure; gradation bounds the growth; bad
//! fields are refused with one error naming the file and the value.

mod common;

use assert_cmd::Command;
use delamesh::core::kernel::circumcenter3;
use delamesh::{MeshSettings, Meshed, Mesher, Point3, SizeSource, SurfaceMesh};
use std::path::Path;

/// The field of most tests: 0.12 on the left of the unit ball, 0.42 on the right.
fn h(p: Point3) -> f64 {
    0.12 + 0.15 * (p.x + 1.0)
}

const H_TEXT: &str = "0.12 + 0.15 * (x + 1)";

fn ball() -> SurfaceMesh {
    SurfaceMesh::icosphere(Point3::ZERO, 1.0, 3)
}

fn mesh(settings: MeshSettings) -> Meshed {
    let settings = MeshSettings {
        features: delamesh::FeatureSettings {
            enabled: false,
            ..Default::default()
        },
        ..settings
    };
    Mesher::new(settings)
        .mesh_surface("ball", ball())
        .expect("meshed")
}

fn with_sizing(source: SizeSource) -> MeshSettings {
    MeshSettings::builder()
        .sizing(source)
        .build()
        .expect("valid settings")
}

/// The centre of the circle through a, b, c.
fn triangle_circumcenter(a: Point3, b: Point3, c: Point3) -> Point3 {
    let (u, v) = (b - a, c - a);
    let n = u.cross(v);
    a + (u.length_squared() * v.cross(n) + v.length_squared() * n.cross(u))
        / (2.0 * n.length_squared())
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Checks the size criteria against `size`: cells' circumradius at their circumcentre,
/// boundary facets' circumradius (a lower bound of their surface ball's radius) at their
/// circumcentre with the field's change over the facet distance, and the median edge / size.
fn assert_follows(m: &Meshed, size: impl Fn(Point3) -> f64) {
    let c = &m.complex;
    for t in &c.tets {
        let [a, b, cc, d] = t.map(|v| c.points[v as usize]);
        let center = circumcenter3(a, b, cc, d);
        let r = center.distance(a);
        assert!(
            r <= size(center) * (1.0 + 1e-6),
            "cell radius {r} > {}",
            size(center)
        );
    }
    for f in &c.facets {
        let [a, b, cc] = f.map(|v| c.points[v as usize]);
        let center = triangle_circumcenter(a, b, cc);
        let r = center.distance(a);
        // The surface ball's centre is within the facet distance (diagonal / 400) of it.
        assert!(
            r <= size(center) * 1.02,
            "facet radius {r} > {}",
            size(center)
        );
    }
    let mut ratios = Vec::new();
    for t in &c.tets {
        for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
            let (a, b) = (c.points[t[i] as usize], c.points[t[j] as usize]);
            ratios.push(a.distance(b) / size(0.5 * (a + b)));
        }
    }
    // Edges are at most a circumdiameter (2h); refinement stops once the criteria hold, so
    // edges are not much shorter than h either.
    let med = median(ratios);
    assert!((0.5..=2.0).contains(&med), "median edge / h = {med}");
}

#[test]
fn meshes_follow_an_expression_and_a_closure() {
    let expr = mesh(with_sizing(SizeSource::Expression(H_TEXT.into())));
    assert_follows(&expr, h);
    let closure = mesh(with_sizing(SizeSource::function(h)));
    assert_follows(&closure, h);
    // The same field: the same mesh.
    assert_eq!(expr.complex.points.len(), closure.complex.points.len());
    // Small on the left, large on the right: more vertices on the left.
    let left = expr.complex.points.iter().filter(|p| p.x < 0.0).count();
    let right = expr.complex.points.len() - left;
    assert!(
        left as f64 > 1.25 * right as f64,
        "{left} on the left, {right} on the right"
    );
}

/// Kuhn-subdivided cubes of `n`³ cells over [-l, l]³: the nodes and tets of the background
/// meshes.
fn kuhn_grid(n: usize, l: f64) -> (Vec<Point3>, Vec<[usize; 4]>) {
    let node = |i: usize, j: usize, k: usize| i + (n + 1) * (j + (n + 1) * k);
    let mut points = Vec::new();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                let t = |a: usize| -l + 2.0 * l * a as f64 / n as f64;
                points.push(Point3::new(t(i), t(j), t(k)));
            }
        }
    }
    let mut tets = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = |b: usize| node(i + (b & 1), j + ((b >> 1) & 1), k + (b >> 2));
                for [p, q] in [[1, 3], [1, 5], [2, 3], [2, 6], [4, 5], [4, 6]] {
                    tets.push([c(0), c(p), c(q), c(7)]);
                }
            }
        }
    }
    (points, tets)
}

/// Legacy VTK with the field `h` at the nodes of [`kuhn_grid`].
fn background_vtk(n: usize, l: f64, value: impl Fn(Point3) -> f64) -> String {
    let (points, tets) = kuhn_grid(n, l);
    let mut s = format!(
        "# vtk DataFile Version 3.0\nbackground\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS {} double\n",
        points.len()
    );
    for p in &points {
        s += &format!("{} {} {}\n", p.x, p.y, p.z);
    }
    s += &format!("CELLS {} {}\n", tets.len(), 5 * tets.len());
    for t in &tets {
        s += &format!("4 {} {} {} {}\n", t[0], t[1], t[2], t[3]);
    }
    s += &format!("CELL_TYPES {}\n", tets.len());
    s += &"10\n".repeat(tets.len());
    s += &format!(
        "POINT_DATA {}\nSCALARS h double 1\nLOOKUP_TABLE default\n",
        points.len()
    );
    for p in &points {
        s += &format!("{}\n", value(*p));
    }
    s
}

/// Gmsh 4.1 binary with the node data `h` on [`kuhn_grid`] (node tags from 1), as Gmsh writes
/// it: `size_t` counts and tags, an `int` tag before each value.
fn background_msh(n: usize, l: f64, value: impl Fn(Point3) -> f64) -> Vec<u8> {
    let (points, tets) = kuhn_grid(n, l);
    let mut s = b"$MeshFormat\n4.1 1 8\n".to_vec();
    s.extend(1i32.to_le_bytes());
    s.extend(b"\n$EndMeshFormat\n$Nodes\n");
    let sizes =
        |s: &mut Vec<u8>, v: &[usize]| v.iter().for_each(|&x| s.extend((x as u64).to_le_bytes()));
    let np = points.len();
    sizes(&mut s, &[1, np, 1, np]);
    [3i32, 1, 0].iter().for_each(|x| s.extend(x.to_le_bytes()));
    sizes(&mut s, &[np]);
    sizes(&mut s, &(1..=np).collect::<Vec<_>>());
    for p in &points {
        p.to_array().iter().for_each(|x| s.extend(x.to_le_bytes()));
    }
    s.extend(b"\n$EndNodes\n$Elements\n");
    sizes(&mut s, &[1, tets.len(), 1, tets.len()]);
    [3i32, 1, 4].iter().for_each(|x| s.extend(x.to_le_bytes()));
    sizes(&mut s, &[tets.len()]);
    for (e, t) in tets.iter().enumerate() {
        sizes(&mut s, &[e + 1, t[0] + 1, t[1] + 1, t[2] + 1, t[3] + 1]);
    }
    s.extend(format!("\n$EndElements\n$NodeData\n1\n\"h\"\n1\n0\n3\n0\n1\n{np}\n").bytes());
    for (k, p) in points.iter().enumerate() {
        s.extend((k as i32 + 1).to_le_bytes());
        s.extend(value(*p).to_le_bytes());
    }
    s.extend(b"\n$EndNodeData\n");
    s
}

/// A MEDIT mesh of [`kuhn_grid`] and the `.sol` of `value` at its vertices.
fn background_medit(n: usize, l: f64, value: impl Fn(Point3) -> f64) -> (String, String) {
    let (points, tets) = kuhn_grid(n, l);
    let mut mesh = format!(
        "MeshVersionFormatted 2\nDimension 3\nVertices\n{}\n",
        points.len()
    );
    let mut sol = format!(
        "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n{}\n1 1\n",
        points.len()
    );
    for p in &points {
        mesh += &format!("{} {} {} 0\n", p.x, p.y, p.z);
        sol += &format!("{}\n", value(*p));
    }
    mesh += &format!("Tetrahedra\n{}\n", tets.len());
    for t in &tets {
        mesh += &format!("{} {} {} {} 1\n", t[0] + 1, t[1] + 1, t[2] + 1, t[3] + 1);
    }
    (mesh + "End\n", sol + "End\n")
}

/// A raw NRRD image of `value` at `n`³ voxel centres over [-l, l]³.
fn size_nrrd(n: usize, l: f64, value: impl Fn(Point3) -> f64) -> Vec<u8> {
    let step = 2.0 * l / (n - 1) as f64;
    let mut bytes = format!(
        "NRRD0004\ntype: double\ndimension: 3\nsizes: {n} {n} {n}\nendian: little\n\
         spacings: {step} {step} {step}\nspace origin: ({l},{l},{l})\nencoding: raw\n\n"
    )
    .replace(&format!("({l},{l},{l})"), &format!("(-{l},-{l},-{l})"))
    .into_bytes();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = Point3::new(i as f64, j as f64, k as f64) * step - Point3::splat(l);
                bytes.extend(value(p).to_le_bytes());
            }
        }
    }
    bytes
}

#[test]
fn the_same_field_as_expression_background_mesh_and_image_gives_the_same_vertex_count() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let bg = dir.path().join("bg.vtk");
    std::fs::write(&bg, background_vtk(6, 1.2, h)).expect("written");
    let image = dir.path().join("h.nrrd");
    std::fs::write(&image, size_nrrd(9, 1.2, h)).expect("written");
    let count = |source: SizeSource| mesh(with_sizing(source)).complex.points.len() as f64;
    let expr = count(SizeSource::Expression(H_TEXT.into()));
    for source in [SizeSource::file(&bg), SizeSource::file(&image)] {
        let n = count(source.clone());
        assert!(
            (n / expr - 1.0).abs() < 0.03,
            "{source:?}: {n} vertices, expression {expr}"
        );
    }
    let background = mesh(with_sizing(SizeSource::file(&bg)));
    assert_follows(&background, h);
    // The same background mesh as Gmsh and MEDIT files: the same mesh.
    let msh = dir.path().join("bg.msh");
    std::fs::write(&msh, background_msh(6, 1.2, h)).expect("written");
    let (medit, sol) = background_medit(6, 1.2, h);
    let medit_path = dir.path().join("bg.mesh");
    std::fs::write(&medit_path, medit).expect("written");
    std::fs::write(dir.path().join("bg.sol"), sol).expect("written");
    for path in [&msh, &medit_path] {
        let other = mesh(with_sizing(SizeSource::file(path)));
        assert_eq!(
            other.complex.points.len(),
            background.complex.points.len(),
            "{}",
            path.display()
        );
    }
}

#[test]
fn gradation_bounds_the_growth_and_keeps_the_field_as_a_bound() {
    // A small size at one point of the surface, growing five times too fast.
    let corner = Point3::new(1.0, 0.0, 0.0);
    let spike = move |p: Point3| 0.06 + 2.0 * p.distance(corner);
    let g = 0.25;
    let settings = MeshSettings::builder()
        .sizing(SizeSource::function(spike))
        .size_gradation(g)
        .build()
        .expect("valid");
    let m = mesh(settings);
    let graded = |p: Point3| m.criteria.cell.size.at(p, 1);
    assert_follows(&m, graded);
    let samples: Vec<Point3> = m.complex.points.iter().step_by(7).copied().collect();
    for (i, &a) in samples.iter().enumerate() {
        assert!(graded(a) <= spike(a) + 1e-12);
        let b = samples[(i + 1) % samples.len()];
        let l1 = (a - b).abs().element_sum();
        assert!((graded(a) - graded(b)).abs() <= g * l1 * (1.0 + 1e-9) + 1e-12);
    }
    // The graded mesh is finer than the field alone, away from the spike too.
    let plain = mesh(with_sizing(SizeSource::function(spike)));
    assert!(m.complex.points.len() > plain.complex.points.len());
}

#[test]
fn per_subdomain_and_per_patch_sizes_bound_their_cells_and_facets() {
    let settings = MeshSettings::builder()
        .size_for_subdomain(1, 0.15)
        .size_for_patch(1, 0.1)
        .build()
        .expect("valid");
    let m = mesh(settings);
    assert!(m.complex.tet_subdomain.iter().all(|s| s.0 == 1));
    assert!(m.complex.facet_patch.iter().all(|p| p.0 == 1));
    let c = &m.complex;
    for t in &c.tets {
        let [a, b, cc, d] = t.map(|v| c.points[v as usize]);
        assert!(circumcenter3(a, b, cc, d).distance(a) <= 0.15 * (1.0 + 1e-6));
    }
    for f in &c.facets {
        let [a, b, cc] = f.map(|v| c.points[v as usize]);
        assert!(triangle_circumcenter(a, b, cc).distance(a) <= 0.1 * 1.02);
    }
}

fn run(dir: &Path, args: &[&str]) -> (bool, String) {
    let input = dir.join("ball.off");
    let s = ball();
    let surface = common::Surface {
        points: s.positions,
        triangles: s.triangles,
    };
    std::fs::write(&input, surface.to_off()).expect("written");
    let out = Command::cargo_bin("delamesh")
        .expect("binary")
        .arg("mesh")
        .arg(&input)
        .arg("-o")
        .arg(dir.join("out.vtu"))
        .args(args)
        .output()
        .expect("ran");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success() || stderr.is_empty() || stderr.contains("warning"));
    if !out.status.success() {
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(!dir.join("out.vtu").exists(), "no output left behind");
        assert_eq!(stderr.trim().lines().count(), 1, "one line: {stderr}");
    }
    (out.status.success(), stderr)
}

#[test]
fn bad_fields_are_refused_naming_the_file_and_the_value() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let d = dir.path();
    let write = |name: &str, text: &str| {
        let path = d.join(name);
        std::fs::write(&path, text).expect("written");
        path.display().to_string()
    };
    let negative = write("neg.vtk", &background_vtk(2, 1.2, |p| p.x));
    let (ok, e) = run(d, &["--sizing", &negative]);
    assert!(
        !ok && e.contains("neg.vtk") && e.contains("node 0") && e.contains("-1.2"),
        "{e}"
    );
    let nan = write(
        "nan.vtk",
        &background_vtk(2, 1.2, |p| if p.z > 0.0 { f64::NAN } else { 1.0 }),
    );
    let (ok, e) = run(d, &["--sizing", &nan]);
    // The VTK reader reads a NaN as infinite: refused all the same.
    assert!(
        !ok && e.contains("nan.vtk") && e.contains("not a positive size"),
        "{e}"
    );
    let small = write("small.vtk", &background_vtk(2, 0.5, |_| 0.3));
    let (ok, e) = run(d, &["--sizing", &small]);
    assert!(
        !ok && e.contains("small.vtk") && e.contains("does not cover"),
        "{e}"
    );
    let good = write("good.vtk", &background_vtk(2, 1.2, |_| 0.4));
    let (ok, e) = run(d, &["--sizing", &good, "--sizing-field", "size"]);
    assert!(
        !ok && e.contains("good.vtk") && e.contains("\"size\"") && e.contains("h"),
        "{e}"
    );
    let points = write("points.xyz", "0 0 0 0.3\n1 0 0 0\n");
    let (ok, e) = run(d, &["--sizing", &points]);
    assert!(
        !ok && e.contains("points.xyz") && e.contains("line 2"),
        "{e}"
    );
    let (ok, e) = run(d, &["--sizing-expr", "x - 0.5"]);
    assert!(
        !ok && e.contains("--sizing-expr") && e.contains("not a positive size"),
        "{e}"
    );
    let (ok, e) = run(d, &["--sizing-expr", "q + 1"]);
    assert!(!ok && e.contains("\"q\""), "{e}");
    let (ok, e) = run(d, &["--size-gradation", "-1"]);
    assert!(!ok && e.contains("--size-gradation"), "{e}");
    let (medit, _) = background_medit(2, 1.2, |_| 0.4);
    let lone = write("lone.mesh", &medit);
    let (ok, e) = run(d, &["--sizing", &lone]);
    assert!(
        !ok && e.contains("lone.mesh") && e.contains("lone.sol"),
        "{e}"
    );
    let (ok, e) = run(
        d,
        &["--sizing", &d.join("missing.vtu").display().to_string()],
    );
    assert!(!ok && e.contains("missing.vtu"), "{e}");
    // The good one meshes, and a point cloud with sizes too.
    assert!(run(d, &["--sizing", &good]).0);
    let cloud = write("cloud.xyz", "-1 0 0 0.2\n1 0 0 0.5\n0 0 1 0.3\n");
    assert!(run(d, &["--sizing", &cloud, "--size-gradation", "0.5"]).0);
}

#[test]
fn a_background_mesh_in_memory_is_checked_as_a_file_is() {
    let source = |l: f64| {
        let (points, tets) = kuhn_grid(2, l);
        let tets = tets.iter().map(|t| t.map(|v| v as u32)).collect();
        let values = vec![0.4; points.len()];
        SizeSource::background(points, tets, values).expect("valid arrays")
    };
    let settings = |l: f64| {
        MeshSettings::builder()
            .sizing(source(l))
            .features(false)
            .build()
            .expect("valid settings")
    };
    let e = Mesher::new(settings(0.5))
        .mesh_surface("ball", ball())
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("does not cover"), "{e}");
    assert_follows(&mesh(settings(1.2)), |_| 0.4);
    let (points, tets) = kuhn_grid(1, 1.0);
    let tets: Vec<[u32; 4]> = tets.iter().map(|t| t.map(|v| v as u32)).collect();
    let mut values = vec![0.4; points.len()];
    values[5] = -0.1;
    let e = SizeSource::background(points, tets, values)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("node 5") && e.contains("-0.1"), "{e}");
}

#[test]
fn gradation_starts_from_small_features_too() {
    // A thin plate: its short edges get small protecting balls, which the constant size
    // knows nothing of.
    let plate = SurfaceMesh::cuboid(Point3::ZERO, Point3::new(2.0, 2.0, 0.12));
    let g = 0.3;
    let settings = MeshSettings::builder()
        .cell_size(0.5)
        .facet_size(0.5)
        .size_gradation(g)
        .build()
        .expect("valid");
    let m = Mesher::new(settings)
        .mesh_surface("plate", plate)
        .expect("meshed");
    let size = |p: Point3| m.criteria.cell.size.at(p, 1);
    let corner = size(Point3::ZERO);
    assert!(corner < 0.1, "size {corner} at a corner");
    let middle = size(Point3::new(1.0, 1.0, 0.06));
    assert!(
        middle > 2.0 * corner && middle <= corner + 1.09 * g * 2f64.sqrt() + 0.05,
        "size {middle} in the middle, {corner} at a corner"
    );
    assert!(m.criteria.edge_size.at(Point3::ZERO, 1) <= corner + 1e-12);
    let points: Vec<Point3> = m.complex.points.iter().step_by(5).copied().collect();
    for (i, &a) in points.iter().enumerate() {
        let b = points[(i + 1) % points.len()];
        let l1 = (a - b).abs().element_sum();
        assert!((size(a) - size(b)).abs() <= g * l1 * (1.0 + 1e-9) + 1e-12);
    }
}
