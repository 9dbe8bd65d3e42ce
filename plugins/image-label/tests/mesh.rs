//! Meshes of synthetic labelled images made here: the labels of the tets match the voxels, the
//! volume of each label approaches the analytic one within a bound tied to the facet distance and
//! the voxel size, every interface is a closed 2-manifold, and the same image read from INR,
//! NIfTI and VTI gives the same bytes.

use delamesh_core::complex::MeshComplex;
use delamesh_core::oracle::{Oracle, PatchId, SubdomainId};
use delamesh_core::quality;
use delamesh_core::random::XorShift;
use delamesh_core::refine::criteria::MeshCriteria;
use delamesh_core::refine::{MeshOptions, mesh_domain};
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
    // Feature curves followed at the facet size, as the command line does for images, with the
    // image's smallest protecting ball.
    MeshCriteria {
        edge_min_size: 2.0,
        ..MeshCriteria::uniform(size, distance)
    }
}

fn mesh(oracle: &ImageLabelOracle, criteria: MeshCriteria) -> MeshComplex {
    let options = MeshOptions {
        optimize: delamesh_core::optimize::OptimizeOptions::none(),
        ..MeshOptions::new(criteria)
    };
    mesh_domain(oracle, &options, &mut |_| {})
        .expect("meshing succeeds")
        .complex
}

fn volumes(c: &MeshComplex) -> BTreeMap<u32, f64> {
    let mut v = BTreeMap::new();
    for (t, &s) in c.tet_subdomain.iter().enumerate() {
        let p = c.tet_points(t);
        *v.entry(s.0).or_insert(0.0) += (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]) / 6.0;
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
        if u32::from(label(voxel_centre)) != s.0 {
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
        let mut pair = c.facet_subdomains[f].map(|s| s.0);
        pair.sort_unstable();
        by_pair.entry(pair).or_default().push(c.facets[f]);
        match p {
            PatchId(0) => unrestricted += 1,
            p => assert_eq!(
                oracle.patch_subdomains(p).map(|s| s.map(|s| s.0)),
                Some(pair),
                "facet {f}"
            ),
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

/// [`assert_volume`] for a ball of radius `r`.
fn assert_ball_volume(v: f64, r: f64, distance: f64, voxel: f64) {
    assert_volume(
        v,
        4.0 / 3.0 * PI * r.powi(3),
        4.0 * PI * r * r,
        distance,
        voxel,
    );
}

#[test]
fn a_ball_is_meshed_inside_its_voxels_with_its_volume() {
    let (c0, r) = (DVec3::splat(12.0), 8.0);
    let label = |p: DVec3| u8::from((p - c0).length() <= r);
    let img = image([25, 25, 25], DVec3::ONE, label);
    let oracle = ImageLabelOracle::new(&img, &ImageOptions::default()).expect("valid image");
    assert_eq!(oracle.subdomains(), vec![SubdomainId(1)]);
    let (size, distance) = (3.0, 0.5);
    let c = mesh(&oracle, criteria(size, distance));
    assert!(c.tet_subdomain.iter().all(|&s| s == SubdomainId(1)));
    assert_tets_in_their_voxels(
        &c,
        DVec3::ONE,
        label,
        |p| ((p - c0).length() - r).abs(),
        1.5,
    );
    let v = volumes(&c);
    assert_ball_volume(v[&1], r, distance, 1.0);
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
    assert_eq!(oracle.subdomains(), vec![SubdomainId(3), SubdomainId(7)]);
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
    assert_ball_volume(v[&1], r, distance, 1.25);
    assert_closed_interfaces(&c, &oracle, &[([0, 1], 2)]);
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

/// The boundary of each label's region (the facets with that label on one side) is a closed
/// 2-manifold, of Euler characteristic `euler` when given.
fn assert_closed_regions(c: &MeshComplex, labels: &[u32], euler: Option<i64>) {
    for &l in labels {
        let facets: Vec<[u32; 3]> = (0..c.facets.len())
            .filter(|&f| c.facet_subdomains[f].contains(&SubdomainId(l)))
            .map(|f| c.facets[f])
            .collect();
        let t = quality::surface_topology(&facets);
        assert_eq!(t.border_edges, 0, "label {l}: border");
        assert_eq!(t.non_manifold_edges, 0, "label {l}: non-manifold edges");
        assert_eq!(
            t.non_manifold_vertices, 0,
            "label {l}: non-manifold vertices"
        );
        if let Some(euler) = euler {
            assert_eq!(t.euler_characteristic, euler, "label {l}");
        }
    }
}

/// The distance from `p` to the mesh's feature edges.
fn distance_to_feature_edges(c: &MeshComplex, p: DVec3) -> f64 {
    c.feature_edges
        .iter()
        .map(|e| {
            let (a, b) = (c.points[e[0] as usize], c.points[e[1] as usize]);
            delamesh_core::refine::curves::point_segment_distance(p, a, b)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Every segment is followed by mesh edges: 21 points along it lie within `tol` of one.
fn assert_segments_on_feature_edges(c: &MeshComplex, segments: &[[DVec3; 2]], tol: f64) {
    for s in segments {
        for k in 0..=20 {
            let p = s[0].lerp(s[1], f64::from(k) / 20.0);
            assert!(
                distance_to_feature_edges(c, p) <= tol,
                "{p} off the mesh edges"
            );
        }
    }
}

/// Each label's volume is within the relative tolerance `rel` of the wanted one.
fn assert_volumes_near(v: &BTreeMap<u32, f64>, want: &[(u32, f64)], rel: f64) {
    for &(l, want) in want {
        assert!(
            (v[&l] - want).abs() <= rel * want,
            "label {l}: {} vs {want}",
            v[&l]
        );
    }
}

/// The distance from `p` to the segment `[a, b]`.
fn to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    delamesh_core::refine::curves::point_segment_distance(p, a, b)
}

#[test]
fn triple_lines_of_three_touching_boxes_are_mesh_edges() {
    // Boxes side by side in x (labels 1, 2) on top of a slab (label 3), in the middle of the
    // image: the triple line where the three meet runs along y at x = 9.5, z = 7.5 (half-way
    // between voxel centres), and the lines where two of them meet the background run around.
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
    let (lo, hi) = (1.5, 18.5);
    // Where three classes meet: the line of the three labels, and on the faces of the union box
    // the lines where two labels meet the background.
    let triple: Vec<[DVec3; 2]> = {
        let v = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let mut s = vec![[v(9.5, lo, 7.5), v(9.5, hi, 7.5)]];
        for y in [lo, hi] {
            s.push([v(9.5, y, 7.5), v(9.5, y, hi)]);
            s.push([v(lo, y, 7.5), v(hi, y, 7.5)]);
        }
        s.push([v(9.5, lo, hi), v(9.5, hi, hi)]);
        for x in [lo, hi] {
            s.push([v(x, lo, 7.5), v(x, hi, 7.5)]);
        }
        s
    };
    let to_triple = |p: DVec3| {
        triple
            .iter()
            .map(|s| to_segment(p, s[0], s[1]))
            .fold(f64::INFINITY, f64::min)
    };
    assert!(!oracle.feature_curves().is_empty());
    for curve in oracle.feature_curves() {
        for &p in &curve.points {
            assert!(
                to_triple(p) <= 0.75,
                "curve {} point {p} off the lines",
                curve.id
            );
        }
    }
    let c = mesh(&oracle, criteria(3.0, 0.5));
    // The lines are chains of mesh edges: every feature edge on a line, every line covered.
    assert!(!c.feature_edges.is_empty());
    for e in &c.feature_edges {
        for &v in e {
            assert!(to_triple(c.points[v as usize]) <= 0.75);
        }
    }
    assert_segments_on_feature_edges(&c, &triple, 0.75);
    assert_closed_regions(&c, &[1, 2, 3], Some(2));
    let dist = |p: DVec3| {
        let mut d = (p.z - 7.5).abs().min((p.x - 9.5).abs());
        for a in 0..3 {
            d = d.min((p[a] - lo).abs()).min((p[a] - hi).abs());
        }
        d
    };
    assert_tets_in_their_voxels(&c, DVec3::ONE, label, dist, 1.5);
    // The volumes: the triple lines are followed, only the box creases (two classes) are rounded
    // off, by about the facet distance across each.
    let v = volumes(&c);
    let exact = |dx: f64, dz: f64| dx * 17.0 * dz;
    assert_volumes_near(
        &v,
        &[
            (1, exact(8.0, 11.0)),
            (2, exact(9.0, 11.0)),
            (3, exact(17.0, 6.0)),
        ],
        0.05,
    );
}

#[test]
fn labels_filling_the_image_keep_its_box_edges_and_border_curves() {
    // Two labels split at x = 7.5 fill the whole image: its faces are boundary, its edges creases,
    // and the interface meets the faces along a square loop.
    let n = 14;
    let label = |p: DVec3| if p.x < 7.5 { 1 } else { 2 };
    let img = image([n, n, n], DVec3::ONE, label);
    let oracle = ImageLabelOracle::new(&img, &ImageOptions::default()).expect("valid image");
    let c = mesh(&oracle, criteria(3.0, 0.3));
    let m = (n - 1) as f64;
    let v = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let mut lines = Vec::new();
    for a in [0.0, m] {
        for b in [0.0, m] {
            lines.push([v(0.0, a, b), v(m, a, b)]);
            lines.push([v(a, 0.0, b), v(a, m, b)]);
            lines.push([v(a, b, 0.0), v(a, b, m)]);
        }
        lines.push([v(7.5, a, 0.0), v(7.5, a, m)]);
        lines.push([v(7.5, 0.0, a), v(7.5, m, a)]);
    }
    assert_segments_on_feature_edges(&c, &lines, 0.5);
    assert_closed_regions(&c, &[1, 2], Some(2));
    // With its edges followed, the box is meshed exactly but for the interface's rounding.
    let v = volumes(&c);
    let area = m * m;
    assert_volumes_near(&v, &[(1, 7.5 * area), (2, (m - 7.5) * area)], 0.01);
}

#[test]
fn random_blobs_of_labels_are_meshed_along_their_junctions() {
    // Overlapping balls of four labels at seeded random places: junctions nobody laid out.
    let n = 24;
    let mut rng = XorShift::new(0x2545_f491_4f6c_dd1d);
    let mut next = move || rng.next_f64();
    let balls: Vec<(DVec3, f64, u8)> = (0..7)
        .map(|k| {
            let c = DVec3::new(next(), next(), next()) * 14.0 + 4.5;
            (c, 3.0 + 3.0 * next(), 1 + (k % 4) as u8)
        })
        .collect();
    let label = |p: DVec3| {
        balls
            .iter()
            .rev()
            .find(|(c, r, _)| p.distance(*c) <= *r)
            .map_or(0, |b| b.2)
    };
    let img = image([n, n, n], DVec3::ONE, label);
    let oracle = ImageLabelOracle::new(&img, &ImageOptions::default()).expect("valid image");
    let c = mesh(&oracle, criteria(2.5, 0.4));
    // Feature edges only where three classes (the outside of the image among them) meet: near
    // a cube of voxels with three labels or more.
    let class = |v: [i64; 3]| {
        if v.iter().any(|&x| x < 0 || x >= n as i64) {
            u8::MAX
        } else {
            label(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64))
        }
    };
    let near_junction = |p: DVec3| {
        let base = p.floor().as_i64vec3();
        (-1..=1).any(|dz| {
            (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let o = [base.x + dx, base.y + dy, base.z + dz];
                    let mut seen = Vec::new();
                    for m in 0..8 {
                        let l = class([o[0] + (m & 1), o[1] + ((m >> 1) & 1), o[2] + (m >> 2)]);
                        if !seen.contains(&l) {
                            seen.push(l);
                        }
                    }
                    seen.len() >= 3
                })
            })
        })
    };
    assert!(!c.feature_edges.is_empty());
    for e in &c.feature_edges {
        for &v in e {
            let p = c.points[v as usize];
            assert!(near_junction(p), "feature vertex {p} far from any junction");
        }
    }
    // Away from the interfaces (no voxel of another label within 1.5), tets lie in their label.
    let away = |p: DVec3| {
        let l = label(p.round());
        let base = p.round().as_i64vec3();
        let mut same = true;
        for dz in -2..=2 {
            for dy in -2..=2 {
                for dx in -2..=2 {
                    let q = DVec3::new(
                        (base.x + dx) as f64,
                        (base.y + dy) as f64,
                        (base.z + dz) as f64,
                    );
                    if q.distance(p) <= 1.5 && label(q) != l {
                        same = false;
                    }
                }
            }
        }
        if same { 2.0 } else { 0.0 }
    };
    assert_tets_in_their_voxels(&c, DVec3::ONE, label, away, 1.0);
    // The boundary of the labelled region (against label 0, the outside), and of each label's
    // region, is a closed 2-manifold (the validity repairs' target).
    assert_closed_regions(&c, &[0, 1, 2, 3, 4], None);
}

#[test]
fn a_single_cube_of_four_labels_keeps_its_junction_and_volumes() {
    // CGAL's feature-detection case 12323: eight voxels, four classes (the background one), one
    // junction of triple lines inside the cube, border curves on all its faces.
    let values = [0u8, 0, 0, 1, 2, 3, 2, 3];
    let img = Image::axis_aligned(
        [2, 2, 2],
        DVec3::ONE,
        DVec3::ZERO,
        Voxels::U8(values.to_vec()),
    );
    let oracle = ImageLabelOracle::new(&img, &ImageOptions::default()).expect("valid image");
    assert!(!oracle.feature_curves().is_empty());
    let distance = 0.03;
    let mut c = criteria(0.25, distance);
    c.edge_min_size = oracle.default_criteria().edge_min_size;
    let c = mesh(&oracle, c);
    assert!(!c.feature_edges.is_empty());
    // The volume of each label of the oracle's own partition, by the midpoint rule.
    let n = 60;
    let mut exact: BTreeMap<u32, f64> = BTreeMap::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = (DVec3::new(i as f64, j as f64, k as f64) + 0.5) / n as f64;
                *exact.entry(oracle.subdomain(p).0).or_insert(0.0) += 1.0 / (n * n * n) as f64;
            }
        }
    }
    let v = volumes(&c);
    for l in [1, 2, 3] {
        // Each facet within the facet distance of the interfaces (the surface level's bound).
        let area: f64 = (0..c.facets.len())
            .filter(|&f| c.facet_subdomains[f].contains(&SubdomainId(l)))
            .map(|f| {
                let [a, b, d] = c.facets[f].map(|v| c.points[v as usize]);
                0.5 * (b - a).cross(d - a).length()
            })
            .sum();
        assert_volume(v[&l], exact[&l], area, distance, 0.0);
    }
    assert_closed_regions(&c, &[1, 2, 3], Some(2));
}

#[test]
fn random_label_images_give_no_cluster_of_vertices_nor_flat_tets() {
    // Seeded images nobody laid out: balls, boxes and speckle of up to four labels on grids of
    // 8 to 23 voxels a side, anisotropic voxels, meshed with the image's default criteria (and
    // optimisation). Near-coincident surface points (one crossing found by two probes) used to
    // leave cells flat and pack vertices into the gap, 1e-7 apart.
    let mut rng = XorShift::new(0x5851_f42d_4c95_7f2d);
    let mut meshed = 0;
    for _ in 0..24 {
        let mut next = || rng.next_f64();
        let dims = [0; 3].map(|_: usize| 8 + (next() * 16.0) as usize);
        let spacing = DVec3::new(0.3 + 1.7 * next(), 0.3 + 1.7 * next(), 0.3 + 1.7 * next());
        let extent = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) * spacing;
        let shapes: Vec<(u8, DVec3, DVec3, u8)> = (0..1 + (next() * 5.0) as usize)
            .map(|_| {
                let kind = (next() * 3.0) as u8;
                let c = DVec3::new(next(), next(), next()) * extent;
                let r = extent.min_element() * (0.1 + 0.4 * next());
                let half = DVec3::new(r, r * (0.3 + 0.7 * next()), r * (0.3 + 0.7 * next()));
                (kind, c, half, 1 + (next() * 4.0) as u8)
            })
            .collect();
        // Speckle: 2 % of the voxels, drawn per voxel ahead (the labelling is a plain function).
        let speckle: Vec<bool> = (0..dims[0] * dims[1] * dims[2])
            .map(|_| next() < 0.02)
            .collect();
        let img = image(dims, spacing, |p| {
            let i = (p / spacing).round().as_uvec3();
            let voxel = i.x as usize + dims[0] * (i.y as usize + dims[1] * i.z as usize);
            let mut l = 0;
            for &(kind, c, half, label) in &shapes {
                let inside = match kind {
                    0 => p.distance(c) < half.x,
                    1 => ((p - c).abs() - half).max_element() < 0.0,
                    _ => speckle[voxel],
                };
                if inside {
                    l = label;
                }
            }
            l
        });
        let Ok(oracle) = ImageLabelOracle::new(&img, &ImageOptions::default()) else {
            continue;
        };
        let Ok(outcome) = mesh_domain(
            &oracle,
            &MeshOptions::new(oracle.default_criteria()),
            &mut |_| {},
        ) else {
            continue;
        };
        let c = outcome.complex;
        let edges = |t: usize| {
            let p = c.tet_points(t);
            (0..4).flat_map(move |i| (i + 1..4).map(move |j| p[i].distance(p[j])))
        };
        let longest = (0..c.tets.len()).flat_map(edges).fold(0.0, f64::max);
        for t in 0..c.tets.len() {
            let shortest = edges(t).fold(f64::INFINITY, f64::min);
            assert!(
                shortest > 1e-3 * longest,
                "tet {t}: edge {shortest:e} of {longest}"
            );
            let volume = quality::tet_volume(&c.tet_points(t));
            assert!(volume > 1e-12 * longest.powi(3), "tet {t} flat: {volume:e}");
        }
        meshed += 1;
    }
    assert!(meshed >= 16, "{meshed} images meshed");
}

#[test]
fn the_default_flips_mend_slivers_between_feature_curves() {
    // A ball of label 1 cut by a slab of label 2 and a wedge of label 3: triple lines and
    // corners where they meet, with slivers between their protected vertices that
    // perturbation and exudation leave (3.9° here).
    let label = |p: DVec3| {
        let q = p - DVec3::splat(10.0);
        match () {
            _ if q.length() > 8.3 => 0,
            _ if q.z.abs() < 1.7 + 0.2 * q.x => 2,
            _ if q.x > 0.6 * q.y.abs() => 3,
            _ => 1,
        }
    };
    let img = image([21, 21, 21], DVec3::ONE, label);
    let oracle = ImageLabelOracle::new(&img, &ImageOptions::default()).expect("valid image");
    let run = |flip| {
        let options = MeshOptions {
            optimize: delamesh_core::optimize::OptimizeOptions {
                flip,
                ..Default::default()
            },
            ..MeshOptions::new(criteria(2.5, 0.4))
        };
        mesh_domain(&oracle, &options, &mut |_| {}).expect("meshing succeeds")
    };
    use delamesh_core::optimize::{Flips, STUCK_FLIP_DEG};
    let (regular, flipped) = (run(Flips::Off), run(Flips::Slivers));
    let smallest = |c: &MeshComplex| {
        (0..c.tets.len())
            .flat_map(|t| quality::dihedral_angles_deg(&c.tet_points(t)))
            .fold(180.0, f64::min)
    };
    let (before, after) = (smallest(&regular.complex), smallest(&flipped.complex));
    assert!(before < STUCK_FLIP_DEG, "no sliver left to mend: {before}°");
    assert!(after > before, "{before}° -> {after}°");
    let report = flipped.optimization.steps.last().expect("a flip step");
    assert_eq!(report.step.name(), "flip");
    // The flips keep every label's region: its facets, and its volume to rounding.
    assert_eq!(flipped.complex.facets, regular.complex.facets);
    for ((l, a), b) in volumes(&flipped.complex)
        .iter()
        .zip(volumes(&regular.complex).values())
    {
        assert!((a - b).abs() <= 1e-9 * b, "label {l}: {a} vs {b}");
    }
}
