//! `--preserve-surface`: the input surface kept exactly. Properties checked on every output:
//! every input vertex is a mesh vertex, every tetrahedron is positive (exact orientation) and
//! locally Delaunay, every boundary facet lies in one input triangle and carries its patch, the
//! facets of each input triangle add up to its area, and the volume of each subdomain is the
//! volume its input surfaces enclose.

mod cli_support;
mod common;

use cli_support::{delamesh, test_data};
use common::{Surface, cuboid, sphere};
use delamesh::core::complex::VertexDimension;
use delamesh::core::kernel::{Point3, Sign, insphere, orient3d};
use delamesh::core::mesh::{PatchId, SurfaceMesh};
use delamesh::core::optimize::{OptimizeOptions, Step};
use delamesh::core::oracle::OUTSIDE;
use delamesh::core::quality::enclosed_volume;
use delamesh::{MeshSettings, Mesher};
use glam::DVec3;
use std::collections::{BTreeMap, HashMap};

/// The surface kept with the default options: optimised, the boundary fixed.
fn preserved(name: &str, surface: &Surface) -> delamesh::Meshed {
    let settings = MeshSettings::builder()
        .preserve_surface(true)
        .build()
        .expect("valid settings");
    preserved_with(name, surface, settings)
}

/// The surface kept without optimisation: the conforming Delaunay mesh.
fn preserved_delaunay(name: &str, surface: &Surface) -> delamesh::Meshed {
    let settings = MeshSettings::builder()
        .preserve_surface(true)
        .optimize(OptimizeOptions::none())
        .build()
        .expect("valid settings");
    preserved_with(name, surface, settings)
}

fn preserved_with(name: &str, surface: &Surface, settings: MeshSettings) -> delamesh::Meshed {
    let mut mesh = SurfaceMesh::from_triangles(surface.points.clone(), surface.triangles.clone());
    // One patch per triangle, so that a facet's patch names the triangle it must lie in.
    mesh.patches = (0..mesh.triangles.len() as u32).map(PatchId).collect();
    mesh.patch_names = (0..mesh.triangles.len()).map(|t| format!("t{t}")).collect();
    Mesher::new(settings)
        .mesh_surface(name, mesh)
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn signed_volume6(p: [Point3; 4]) -> f64 {
    (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0])
}

fn area(p: [Point3; 3]) -> f64 {
    0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
}

/// Whether `p` lies in triangle `t`: exactly on its plane when it is an input vertex, within
/// rounding otherwise, and inside its edges.
fn lies_in(p: Point3, t: [Point3; 3], input_vertex: bool, tolerance: f64) -> bool {
    let normal = (t[1] - t[0]).cross(t[2] - t[0]);
    let unit = normal.normalize();
    if input_vertex {
        if orient3d(t[0], t[1], t[2], p) != Sign::Zero {
            return false;
        }
    } else if unit.dot(p - t[0]).abs() > tolerance {
        return false;
    }
    (0..3).all(|k| unit.dot((t[(k + 1) % 3] - t[k]).cross(p - t[k])) >= -tolerance)
}

/// Positive tetrahedra (output convention: the opposite of Shewchuk's orient3d sign), none flat
/// (|6V| at most 1e-12 of its longest edge cubed): Steiner points rounded off their triangle's
/// plane make such cells on the boundary, which go outside, and four boundary points nearly
/// cospherical make them inside, which are refined. Returns the total volume.
fn assert_positive_not_flat(name: &str, c: &delamesh::core::complex::MeshComplex) -> f64 {
    let mut total = 0.0;
    for (t, tet) in c.tets.iter().enumerate() {
        let p = tet.map(|v| c.points[v as usize]);
        assert_eq!(
            orient3d(p[0], p[1], p[2], p[3]),
            Sign::Negative,
            "{name}: tet {t} not positive"
        );
        let longest = (0..4)
            .flat_map(|i| (i + 1..4).map(move |j| p[i].distance(p[j])))
            .fold(0.0, f64::max);
        assert!(
            signed_volume6(p).abs() > 1e-12 * longest.powi(3),
            "{name}: tet {t} is flat"
        );
        total += signed_volume6(p) / 6.0;
    }
    total
}

/// Every property of a kept surface; `subdomain_volumes` maps each expected subdomain volume.
/// A mesh left as recovery made it (`optimised` false) is locally Delaunay; an optimised one
/// went through the flips, and its smallest dihedral angle did not drop.
fn check(
    name: &str,
    surface: &Surface,
    meshed: &delamesh::Meshed,
    subdomain_volumes: &[f64],
    optimised: bool,
) {
    let c = &meshed.complex;
    let diagonal = {
        let (lo, hi) = surface.points.iter().fold(
            (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        (hi - lo).length()
    };
    // Every input vertex is a mesh vertex.
    let index: HashMap<[u64; 3], usize> = c
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| (p.to_array().map(f64::to_bits), i))
        .collect();
    for p in &surface.points {
        assert!(
            index.contains_key(&p.to_array().map(f64::to_bits)),
            "{name}: input vertex {p} missing"
        );
    }
    let is_input: Vec<bool> = {
        let set: std::collections::HashSet<[u64; 3]> = surface
            .points
            .iter()
            .map(|p| p.to_array().map(f64::to_bits))
            .collect();
        c.points
            .iter()
            .map(|p| set.contains(&p.to_array().map(f64::to_bits)))
            .collect()
    };
    assert_positive_not_flat(name, c);
    let report = &meshed.optimization;
    if optimised {
        assert_eq!(
            report.steps.last().map(|s| s.step),
            Some(Step::Flip),
            "{name}"
        );
        assert!(
            report.after().min_dihedral_deg >= report.before.min_dihedral_deg,
            "{name}: smallest angle {} after optimisation, {} before",
            report.after().min_dihedral_deg,
            report.before.min_dihedral_deg
        );
    } else {
        assert!(report.steps.is_empty(), "{name}: optimised");
    }
    // Every face in two tetrahedra at most; unless optimised, locally Delaunay: across every
    // face shared by two tetrahedra, the far vertex is not strictly inside the other's
    // circumsphere.
    let mut faces: HashMap<[u32; 3], Vec<(usize, u32)>> = HashMap::new();
    for (t, tet) in c.tets.iter().enumerate() {
        for i in 0..4 {
            let mut f = [0, 1, 2, 3].map(|k| tet[k]);
            let apex = f[i];
            let mut face = [f[(i + 1) % 4], f[(i + 2) % 4], f[(i + 3) % 4]];
            face.sort_unstable();
            f.sort_unstable();
            faces.entry(face).or_default().push((t, apex));
        }
    }
    for (face, sides) in &faces {
        assert!(
            sides.len() <= 2,
            "{name}: face {face:?} in {} tets",
            sides.len()
        );
        if let [(t, _), (_, apex)] = sides[..]
            && !optimised
        {
            let p = c.tets[t].map(|v| c.points[v as usize]);
            let e = c.points[apex as usize];
            // Positive output tets are negative in Shewchuk's sign: inside is a negative insphere.
            assert_ne!(
                insphere(p[0], p[1], p[2], p[3], e),
                Sign::Negative,
                "{name}: not Delaunay across {face:?}"
            );
        }
    }
    // Boundary facets: each in its input triangle (its patch names it), areas adding up.
    let tolerance = 1e-12 * diagonal;
    let mut facet_area: BTreeMap<u32, f64> = BTreeMap::new();
    for (f, facet) in c.facets.iter().enumerate() {
        let patch = c.facet_patch[f].0;
        assert!(patch >= 1, "{name}: facet {f} without a patch");
        let t = (patch - 1) as usize;
        let tri = surface.triangles[t].map(|v| surface.points[v as usize]);
        for &v in facet {
            let p = c.points[v as usize];
            assert!(
                lies_in(p, tri, is_input[v as usize], tolerance),
                "{name}: facet {f} vertex {p} not in input triangle {t}"
            );
        }
        *facet_area.entry(t as u32).or_default() += area(facet.map(|v| c.points[v as usize]));
    }
    for (t, tri) in surface.triangles.iter().enumerate() {
        let want = area(tri.map(|v| surface.points[v as usize]));
        let got = facet_area.get(&(t as u32)).copied().unwrap_or(0.0);
        assert!(
            (got - want).abs() <= 1e-9 * want.max(diagonal * diagonal * 1e-6),
            "{name}: input triangle {t} has area {want}, its facets {got}"
        );
    }
    // Volumes per subdomain.
    let mut volumes: BTreeMap<u32, f64> = BTreeMap::new();
    for (t, tet) in c.tets.iter().enumerate() {
        assert_ne!(c.tet_subdomain[t], OUTSIDE);
        *volumes.entry(c.tet_subdomain[t].0).or_default() +=
            signed_volume6(tet.map(|v| c.points[v as usize])) / 6.0;
    }
    let mut got: Vec<f64> = volumes.values().copied().collect();
    let mut want = subdomain_volumes.to_vec();
    got.sort_by(f64::total_cmp);
    want.sort_by(f64::total_cmp);
    assert_eq!(got.len(), want.len(), "{name}: subdomains {volumes:?}");
    for (g, w) in got.iter().zip(&want) {
        assert!(
            (g - w).abs() <= 1e-9 * w.abs(),
            "{name}: volume {g}, input {w}"
        );
    }
}

/// Checks the kept surface without and with optimisation.
fn check_closed(name: &str, surface: &Surface) {
    let volume = enclosed_volume(&surface.points, &surface.triangles);
    check(
        name,
        surface,
        &preserved_delaunay(name, surface),
        &[volume],
        false,
    );
    check(name, surface, &preserved(name, surface), &[volume], true);
}

/// The prism over a counter-clockwise polygon `ring` triangulated by `caps`, from z = 0 to `h`.
fn prism(ring: &[[f64; 2]], caps: &[[u32; 3]], h: f64) -> Surface {
    let n = ring.len() as u32;
    let mut points: Vec<DVec3> = ring.iter().map(|p| DVec3::new(p[0], p[1], 0.0)).collect();
    points.extend(ring.iter().map(|p| DVec3::new(p[0], p[1], h)));
    let mut triangles = Vec::new();
    for &[a, b, c] in caps {
        triangles.push([a, c, b]);
        triangles.push([a + n, b + n, c + n]);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        triangles.push([i, j, j + n]);
        triangles.push([i, j + n, i + n]);
    }
    Surface { points, triangles }
}

#[test]
fn cube_and_sphere_keep_their_triangles() {
    check_closed("cube", &cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 0.5)));
    check_closed("sphere", &sphere(DVec3::new(0.1, 0.2, 0.3), 1.0, 2));
}

#[test]
fn wedges_of_small_angles_keep_their_triangles() {
    for degrees in [20.0f64, 5.0, 1.0] {
        let a = degrees.to_radians();
        let ring = [[0.0, 0.0], [1.0, 0.0], [a.cos(), a.sin()]];
        check_closed(
            &format!("wedge {degrees}°"),
            &prism(&ring, &[[0, 1, 2]], 0.4),
        );
    }
}

#[test]
fn box_with_a_thin_slot_keeps_its_triangles() {
    // A U-shaped section: a slot 0.02 wide and 0.7 deep cut into a 3 × 1 block.
    let (l, r) = (1.49, 1.51);
    let ring = [
        [0.0, 0.0],
        [l, 0.0],
        [r, 0.0],
        [3.0, 0.0],
        [3.0, 1.0],
        [r, 1.0],
        [r, 0.3],
        [l, 0.3],
        [l, 1.0],
        [0.0, 1.0],
    ];
    let caps = [
        [0, 1, 7],
        [0, 7, 8],
        [0, 8, 9],
        [1, 2, 6],
        [1, 6, 7],
        [3, 4, 5],
        [3, 5, 6],
        [3, 6, 2],
    ];
    check_closed("slot", &prism(&ring, &caps, 0.8));
}

/// The cell criteria refine the volume and keep the surface: every check above still holds,
/// points are added inside, every cell with no vertex on the surface meets the size bound, and
/// nearly all of them the radius-edge bound.
#[test]
fn cell_criteria_refine_the_volume_and_keep_the_triangles() {
    let (ratio, size) = (1.5, 0.2);
    let ring = [[0.0, 0.0], [1.0, 0.0], [1.0, 0.3], [0.0, 1.0]];
    for (name, surface) in [
        ("cube", cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 0.5))),
        ("sphere", sphere(DVec3::new(0.1, 0.2, 0.3), 1.0, 2)),
        ("prism", prism(&ring, &[[0, 1, 2], [0, 2, 3]], 0.8)),
    ] {
        // The criteria are refinement's: optimisation does not bound cell sizes.
        let settings = MeshSettings::builder()
            .preserve_surface(true)
            .cell_radius_edge_ratio(ratio)
            .cell_size(size)
            .optimize(OptimizeOptions::none())
            .build()
            .expect("valid settings");
        let meshed = preserved_with(name, &surface, settings);
        let volume = enclosed_volume(&surface.points, &surface.triangles);
        check(name, &surface, &meshed, &[volume], false);
        let c = &meshed.complex;
        let inside = |v: u32| c.vertex_dimension[v as usize] == VertexDimension::Volume;
        assert!(
            (0..c.points.len() as u32).any(inside),
            "{name}: no point inside"
        );
        let (mut away, mut shaped) = (0, 0);
        for tet in c.tets.iter().filter(|t| t.iter().all(|&v| inside(v))) {
            let p = tet.map(|v| c.points[v as usize]);
            let center = delamesh::core::quality::tet_circumcenter(&p).expect("not flat");
            let radius = center.distance(p[0]);
            let shortest = (0..4)
                .flat_map(|i| (i + 1..4).map(move |j| p[i].distance(p[j])))
                .fold(f64::INFINITY, f64::min);
            assert!(
                radius <= size * (1.0 + 1e-9),
                "{name}: circumradius {radius}"
            );
            away += 1;
            if radius / shortest <= ratio * (1.0 + 1e-9) {
                shaped += 1;
            }
        }
        // The shape bound yields near the surface when meeting it would split the input finer
        // than itself; away from it, nearly every cell meets it.
        assert!(
            shaped as f64 >= 0.9 * away as f64,
            "{name}: {shaped} of {away} cells meet the radius-edge bound"
        );
        assert!(away > 0, "{name}: no cell away from the surface");
    }
}

#[test]
fn nested_boxes_give_two_subdomains() {
    let outer = cuboid(DVec3::ZERO, DVec3::ONE);
    let inner = cuboid(DVec3::splat(0.3), DVec3::splat(0.6));
    let surface = outer.merge(inner);
    let meshed = preserved("nested", &surface);
    check("nested", &surface, &meshed, &[1.0 - 0.027, 0.027], true);
}

/// `csg_0900` is a part of `benches/csg_parts.py --seed 900`; `csg_11001` and `csg_11002`, of
/// `--seed 11000`, had flat cells inside, of four Steiner points on two nearly coplanar faces.
#[test]
fn random_csg_parts_keep_their_triangles() {
    for name in ["csg_0900", "csg_11001", "csg_11002"] {
        let read = delamesh::formats::read_surface(&test_data(&format!("csg/{name}.off")), None)
            .expect("fixture reads")
            .mesh;
        let surface = Surface {
            points: read.positions,
            triangles: read.triangles,
        };
        check_closed(name, &surface);
    }
}

/// Checks a mesh that keeps the boundary of a dirty surface's winding-number domain: tets
/// positive and not flat, boundary facets a closed 2-manifold of Euler characteristic `euler`
/// lying on the triangles of `on` (the input, or the surface it should be repaired into), and
/// the volume.
fn check_kept_boundary(name: &str, surface: &Surface, on: &Surface, volume: f64, euler: i64) {
    let meshed = preserved(name, surface);
    let c = &meshed.complex;
    let diagonal = 3f64.sqrt() * 2.0;
    let total = assert_positive_not_flat(name, c);
    assert!(
        (total - volume).abs() <= 1e-9 * volume,
        "{name}: volume {total}, expected {volume}"
    );
    assert_facets_on(name, c, &on.points, &on.triangles, 1e-9 * diagonal);
    assert_eq!(
        closed_oriented_euler(name, c),
        euler,
        "{name}: Euler characteristic"
    );
}

/// Asserts that every boundary facet vertex lies within `tolerance` of the surface `triangles`.
fn assert_facets_on(
    name: &str,
    c: &delamesh::core::complex::MeshComplex,
    points: &[Point3],
    triangles: &[[u32; 3]],
    tolerance: f64,
) {
    for f in &c.facets {
        for &v in f {
            let p = c.points[v as usize];
            let near = triangles
                .iter()
                .map(|t| {
                    let tri = t.map(|v| points[v as usize]);
                    delamesh::polyhedral::closest_point_on_triangle(p, &tri).distance(p)
                })
                .fold(f64::MAX, f64::min);
            assert!(near <= tolerance, "{name}: facet vertex {p} off the input");
        }
    }
}

/// Asserts that the boundary facets form a closed, oriented 2-manifold (every edge in two
/// facets, traversed in opposite directions, no pinched vertex) and returns its Euler
/// characteristic.
fn closed_oriented_euler(name: &str, c: &delamesh::core::complex::MeshComplex) -> i64 {
    let mut uses: HashMap<[u32; 2], (usize, i32)> = HashMap::new();
    let mut fans: HashMap<u32, Vec<[u32; 2]>> = HashMap::new();
    for f in &c.facets {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            let entry = uses.entry([a.min(b), a.max(b)]).or_default();
            entry.0 += 1;
            entry.1 += if a < b { 1 } else { -1 };
            fans.entry(f[k]).or_default().push([b, f[(k + 2) % 3]]);
        }
    }
    assert!(uses.values().all(|u| u.0 == 2), "{name}: not edge-manifold");
    assert!(uses.values().all(|u| u.1 == 0), "{name}: not oriented");
    // Around each vertex, the facets' far edges make one cycle.
    for (v, link) in &fans {
        let mut next: HashMap<u32, u32> = link.iter().map(|e| (e[0], e[1])).collect();
        let start = link[0][0];
        let mut at = start;
        let mut steps = 0;
        while let Some(n) = next.remove(&at) {
            at = n;
            steps += 1;
        }
        assert!(
            at == start && steps == link.len(),
            "{name}: vertex {v} pinched"
        );
    }
    let vertices = fans.len() as i64;
    vertices - uses.len() as i64 + c.facets.len() as i64
}

/// Volume of the union of axis-aligned boxes, by inclusion–exclusion.
fn union_volume(boxes: &[(DVec3, DVec3)]) -> f64 {
    let mut total = 0.0;
    for mask in 1u32..(1 << boxes.len()) {
        let (mut lo, mut hi) = (DVec3::splat(f64::MIN), DVec3::splat(f64::MAX));
        for (i, b) in boxes.iter().enumerate() {
            if mask & (1 << i) != 0 {
                lo = lo.max(b.0);
                hi = hi.min(b.1);
            }
        }
        let size = (hi - lo).max(DVec3::ZERO);
        let sign = if mask.count_ones() % 2 == 1 {
            1.0
        } else {
            -1.0
        };
        total += sign * size.x * size.y * size.z;
    }
    total
}

#[test]
fn crossing_boxes_keep_the_boundary_of_their_union() {
    // Corners off every face diagonal of the others, so that every contact is a crossing.
    let boxes = [
        (DVec3::ZERO, DVec3::ONE),
        (DVec3::new(0.31, 0.27, 0.23), DVec3::new(1.31, 1.27, 1.23)),
        (DVec3::new(0.62, -0.19, 0.44), DVec3::new(1.62, 0.81, 1.44)),
    ];
    let two = cuboid(boxes[0].0, boxes[0].1).merge(cuboid(boxes[1].0, boxes[1].1));
    check_kept_boundary("two boxes", &two, &two, union_volume(&boxes[..2]), 2);
    // Three boxes: their faces meet at triple points, where three cut triangles share a point.
    let three = two.merge(cuboid(boxes[2].0, boxes[2].1));
    check_kept_boundary("three boxes", &three, &three, union_volume(&boxes), 2);
}

#[test]
fn reoriented_open_and_duplicated_surfaces_are_kept_repaired() {
    let cube = cuboid(DVec3::ZERO, DVec3::ONE);
    let mut shuffled = cube.clone();
    for t in shuffled.triangles.iter_mut().step_by(3) {
        t.swap(1, 2);
    }
    check_kept_boundary("shuffled", &shuffled, &cube, 1.0, 2);
    // A missing face is capped by a fan from its centroid.
    let mut open = cube.clone();
    open.triangles.pop();
    check_kept_boundary("open", &open, &cube, 1.0, 2);
    let mut duplicated = cube.clone();
    duplicated.triangles.push(duplicated.triangles[0]);
    duplicated.triangles.push([0, 0, 1]);
    check_kept_boundary("duplicated", &duplicated, &cube, 1.0, 2);
}

#[test]
fn dirty_surfaces_are_refused_with_strict() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut open = cuboid(DVec3::ZERO, DVec3::ONE);
    open.triangles.pop();
    let crossing =
        cuboid(DVec3::ZERO, DVec3::ONE).merge(cuboid(DVec3::splat(0.5), DVec3::splat(1.5)));
    for (name, surface, problem) in [
        ("open", open, "not closed"),
        ("crossing", crossing, "intersect"),
    ] {
        let input = dir.path().join(format!("{name}.off"));
        std::fs::write(&input, surface.to_off()).expect("write input");
        let out = dir.path().join(format!("{name}.vtu"));
        let assert = delamesh()
            .args(["mesh", "-q", "--preserve-surface", "--strict"])
            .arg(&input)
            .arg("-o")
            .arg(&out)
            .assert()
            .failure()
            .code(1);
        let stderr = String::from_utf8_lossy(&assert.get_output().stderr).to_string();
        assert!(
            stderr.contains("--preserve-surface") && stderr.contains(problem),
            "{name}: {stderr}"
        );
        assert!(!out.exists(), "{name}: output left behind");
    }
}

#[test]
fn resampling_options_are_refused_with_preserve_surface() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = dir.path().join("cube.off");
    std::fs::write(&input, cuboid(DVec3::ZERO, DVec3::ONE).to_off()).expect("write input");
    let assert = delamesh()
        .args(["mesh", "-q", "--preserve-surface", "--facet-size", "0.1"])
        .arg(&input)
        .arg("-o")
        .arg(dir.path().join("cube.vtu"))
        .assert()
        .failure();
    let stderr = String::from_utf8_lossy(&assert.get_output().stderr).to_string();
    assert!(
        stderr.contains("--preserve-surface") && stderr.contains("--facet-size"),
        "{stderr}"
    );
    // And the library refuses the merge of coplanar triangles without a surface to keep.
    let refused = MeshSettings::builder().merge_coplanar(true).build();
    assert!(refused.is_err_and(|e| e.to_string().contains("--preserve-surface")));
}

/// `delamesh mesh INPUT --preserve-surface -o OUT`, which must succeed, and its report.
fn kept_by_the_cli(input: &std::path::Path, out: &std::path::Path) -> serde_json::Value {
    let report = out.with_extension("json");
    delamesh()
        .args(["mesh", "-q", "--preserve-surface"])
        .arg(input)
        .arg("-o")
        .arg(out)
        .arg("--report")
        .arg(&report)
        .assert()
        .success();
    serde_json::from_slice(&std::fs::read(&report).expect("report written")).expect("JSON")
}

#[test]
fn the_cli_writes_the_kept_surface() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = dir.path().join("cube.off");
    let cube = cuboid(DVec3::ZERO, DVec3::ONE);
    std::fs::write(&input, cube.to_off()).expect("write input");
    let r = kept_by_the_cli(&input, &dir.path().join("cube.mesh"));
    assert_eq!(r["boundary"]["closed"], true);
    assert_eq!(r["quality"]["inverted_tets"], 0);
    let ratio = r["approximation"]["volume_ratio"].as_f64().expect("number");
    assert!((ratio - 1.0).abs() < 1e-12, "volume ratio {ratio}");
}

/// An L-shaped prism written with polygon faces: each cap a hexagon listed from a vertex its
/// other vertices are not all visible from (a fan from there folds over the notch), the sides
/// quads. Kept as written, it encloses the L's area times the height.
#[test]
fn non_convex_polygon_faces_are_kept() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = dir.path().join("l.off");
    let ring = [
        [2.0, 1.0],
        [1.0, 1.0],
        [1.0, 2.0],
        [0.0, 2.0],
        [0.0, 0.0],
        [2.0, 0.0],
    ];
    let mut off = String::from("OFF\n12 8 0\n");
    for z in [0.0, 1.0] {
        for [x, y] in ring {
            off += &format!("{x} {y} {z}\n");
        }
    }
    // The ring turns clockwise seen from above: the bottom cap as listed faces down.
    off += "6 0 1 2 3 4 5\n6 6 11 10 9 8 7\n";
    for k in 0..6 {
        let next = (k + 1) % 6;
        off += &format!("4 {k} {} {} {next}\n", k + 6, next + 6);
    }
    std::fs::write(&input, off).expect("write input");
    let r = kept_by_the_cli(&input, &dir.path().join("l.vtu"));
    assert_eq!(r["boundary"]["closed"], true);
    assert_eq!(r["boundary"]["euler_characteristic"], 2);
    let volume = r["approximation"]["volume"].as_f64().expect("number");
    assert!((volume - 3.0).abs() < 1e-12, "volume {volume}");
}

#[test]
fn random_overlapping_boxes_keep_the_boundary_of_their_union() {
    use delamesh::core::random::XorShift;
    use glam::DQuat;
    for seed in 1..=6u64 {
        let mut rng = XorShift::new(seed);
        let mut union: Option<Surface> = None;
        let mut largest: f64 = 0.0;
        let mut sum = 0.0;
        for _ in 0..3 {
            let mut r = || rng.next_f64();
            let half = DVec3::new(0.3 + 0.4 * r(), 0.3 + 0.4 * r(), 0.3 + 0.4 * r());
            let axis = DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize();
            let turn = DQuat::from_axis_angle(axis, std::f64::consts::TAU * r());
            let shift = DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 0.6;
            let mut part = cuboid(-half, half);
            for p in &mut part.points {
                *p = turn * *p + shift;
            }
            let volume = 8.0 * half.x * half.y * half.z;
            largest = largest.max(volume);
            sum += volume;
            union = Some(match union {
                Some(u) => u.merge(part),
                None => part,
            });
        }
        let surface = union.expect("three boxes");
        let name = format!("boxes {seed}");
        let mut meshed = preserved(&name, &surface);
        // The winding-number volume of the input, integrated along a grid of exact lines.
        let want = meshed
            .report()
            .approximation
            .expect("a surface input")
            .input_volume;
        assert!(want > largest && want < sum, "{name}: union volume {want}");
        let got = assert_positive_not_flat(&name, &meshed.complex);
        let euler = closed_oriented_euler(&name, &meshed.complex);
        assert!(
            euler % 2 == 0 && euler <= 6,
            "{name}: Euler characteristic {euler}"
        );
        assert!(
            (got - want).abs() <= 2e-3 * want,
            "{name}: volume {got}, winding volume {want}"
        );
    }
}

/// How many boundary facets have an angle below `degrees`.
fn facets_below(c: &delamesh::core::complex::MeshComplex, degrees: f64) -> usize {
    let smallest = |f: &[u32; 3]| {
        let p = f.map(|v| c.points[v as usize]);
        (0..3)
            .map(|k| (p[(k + 1) % 3] - p[k]).angle_between(p[(k + 2) % 3] - p[k]))
            .fold(f64::INFINITY, f64::min)
            .to_degrees()
    };
    c.facets.iter().filter(|f| smallest(f) < degrees).count()
}

#[test]
fn merged_coplanar_regions_keep_the_surface_and_raise_its_smallest_angle() {
    for name in ["csg_0900", "csg_11001", "csg_11002", "csg_4739"] {
        let read = delamesh::formats::read_surface(&test_data(&format!("csg/{name}.off")), None)
            .expect("fixture reads")
            .mesh;
        let mesh = |merge: bool| {
            let settings = MeshSettings::builder()
                .preserve_surface(true)
                .merge_coplanar(merge)
                .optimize(OptimizeOptions::none())
                .build()
                .expect("valid settings");
            Mesher::new(settings)
                .mesh_surface(name, read.clone())
                .unwrap_or_else(|e| panic!("{name}: {e}"))
                .complex
        };
        let (kept, merged) = (mesh(false), mesh(true));
        let (lo, hi) = read
            .positions
            .iter()
            .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let diagonal = (hi - lo).length();
        // The same solid: its volume, its topology, every input vertex, and every boundary
        // vertex on the input surface to within the merge tolerance.
        let volume = enclosed_volume(&read.positions, &read.triangles);
        let total = assert_positive_not_flat(name, &merged);
        assert!(
            (total - volume).abs() <= 1e-7 * volume,
            "{name}: volume {total}, expected {volume}"
        );
        assert_eq!(
            closed_oriented_euler(name, &merged),
            closed_oriented_euler(name, &kept),
            "{name}: Euler characteristic"
        );
        let output: std::collections::HashSet<[u64; 3]> = merged
            .points
            .iter()
            .map(|p| p.to_array().map(f64::to_bits))
            .collect();
        assert!(
            read.positions
                .iter()
                .all(|p| output.contains(&p.to_array().map(f64::to_bits))),
            "{name}: an input vertex is missing"
        );
        assert_facets_on(
            name,
            &merged,
            &read.positions,
            &read.triangles,
            2e-8 * diagonal,
        );
        // The fans of slivers on planar faces are gone: fewer thin facets, and fewer facets.
        let (before, after) = (facets_below(&kept, 5.0), facets_below(&merged, 5.0));
        assert!(
            after < before,
            "{name}: facets below 5°: {before} -> {after}"
        );
        assert!(
            merged.facets.len() < kept.facets.len(),
            "{name}: more facets"
        );
    }
}
