//! Meshes of synthetic labelled images made here: the labels of the tets match the voxels, the
//! volume of each label approaches the analytic one within a bound tied to the facet distance and
//! the voxel size, every interface is a closed 2-manifold, and the same image read from INR,
//! NIfTI and VTI gives the same bytes.

use delamesh_core::complex::MeshComplex;
use delamesh_core::oracle::Oracle;
use delamesh_core::quality;
use delamesh_core::refine::criteria::{MeshCriteria, Sizing};
use delamesh_core::refine::{Limits, MeshOptions, mesh_domain};
use delamesh_formats::image::{Image, ImageFormat, Voxels, read_image, read_image_bytes};
use delamesh_image_label::{ImageLabelOracle, ImageOptions};
use glam::DVec3;
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// An image of `dims` voxels of size `spacing` (first centre at the origin), labelled by `label`
/// of each voxel centre.
fn image(dims: [usize; 3], spacing: DVec3, label: impl Fn(DVec3) -> u8) -> Image {
    let mut v = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                v.push(label(DVec3::new(i as f64, j as f64, k as f64) * spacing));
            }
        }
    }
    Image::axis_aligned(dims, spacing, DVec3::ZERO, Voxels::U8(v))
}

fn criteria(size: f64, distance: f64) -> MeshCriteria {
    let mut c = MeshCriteria::default_for(&delamesh_core::oracle::Aabb {
        min: DVec3::ZERO,
        max: DVec3::ONE,
    });
    c.facet.angle_deg = 25.0;
    c.facet.size = Sizing::Constant(size);
    c.facet.distance = Sizing::Constant(distance);
    c.cell.size = Sizing::Constant(size);
    c
}

fn mesh(oracle: &ImageLabelOracle, criteria: MeshCriteria) -> MeshComplex {
    let options = MeshOptions {
        criteria,
        limits: Limits::default(),
        keep_partial: false,
        validity: Default::default(),
        optimize: delamesh_core::optimize::OptimizeOptions::none(),
    };
    mesh_domain(oracle, &options, &mut |_| {})
        .expect("meshing succeeds")
        .complex
}

fn volumes(c: &MeshComplex) -> BTreeMap<u32, f64> {
    let mut v = BTreeMap::new();
    for (t, &s) in c.tet_subdomain.iter().enumerate() {
        let p = c.tet_points(t);
        *v.entry(s).or_insert(0.0) += (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]) / 6.0;
    }
    v
}

/// Every tet whose centroid is farther than `margin` from the interfaces (`distance` gives the
/// distance of a point to them) has the label of the voxel nearest its centroid, but for 1 %.
fn assert_tets_in_their_voxels(
    c: &MeshComplex,
    spacing: DVec3,
    label: impl Fn(DVec3) -> u8,
    distance: impl Fn(DVec3) -> f64,
    margin: f64,
) {
    let (mut away, mut wrong) = (0usize, 0usize);
    for (t, &s) in c.tet_subdomain.iter().enumerate() {
        let p = c.tet_points(t);
        let centroid = (p[0] + p[1] + p[2] + p[3]) / 4.0;
        if distance(centroid) <= margin {
            continue;
        }
        away += 1;
        let voxel_centre = (centroid / spacing).round() * spacing;
        if u32::from(label(voxel_centre)) != s {
            wrong += 1;
        }
    }
    assert!(away > 50, "too few tets away from the interfaces: {away}");
    assert!(
        wrong * 100 <= away,
        "{wrong} of {away} tets away from the interfaces lie in a voxel of another label"
    );
}

/// The facets between each pair of labels form closed 2-manifolds with `euler` as Euler
/// characteristic (summed over components), each facet's patch is that pair's, but for the 1 %
/// the surface level did not find restricted (patch 0; see `MeshComplex::facet_patch`).
fn assert_closed_interfaces(c: &MeshComplex, oracle: &ImageLabelOracle, euler: &[([u32; 2], i64)]) {
    let mut by_pair: BTreeMap<[u32; 2], Vec<[u32; 3]>> = BTreeMap::new();
    let mut unrestricted = 0;
    for (f, &p) in c.facet_patch.iter().enumerate() {
        let mut pair = c.facet_subdomains[f];
        pair.sort_unstable();
        by_pair.entry(pair).or_default().push(c.facets[f]);
        match p {
            0 => unrestricted += 1,
            p => assert_eq!(oracle.patch_subdomains(p), Some(pair), "facet {f}"),
        }
    }
    assert!(
        unrestricted * 100 <= c.facets.len(),
        "{unrestricted} of {} facets unrestricted",
        c.facets.len()
    );
    let pairs: Vec<[u32; 2]> = by_pair.keys().copied().collect();
    assert_eq!(pairs, euler.iter().map(|e| e.0).collect::<Vec<_>>());
    for ((pair, facets), (_, want)) in by_pair.into_iter().zip(euler) {
        let t = quality::surface_topology(&facets);
        assert_eq!(t.border_edges, 0, "interface {pair:?} has a border");
        assert_eq!(
            t.non_manifold_edges, 0,
            "interface {pair:?} is not manifold"
        );
        assert_eq!(
            t.non_manifold_vertices, 0,
            "interface {pair:?} is not manifold"
        );
        assert_eq!(t.euler_characteristic, *want, "interface {pair:?}");
    }
}

/// `|V - V_exact| ≤ area × (facet distance + voxel size / 2)`: an interface approximated within
/// the facet distance of the voxelised surface, itself within half a voxel of the exact one.
fn assert_volume(v: f64, exact: f64, area: f64, distance: f64, voxel: f64) {
    let tolerance = area * (distance + 0.5 * voxel);
    assert!(
        (v - exact).abs() <= tolerance,
        "volume {v} vs exact {exact}: more than {tolerance} apart"
    );
}

#[test]
fn a_ball_is_meshed_inside_its_voxels_with_its_volume() {
    let (c0, r) = (DVec3::splat(12.0), 8.0);
    let label = |p: DVec3| u8::from((p - c0).length() <= r);
    let img = image([25, 25, 25], DVec3::ONE, label);
    let oracle = ImageLabelOracle::new(&img, &ImageOptions::default()).expect("valid image");
    assert_eq!(oracle.subdomains(), vec![1]);
    let (size, distance) = (3.0, 0.5);
    let c = mesh(&oracle, criteria(size, distance));
    assert!(c.tet_subdomain.iter().all(|&s| s == 1));
    assert_tets_in_their_voxels(
        &c,
        DVec3::ONE,
        label,
        |p| ((p - c0).length() - r).abs(),
        1.5,
    );
    let v = volumes(&c);
    assert_volume(
        v[&1],
        4.0 / 3.0 * PI * r.powi(3),
        4.0 * PI * r * r,
        distance,
        1.0,
    );
    assert_closed_interfaces(&c, &oracle, &[([0, 1], 2)]);
}

#[test]
fn nested_balls_give_two_labels_and_two_closed_interfaces() {
    let c0 = DVec3::splat(12.0);
    let (r1, r2) = (4.5, 9.0);
    let label = |p: DVec3| match (p - c0).length() {
        d if d <= r1 => 3,
        d if d <= r2 => 7,
        _ => 0,
    };
    let img = image([25, 25, 25], DVec3::ONE, label);
    let oracle = ImageLabelOracle::new(&img, &ImageOptions::default()).expect("valid image");
    assert_eq!(oracle.subdomains(), vec![3, 7]);
    let distance = 0.4;
    let c = mesh(&oracle, criteria(2.5, distance));
    let dist = |p: DVec3| {
        let d = (p - c0).length();
        (d - r1).abs().min((d - r2).abs())
    };
    assert_tets_in_their_voxels(&c, DVec3::ONE, label, dist, 1.5);
    let v = volumes(&c);
    let (inner, outer) = (4.0 / 3.0 * PI * r1.powi(3), 4.0 / 3.0 * PI * r2.powi(3));
    let (a1, a2) = (4.0 * PI * r1 * r1, 4.0 * PI * r2 * r2);
    // Labels are the label values, not a renumbering.
    assert_volume(v[&3], inner, a1, distance, 1.0);
    assert_volume(v[&7], outer - inner, a1 + a2, distance, 1.0);
    assert_closed_interfaces(&c, &oracle, &[([0, 7], 2), ([3, 7], 2)]);
}

#[test]
fn an_anisotropic_voxel_size_is_honoured() {
    let spacing = DVec3::new(0.5, 0.5, 1.25);
    let (c0, r) = (DVec3::new(6.0, 6.0, 6.25), 4.5);
    let label = |p: DVec3| u8::from((p - c0).length() <= r);
    let img = image([25, 25, 11], spacing, label);
    let oracle = ImageLabelOracle::new(&img, &ImageOptions::default()).expect("valid image");
    let b = oracle.bounding_box();
    assert!(b.contains(c0 + DVec3::splat(r)) && b.contains(c0 - DVec3::splat(r)));
    // No finer than the voxels, as the image defaults: finer chases the voxel staircase.
    let distance = 0.5;
    let c = mesh(&oracle, criteria(2.0, distance));
    assert_tets_in_their_voxels(&c, spacing, label, |p| ((p - c0).length() - r).abs(), 1.25);
    let v = volumes(&c);
    assert_volume(
        v[&1],
        4.0 / 3.0 * PI * r.powi(3),
        4.0 * PI * r * r,
        distance,
        1.25,
    );
    assert_closed_interfaces(&c, &oracle, &[([0, 1], 2)]);
}

#[test]
fn three_touching_boxes_keep_their_labels_and_volumes() {
    // Boxes side by side in x (labels 1, 2) on top of a slab (label 3): a triple line where the
    // three meet.
    let label = |p: DVec3| {
        let inside = p.cmpge(DVec3::splat(2.0)).all() && p.cmple(DVec3::splat(18.0)).all();
        match () {
            _ if !inside => 0,
            _ if p.z < 8.0 => 3,
            _ if p.x < 10.0 => 1,
            _ => 2,
        }
    };
    let img = image([21, 21, 21], DVec3::ONE, label);
    let oracle = ImageLabelOracle::new(&img, &ImageOptions::default()).expect("valid image");
    assert_eq!(oracle.subdomains(), vec![1, 2, 3]);
    let c = mesh(&oracle, criteria(3.0, 0.5));
    let v = volumes(&c);
    // Interfaces lie half-way between voxel centres of different labels: the boxes span
    // [1.5, 18.5] and meet at x = 9.5 and z = 7.5. Their edges are rounded off (no features
    // here), by at most about the facet distance across each edge.
    let exact = |dx: f64, dz: f64| dx * 17.0 * dz;
    for (l, want) in [
        (1, exact(8.0, 11.0)),
        (2, exact(9.0, 11.0)),
        (3, exact(17.0, 6.0)),
    ] {
        let got = v[&l];
        assert!(
            (got - want).abs() <= 0.05 * want,
            "label {l}: {got} vs {want}"
        );
    }
    let dist = |p: DVec3| {
        let mut d = (p.z - 7.5).abs().min((p.x - 9.5).abs());
        for a in 0..3 {
            d = d.min((p[a] - 1.5).abs()).min((p[a] - 18.5).abs());
        }
        d
    };
    assert_tets_in_their_voxels(&c, DVec3::ONE, label, dist, 1.5);
}

/// The 8-bit image as INR bytes.
fn inr_bytes(img: &Image, v: &[u8]) -> Vec<u8> {
    let s = img.spacing();
    let mut h = format!(
        "#INRIMAGE-4#{{\nXDIM={}\nYDIM={}\nZDIM={}\nVDIM=1\nTYPE=unsigned fixed\nPIXSIZE=8 bits\nCPU=decm\nVX={}\nVY={}\nVZ={}\n",
        img.dims[0], img.dims[1], img.dims[2], s.x, s.y, s.z
    )
    .into_bytes();
    h.resize(252, b'\n');
    h.extend_from_slice(b"##}\n");
    h.extend_from_slice(v);
    h
}

/// The 8-bit image as a NIfTI-1 file with an sform.
fn nifti_bytes(img: &Image, v: &[u8]) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    let put = |h: &mut Vec<u8>, at: usize, b: &[u8]| h[at..at + b.len()].copy_from_slice(b);
    put(&mut h, 0, &348i32.to_le_bytes());
    let dims = [
        3i16,
        img.dims[0] as i16,
        img.dims[1] as i16,
        img.dims[2] as i16,
        1,
        1,
        1,
        1,
    ];
    for (n, d) in dims.iter().enumerate() {
        put(&mut h, 40 + 2 * n, &d.to_le_bytes());
    }
    put(&mut h, 70, &2i16.to_le_bytes()); // DT_UINT8
    put(&mut h, 72, &8i16.to_le_bytes());
    let s = img.spacing();
    for (n, p) in [1.0, s.x, s.y, s.z].iter().enumerate() {
        put(&mut h, 76 + 4 * n, &(*p as f32).to_le_bytes());
    }
    put(&mut h, 108, &352f32.to_le_bytes());
    put(&mut h, 254, &1i16.to_le_bytes()); // sform_code
    for (row, at) in [280, 296, 312].into_iter().enumerate() {
        let mut r = [0f32; 4];
        r[row] = s[row] as f32;
        for (n, x) in r.iter().enumerate() {
            put(&mut h, at + 4 * n, &x.to_le_bytes());
        }
    }
    put(&mut h, 344, b"n+1\0");
    h.extend_from_slice(v);
    h
}

/// The 8-bit image as ASCII VTK image data.
fn vti_bytes(img: &Image, v: &[u8]) -> Vec<u8> {
    let [nx, ny, nz] = img.dims.map(|d| d - 1);
    let s = img.spacing();
    let values: Vec<String> = v.iter().map(|x| x.to_string()).collect();
    format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n\
         <ImageData WholeExtent=\"0 {nx} 0 {ny} 0 {nz}\" Origin=\"0 0 0\" Spacing=\"{} {} {}\">\n\
         <Piece Extent=\"0 {nx} 0 {ny} 0 {nz}\">\n<PointData Scalars=\"labels\">\n\
         <DataArray type=\"UInt8\" Name=\"labels\" format=\"ascii\">\n{}\n</DataArray>\n\
         </PointData>\n<CellData>\n</CellData>\n</Piece>\n</ImageData>\n</VTKFile>\n",
        s.x,
        s.y,
        s.z,
        values.join(" ")
    )
    .into_bytes()
}

#[test]
fn the_same_image_as_inr_nifti_and_vti_gives_the_same_mesh_bytes() {
    let (c0, r) = (DVec3::new(5.0, 5.0, 5.0), 3.6);
    let spacing = DVec3::new(0.5, 0.5, 1.0);
    let label = |p: DVec3| u8::from((p - c0).length() <= r) * 4;
    let img = image([21, 21, 11], spacing, label);
    let Voxels::U8(v) = &img.voxels else {
        unreachable!("made as bytes")
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let mut outputs = Vec::new();
    for (format, bytes, name) in [
        (ImageFormat::Inr, inr_bytes(&img, v), "ball.inr"),
        (ImageFormat::Nifti, nifti_bytes(&img, v), "ball.nii"),
        (ImageFormat::Vti, vti_bytes(&img, v), "ball.vti"),
    ] {
        let parsed = read_image_bytes(&bytes, format, None).expect("readable");
        assert_eq!(parsed, img, "{name}");
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes).expect("write");
        let read = read_image(&path).expect("readable");
        let oracle = ImageLabelOracle::new(&read, &ImageOptions::default()).expect("valid");
        let c = mesh(&oracle, criteria(1.5, 0.3));
        let out = dir.path().join(format!("{name}.vtu"));
        delamesh_formats::write_tet_mesh(&out, &c.to_tet_mesh(), &Default::default())
            .expect("write");
        outputs.push(std::fs::read(&out).expect("read back"));
    }
    assert!(outputs.iter().all(|o| *o == outputs[0]));
    // Gzipped, the INR is the same image.
    let gz = dir.path().join("ball.inr.gz");
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    std::io::Write::write_all(&mut e, &inr_bytes(&img, v)).expect("in memory");
    std::fs::write(&gz, e.finish().expect("in memory")).expect("write");
    assert_eq!(read_image(&gz).expect("readable"), img);
}

#[test]
fn a_gray_level_image_is_meshed_above_its_isovalue() {
    let (c0, r) = (DVec3::splat(10.0), 6.0f64);
    let mut v = Vec::new();
    for k in 0..21 {
        for j in 0..21 {
            for i in 0..21 {
                let d = (DVec3::new(i as f64, j as f64, k as f64) - c0).length();
                v.push((1000.0 - 100.0 * d) as f32);
            }
        }
    }
    let img = Image::axis_aligned([21; 3], DVec3::ONE, DVec3::ZERO, Voxels::F32(v));
    // Not labels: a clear error unless an isovalue is given.
    let e = ImageLabelOracle::new(&img, &ImageOptions::default()).err();
    assert!(e.is_some_and(|e| e.to_string().contains("isovalue")));
    let options = ImageOptions {
        isovalue: Some(400.0),
        ..ImageOptions::default()
    };
    let oracle = ImageLabelOracle::new(&img, &options).expect("valid");
    let c = mesh(&oracle, criteria(2.0, 0.3));
    let v = volumes(&c);
    assert_volume(
        v[&1],
        4.0 / 3.0 * PI * r.powi(3),
        4.0 * PI * r * r,
        0.3,
        1.0,
    );
}

#[test]
fn bad_images_are_errors_not_panics() {
    let empty = image([8, 8, 8], DVec3::ONE, |_| 0);
    let e = ImageLabelOracle::new(&empty, &ImageOptions::default()).err();
    assert!(e.is_some_and(|e| e.to_string().contains("nothing to mesh")));
    let dir = tempfile::tempdir().expect("temp dir");
    for (name, bytes) in [
        ("short.inr", b"#INRIMAGE-4#{\nXDIM=9\n".to_vec()),
        ("short.nii", vec![0u8; 100]),
        ("bad.vti", b"<VTKFile><ImageData".to_vec()),
        (
            "bad.nrrd",
            b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 999999 999999 999999\n\n".to_vec(),
        ),
        ("bad.inr.gz", vec![0x1f, 0x8b, 1, 2, 3]),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).expect("write");
        let e = read_image(&path).expect_err(name).to_string();
        assert!(e.starts_with(&path.display().to_string()), "{e}");
        assert!(!e.contains('\n'), "{e}");
    }
}
