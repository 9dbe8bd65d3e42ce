//! Plugins loaded at run time answer through the `Oracle` trait exactly as the same code linked
//! statically, and every fault the ABI can express becomes an error naming the plugin.

mod plugins_support;
use plugins_support as common;

use delamesh::core::kernel::Point3;
use delamesh::core::oracle::{OUTSIDE, Oracle, SurfaceHit};
use delamesh::core::plugin::{DynOracle, PluginLibrary, PluginOracle, PluginProblem};
use delamesh::core::random::XorShift;
use delamesh_implicit::ImplicitOracle;

/// Deterministic pseudo-random points in a box (xorshift; no seeded RNG dependency needed).
fn points_in(min: Point3, max: Point3, count: usize) -> Vec<Point3> {
    let mut rng = XorShift::new(0x9E37_79B9_7F4A_7C15);
    let mut unit = move || rng.next_f64();
    (0..count)
        .map(|_| min + Point3::new(unit(), unit(), unit()) * (max - min))
        .collect()
}

fn load(path: &std::path::Path, config: &str) -> DynOracle {
    let library = PluginLibrary::open(path).unwrap_or_else(|e| panic!("{e}"));
    library.create(config).unwrap_or_else(|e| panic!("{e}"))
}

/// Bitwise comparison: the dynamic path must not even round differently.
fn same_hits(a: &[SurfaceHit], b: &[SurfaceHit]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            x.point.to_array().map(f64::to_bits) == y.point.to_array().map(f64::to_bits)
                && x.t.to_bits() == y.t.to_bits()
                && x.patch == y.patch
        })
}

#[test]
fn implicit_plugin_answers_bit_for_bit_like_the_static_oracle() {
    let path = common::implicit_plugin();
    for config in [
        "shape=sphere radius=0.7 center=0.1,0.2,0.3",
        "shape=torus major=1 minor=0.3",
        "shape=tanglecube samples=48",
    ] {
        let direct = ImplicitOracle::from_config(config).expect("valid config");
        let loaded = load(&path, config);
        let bbox = direct.bounding_box();
        assert_eq!(loaded.bounding_box(), bbox, "{config}");
        let grown = (bbox.max - bbox.min) * 0.25;
        let points = points_in(bbox.min - grown, bbox.max + grown, 4000);
        let mut batch = vec![OUTSIDE; points.len()];
        loaded
            .try_subdomains(&points, &mut batch)
            .expect("batch location");
        let mut inside = 0;
        for (&p, &label) in points.iter().zip(&batch) {
            assert_eq!(loaded.subdomain(p), direct.subdomain(p), "{config} at {p}");
            assert_eq!(label, direct.subdomain(p), "{config}: batch at {p}");
            inside += usize::from(label != OUTSIDE);
        }
        assert!(
            inside > 0 && inside < points.len(),
            "{config}: the sample must straddle the boundary"
        );
        let (mut expected, mut got, mut crossings) = (Vec::new(), Vec::new(), 0);
        for pair in points.chunks_exact(2) {
            expected.clear();
            got.clear();
            direct.segment_hits(pair[0], pair[1], &mut expected);
            loaded.segment_hits(pair[0], pair[1], &mut got);
            assert!(same_hits(&expected, &got), "{config}: segment {pair:?}");
            expected.clear();
            got.clear();
            direct.ray_hits(pair[0], pair[1] - pair[0], &mut expected);
            loaded.ray_hits(pair[0], pair[1] - pair[0], &mut got);
            assert!(same_hits(&expected, &got), "{config}: ray {pair:?}");
            crossings += got.len();
        }
        assert!(
            crossings > 0,
            "{config}: some queries must cross the surface"
        );
        let (a, b) = (direct.initial_points(), loaded.initial_points());
        assert_eq!(a, b, "{config}: initial points");
        assert!(loaded.fault().is_none(), "{config}: {:?}", loaded.fault());
        loaded
            .self_check()
            .expect("a correct plugin passes its self-check");
    }
}

#[test]
fn plugin_queries_are_safe_from_several_threads() {
    let loaded = load(&common::implicit_plugin(), "shape=torus");
    let direct = ImplicitOracle::from_config("shape=torus").expect("valid config");
    let points = points_in(Point3::splat(-1.5), Point3::splat(1.5), 2000);
    std::thread::scope(|scope| {
        for chunk in points.chunks(500) {
            scope.spawn(|| {
                let (mut a, mut b) = (Vec::new(), Vec::new());
                for pair in chunk.windows(2) {
                    a.clear();
                    b.clear();
                    direct.segment_hits(pair[0], pair[1], &mut a);
                    loaded.segment_hits(pair[0], pair[1], &mut b);
                    assert!(same_hits(&a, &b));
                    assert_eq!(direct.subdomain(pair[0]), loaded.subdomain(pair[0]));
                }
            });
        }
    });
}

#[test]
fn c_plugin_is_a_ball_with_its_configured_radius_and_center() {
    let path = common::c_plugin("examples/plugins/c-sphere/sphere.c", &[]);
    let library = PluginLibrary::open(&path).expect("the C example loads");
    assert_eq!(
        (
            library.info().name.as_str(),
            library.info().kind.as_str(),
            library.info().abi_version
        ),
        ("c-sphere", "implicit", 1)
    );
    let center = Point3::new(1.0, -2.0, 0.5);
    let oracle = library
        .create("radius=2 center=1,-2,0.5")
        .expect("valid config");
    oracle
        .self_check()
        .expect("the C example honours the contract");
    let bbox = oracle.bounding_box();
    assert_eq!((bbox.min, bbox.max), (center - 2.0, center + 2.0));
    let points = points_in(bbox.min - 1.0, bbox.max + 1.0, 2000);
    let mut hits = Vec::new();
    for pair in points.chunks_exact(2) {
        assert_eq!(
            oracle.subdomain(pair[0]) != OUTSIDE,
            pair[0].distance(center) < 2.0
        );
        hits.clear();
        oracle.segment_hits(pair[0], pair[1], &mut hits);
        let ends_inside = [pair[0], pair[1]].map(|p| p.distance(center) < 2.0);
        if ends_inside[0] != ends_inside[1] {
            assert_eq!(hits.len(), 1, "one end inside: exactly one crossing");
        }
        for hit in &hits {
            assert!((hit.point.distance(center) - 2.0).abs() < 1e-9 && hit.patch.0 == 1);
            assert!((pair[0].lerp(pair[1], hit.t) - hit.point).length() < 1e-9);
        }
    }
    assert!(
        oracle
            .initial_points()
            .iter()
            .all(|p| (p.point.distance(center) - 2.0).abs() < 1e-12)
    );
    assert!(oracle.feature_curves().is_empty() && oracle.corners().is_empty());
    assert!(oracle.fault().is_none());
}

/// The problem a broken plugin causes, checking the error names the plugin.
fn problem(
    result: Result<impl Sized, delamesh::core::plugin::PluginError>,
    name: &str,
) -> PluginProblem {
    let Err(error) = result else {
        panic!("the fault of {name} went unnoticed")
    };
    assert!(
        error.to_string().contains(name),
        "error does not name the plugin: {error}"
    );
    error.problem
}

#[test]
fn broken_tables_are_refused_at_load_time() {
    let missing = common::c_plugin("tests/plugins/faulty_table.c", &["FAULT_NO_ENTRY"]);
    let name = missing
        .file_name()
        .and_then(|n| n.to_str())
        .expect("file name")
        .to_string();
    assert!(matches!(
        problem(PluginLibrary::open(&missing), &name),
        PluginProblem::MissingEntryPoint
    ));
    let version = common::c_plugin("tests/plugins/faulty_table.c", &["FAULT_ABI_VERSION"]);
    let name = version
        .file_name()
        .and_then(|n| n.to_str())
        .expect("file name")
        .to_string();
    assert!(matches!(
        problem(PluginLibrary::open(&version), &name),
        PluginProblem::AbiVersion { found: 99 }
    ));
    let null = common::c_plugin("tests/plugins/faulty_table.c", &["FAULT_NULL_FUNCTION"]);
    let error = problem(PluginLibrary::open(&null), "faulty-table");
    assert!(
        matches!(&error, PluginProblem::BadTable(m) if m.contains("create")),
        "{error}"
    );
    let absent = common::repo_root().join("no-such-plugin.so");
    assert!(matches!(
        problem(PluginLibrary::open(&absent), "no-such-plugin.so"),
        PluginProblem::Load(_)
    ));
}

#[test]
fn create_failures_carry_the_plugin_message() {
    let c_sphere =
        PluginLibrary::open(&common::c_plugin("examples/plugins/c-sphere/sphere.c", &[]))
            .expect("loads");
    let error = problem(c_sphere.create("radius=-1"), "c-sphere");
    assert!(
        matches!(&error, PluginProblem::Create(m) if m.contains("radius")),
        "{error}"
    );
    let faulty = PluginLibrary::open(&common::faulty_plugin()).expect("loads");
    let error = problem(faulty.create("fault=fail-create"), "faulty");
    assert!(
        matches!(&error, PluginProblem::Create(m) if m.contains("deliberate create failure")),
        "{error}"
    );
    let error = problem(faulty.create("fault=panic-create"), "faulty");
    assert!(
        matches!(&error, PluginProblem::Create(m) if m.contains("panicked") && m.contains("deliberate")),
        "{error}"
    );
}

#[test]
fn query_faults_are_contained_and_reported() {
    let faulty = PluginLibrary::open(&common::faulty_plugin()).expect("loads");
    let healthy = faulty.create("fault=none").expect("creates");
    healthy
        .self_check()
        .expect("the faulty plugin without a fault is correct");
    for (fault, expected) in [
        ("panic-subdomain", "deliberate panic in subdomain"),
        ("panic-hits", "deliberate panic in segment_hits"),
        ("nan-hits", "non-finite"),
        ("outside-hits", "outside its bounding box"),
        ("outside-initial-points", "outside its bounding box"),
    ] {
        let oracle = faulty.create(&format!("fault={fault}")).expect("creates");
        let error = problem(oracle.self_check(), "faulty");
        assert!(error.to_string().contains(expected), "{fault}: {error}");
        // Through the infallible trait: a neutral answer, and the fault kept for the caller.
        let mut hits = Vec::new();
        let label = oracle.subdomain(Point3::ZERO);
        oracle.segment_hits(Point3::splat(-2.0), Point3::splat(2.0), &mut hits);
        let points = oracle.initial_points();
        let fault_seen = oracle.check().expect_err(fault);
        assert!(
            fault_seen.to_string().contains(expected),
            "{fault}: {fault_seen}"
        );
        match fault {
            "panic-subdomain" => assert_eq!(label, OUTSIDE),
            "outside-initial-points" => assert!(points.is_empty()),
            _ => assert!(
                hits.is_empty(),
                "{fault}: faulty hits must not reach the mesher"
            ),
        }
    }
}
