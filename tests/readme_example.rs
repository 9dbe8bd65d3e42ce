//! README.md's Rust example is `examples/mesh_file.rs`, which `cargo test` compiles: the two must
//! stay the same text, so the README's example always compiles.

#[test]
fn readme_shows_the_mesh_file_example() {
    let readme = include_str!("../README.md");
    let example = include_str!("../examples/mesh_file.rs");
    let block = readme
        .split("```rust\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("README.md has a ```rust block");
    assert_eq!(
        block, example,
        "README.md's example differs from examples/mesh_file.rs"
    );
    assert!(
        example.lines().count() <= 15,
        "the example is meant to be short"
    );
    assert_eq!(
        example.lines().filter(|l| l.starts_with("use ")).count(),
        1,
        "one `use` line"
    );
}
