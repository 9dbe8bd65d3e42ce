//! Feature extraction on shapes whose sharp edges, corners and faces are known.

use delamesh_core::mesh::SurfaceMesh;
use delamesh_piecewise_smooth::models::{
    box_with_hole, convex_prism, cylinder, l_bracket, two_boxes, voxels, wedge,
};
use delamesh_piecewise_smooth::{FeatureError, FeatureOptions, Features, Polyline};
use glam::{DVec2, DVec3};

fn extract(s: &SurfaceMesh) -> Features {
    Features::extract(s, &FeatureOptions::default(), &[]).expect("valid surface")
}

/// Properties every extraction must have, whatever the shape.
fn check_consistency(f: &Features) {
    // Ids from 1, in order.
    for (i, c) in f.curves.iter().enumerate() {
        assert_eq!(c.id.0 as usize, i + 1);
        assert!(c.points.len() >= if c.closed { 3 } else { 2 });
        assert_eq!(c.points.len(), c.vertices.len());
        assert!(!c.patches.is_empty());
        assert!(c.patches.iter().all(|&p| p.0 >= 1 && p.0 <= f.num_patches));
        // Open curves run between corners, and only their ends are corners.
        let is_corner = |v: &u32| f.corners.binary_search_by_key(v, |k| k.vertex).is_ok();
        if !c.closed {
            assert!(is_corner(&c.vertices[0]) && is_corner(c.vertices.last().unwrap()));
        }
        assert!(
            c.vertices[1..c.vertices.len() - 1]
                .iter()
                .all(|v| !is_corner(v))
        );
    }
    // Each corner lists exactly the curves ending there.
    for k in &f.corners {
        assert_eq!(k.point, f.positions[k.vertex as usize]);
        let ending: Vec<_> = f
            .curves
            .iter()
            .filter(|c| c.vertices[0] == k.vertex || *c.vertices.last().unwrap() == k.vertex)
            .map(|c| c.id)
            .collect();
        assert_eq!(k.curves, ending);
    }
    // Every patch id is used, and no other.
    let mut used: Vec<u32> = f.triangle_patches.iter().map(|p| p.0).collect();
    used.sort_unstable();
    used.dedup();
    assert_eq!(used, (1..=f.num_patches).collect::<Vec<_>>());
}

/// [`check_consistency`], and the numbers of curves, corners and patches.
fn check_counts(f: &Features, curves: usize, corners: usize, patches: u32) {
    check_consistency(f);
    assert_eq!(
        (f.curves.len(), f.corners.len(), f.num_patches),
        (curves, corners, patches)
    );
}

fn bits(p: DVec3) -> [u64; 3] {
    p.to_array().map(f64::to_bits)
}

#[test]
fn cube_has_twelve_curves_eight_exact_corners_six_patches() {
    let cube = SurfaceMesh::cuboid(DVec3::new(-0.3, 0.1, 2.0), DVec3::new(0.7, 1.3, 2.9));
    let f = extract(&cube);
    check_consistency(&f);
    assert_eq!(f.curves.len(), 12);
    assert_eq!(f.num_patches, 6);
    let mut corners: Vec<[u64; 3]> = f.corners.iter().map(|k| bits(k.point)).collect();
    let mut expected: Vec<[u64; 3]> = cube.positions.iter().map(|&p| bits(p)).collect();
    corners.sort_unstable();
    expected.sort_unstable();
    assert_eq!(corners, expected);
    for c in &f.curves {
        assert!(!c.closed && c.points.len() == 2 && c.patches.len() == 2);
    }
    assert!(f.corners.iter().all(|k| k.curves.len() == 3));
    // Each face of the cube is one patch: its two triangles share it, and no other does.
    for t in (0..12).step_by(2) {
        assert_eq!(f.triangle_patches[t], f.triangle_patches[t + 1]);
    }
}

#[test]
fn prisms_have_three_curves_and_two_corners_per_polygon_vertex() {
    // Facets turning by 72° (> 60°) make the side edges sharp too.
    for (sides, height) in [(3, 1.0), (4, 0.5), (5, 2.0)] {
        let f = extract(&cylinder(1.0, height, sides));
        check_counts(&f, 3 * sides, 2 * sides, sides as u32 + 2);
    }
}

#[test]
fn cylinder_has_two_closed_circles_no_corner_three_patches() {
    let f = extract(&cylinder(1.5, 2.0, 32));
    check_consistency(&f);
    assert!(f.corners.is_empty());
    assert_eq!(f.curves.len(), 2);
    assert_eq!(f.num_patches, 3);
    for c in &f.curves {
        assert!(c.closed);
        assert_eq!(c.points.len(), 32);
        let z = c.points[0].z;
        assert!(z == 0.0 || z == 2.0);
        assert!(c.points.iter().all(|p| p.z == z));
        assert_eq!(c.patches.len(), 2);
        // The perimeter of the inscribed 32-gon.
        let expected = 32.0 * 2.0 * 1.5 * (std::f64::consts::PI / 32.0).sin();
        assert!((c.length() - expected).abs() < 1e-12);
    }
    // A coarser threshold than the facets' turn finds the side edges again.
    let f = Features::extract(
        &cylinder(1.5, 2.0, 32),
        &FeatureOptions { angle_deg: 10.0 },
        &[],
    )
    .unwrap();
    assert_eq!(f.curves.len(), 3 * 32);
}

#[test]
fn l_bracket_is_a_prism_over_a_hexagon() {
    let f = extract(&l_bracket());
    check_counts(&f, 18, 12, 8);
    // The concave edge is a feature too.
    let concave = [DVec3::new(1.0, 1.0, 0.0), DVec3::new(1.0, 1.0, 1.0)];
    assert!(
        f.curves
            .iter()
            .any(|c| c.points == concave || c.points == [concave[1], concave[0]])
    );
    // Straight edges made of several surface edges are one curve.
    assert!(f.curves.iter().any(|c| c.points.len() == 3));
}

#[test]
fn box_with_hole_has_curves_around_the_hole() {
    let f = extract(&box_with_hole());
    // Outer box: 12 curves and 8 corners; the hole: 4 walls' edges and two square rims. Patches:
    // 4 outer sides, 4 hole walls, the top and bottom rings.
    check_counts(&f, 24, 16, 10);
    let on_hole = |p: &DVec3| (p.x == 1.0 || p.x == 2.0) && (p.y == 1.0 || p.y == 2.0);
    let hole_curves = f
        .curves
        .iter()
        .filter(|c| {
            c.points
                .iter()
                .all(|p| (1.0..=2.0).contains(&p.x) && (1.0..=2.0).contains(&p.y))
        })
        .count();
    assert_eq!(hole_curves, 12);
    assert_eq!(f.corners.iter().filter(|k| on_hole(&k.point)).count(), 8);
}

#[test]
fn wedges_keep_their_sharp_edge() {
    for angle in [20.0, 5.0] {
        let f = extract(&wedge(angle, 1.0, 0.5));
        check_counts(&f, 9, 6, 5);
        let edge = [DVec3::ZERO, DVec3::new(0.0, 0.0, 0.5)];
        let sharp = f
            .curves
            .iter()
            .find(|c| c.points == edge || c.points == [edge[1], edge[0]])
            .expect("the sharp edge is a curve");
        assert_eq!(sharp.patches.len(), 2);
    }
}

#[test]
fn two_boxes_share_an_interface_patch() {
    let f = extract(&two_boxes());
    assert_eq!(f.shared_faces.len(), 2);
    // Curves: the union's 12 edges, the 4 along x cut in two by the interface, plus its 4 edges.
    // Patches: 5 outer faces per box and the interface.
    check_counts(&f, 20, 12, 11);
    let interface = f.triangle_patches[f.shared_faces[0][0] as usize];
    for &[a, b] in &f.shared_faces {
        assert_eq!(f.triangle_patches[a as usize], interface);
        assert_eq!(f.triangle_patches[b as usize], interface);
    }
    let around_interface: Vec<_> = f
        .curves
        .iter()
        .filter(|c| c.patches.contains(&interface))
        .collect();
    assert_eq!(around_interface.len(), 4);
    assert!(around_interface.iter().all(|c| c.patches.len() == 3));
}

#[test]
fn patch_labels_of_the_input_are_features() {
    // A 2 × 1 × 1 block whose two halves are different input groups: the square where they meet
    // (no edge there is sharp) gives 4 curves, cutting the 4 block edges along x in two.
    let mut s = voxels(&[[0, 0, 0], [1, 0, 0]], 1.0);
    let centroid_x = |t: &[u32; 3]| t.iter().map(|&v| s.positions[v as usize].x).sum::<f64>() / 3.0;
    s.patches = s
        .triangles
        .iter()
        .map(|t| delamesh_core::mesh::PatchId(u32::from(centroid_x(t) > 1.0)))
        .collect();
    s.patch_names = vec!["left".into(), "right".into()];
    let f = extract(&s);
    check_consistency(&f);
    assert_eq!(f.num_patches, 10);
    assert_eq!(f.curves.len(), 20);
    let plain = extract(&voxels(&[[0, 0, 0], [1, 0, 0]], 1.0));
    assert_eq!(plain.num_patches, 6);
    assert_eq!(plain.curves.len(), 12);
}

#[test]
fn user_polylines_follow_surface_edges_and_split_patches() {
    // The top of a 2 × 2 × 1 block, cut along x = 1 by a polyline over two collinear edges.
    let block = voxels(&[[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], 1.0);
    let plain = extract(&block);
    assert_eq!(plain.num_patches, 6);
    let line = Polyline {
        line: 3,
        points: vec![DVec3::new(1.0, 0.0, 1.0), DVec3::new(1.0, 2.0, 1.0 + 1e-9)],
    };
    let f = Features::extract(&block, &FeatureOptions::default(), &[line]).unwrap();
    // The polyline's ends were on box edges: each edge is cut in two there.
    check_counts(&f, 12 + 2 + 1, 10, 7);
    let user = f
        .curves
        .iter()
        .find(|c| c.points.iter().all(|p| p.x == 1.0 && p.z == 1.0))
        .expect("the polyline is a curve");
    assert_eq!(user.points.len(), 3);
    assert_eq!(
        user.points[2],
        DVec3::new(1.0, 2.0, 1.0),
        "snapped to the vertex"
    );

    let off = Polyline {
        line: 7,
        points: vec![DVec3::new(1.0, 0.0, 1.0), DVec3::new(1.0, 0.5, 1.0)],
    };
    let e = Features::extract(&block, &FeatureOptions::default(), &[off]).unwrap_err();
    assert!(matches!(
        e,
        FeatureError::PolylineOffSurface {
            line: 7,
            point: 2,
            ..
        }
    ));
    assert!(e.to_string().contains("line 7"));
    // A diagonal of the top with no surface edge under it.
    let diagonal = Polyline {
        line: 1,
        points: vec![DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.0, 1.0, 1.0)],
    };
    let found = Features::extract(&block, &FeatureOptions::default(), &[diagonal]);
    let quad_diagonal_exists = block.triangles.iter().any(|t| {
        let p = t.map(|v| block.positions[v as usize]);
        p.contains(&DVec3::new(0.0, 0.0, 1.0)) && p.contains(&DVec3::new(1.0, 1.0, 1.0))
    });
    if quad_diagonal_exists {
        assert!(found.is_ok());
    } else {
        assert!(matches!(
            found,
            Err(FeatureError::PolylineOffEdges {
                line: 1,
                segment: 1
            })
        ));
    }
}

#[test]
fn invalid_input_is_an_error_not_a_panic() {
    let mut s = SurfaceMesh::cuboid(DVec3::ZERO, DVec3::ONE);
    assert!(matches!(
        Features::extract(
            &s,
            &FeatureOptions {
                angle_deg: f64::NAN
            },
            &[]
        ),
        Err(FeatureError::Angle(_))
    ));
    s.triangles[3][1] = 99;
    assert!(matches!(
        Features::extract(&s, &FeatureOptions::default(), &[]),
        Err(FeatureError::Surface(_))
    ));
}

#[test]
fn extraction_is_deterministic_and_independent_of_vertex_order() {
    let s = box_with_hole();
    assert_eq!(extract(&s), extract(&s));
    // Reverse the vertex numbering: same counts, same corner positions.
    let n = s.positions.len() as u32;
    let reversed = SurfaceMesh {
        positions: s.positions.iter().rev().copied().collect(),
        triangles: s.triangles.iter().map(|t| t.map(|v| n - 1 - v)).collect(),
        ..s.clone()
    };
    let (a, b) = (extract(&s), extract(&reversed));
    assert_eq!(a.curves.len(), b.curves.len());
    assert_eq!(a.num_patches, b.num_patches);
    let mut pa: Vec<_> = a.corners.iter().map(|k| bits(k.point)).collect();
    let mut pb: Vec<_> = b.corners.iter().map(|k| bits(k.point)).collect();
    pa.sort_unstable();
    pb.sort_unstable();
    assert_eq!(pa, pb);
}

#[test]
fn an_unwelded_soup_gives_the_same_features() {
    let cube = SurfaceMesh::cuboid(DVec3::ZERO, DVec3::ONE);
    let soup = SurfaceMesh {
        positions: cube
            .triangles
            .iter()
            .flat_map(|t| t.map(|v| cube.positions[v as usize]))
            .collect(),
        triangles: (0..12).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
        ..cube.clone()
    };
    let f = extract(&soup);
    assert_eq!((f.curves.len(), f.corners.len(), f.num_patches), (12, 8, 6));
}

#[test]
fn a_convex_prism_is_closed_and_outward() {
    let hexagon: Vec<DVec2> = (0..6)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / 6.0;
            DVec2::new(a.cos(), a.sin())
        })
        .collect();
    for s in [
        convex_prism(&hexagon, 1.0),
        wedge(5.0, 1.0, 1.0),
        l_bracket(),
        box_with_hole(),
    ] {
        let t = s.topology();
        assert!(t.closed && t.manifold && t.orientation_consistent);
        assert!(t.signed_volume > 0.0);
    }
    assert_eq!(box_with_hole().topology().genus, Some(1));
    assert!((box_with_hole().topology().signed_volume - 8.0).abs() < 1e-12);
}

#[test]
fn arc_length_parametrisation_returns_vertices_exactly() {
    let f = extract(&cylinder(1.0, 1.0, 12));
    let circle = &f.curves[0];
    let s = circle.arc_lengths();
    assert_eq!(s.len(), circle.points.len() + 1, "closed: one more entry");
    for (i, &p) in circle.points.iter().enumerate() {
        assert_eq!(circle.point_at(s[i]), p);
    }
    // Closed curves wrap around; points between vertices lie on the chords.
    let total = circle.length();
    assert_eq!(circle.point_at(total), circle.points[0]);
    assert_eq!(
        circle.point_at(-s[1] + total),
        circle.point_at(total - s[1])
    );
    let mid = circle.point_at(0.5 * s[1]);
    assert!((mid - 0.5 * (circle.points[0] + circle.points[1])).length() < 1e-15);
    // Open curves clamp at their ends.
    let f = extract(&l_bracket());
    let long = f.curves.iter().find(|c| c.points.len() == 3).unwrap();
    assert_eq!(long.point_at(-1.0), long.points[0]);
    assert_eq!(long.point_at(10.0), long.points[2]);
    assert!((long.length() - 2.0).abs() < 1e-15);
}
