//! A generated corpus of bad input, run through every reader and command under a memory cap and
//! a time limit. Every run must end with exit code 0, 1 or 2 (never a panic's 101, never a
//! signal), and a failed run must say so on one short line naming the file or the option, leave
//! no output behind and leave an existing output untouched.
//!
//! The files are generated (seeded mutations of small valid files, plus the cases that once
//! crashed), not committed.

mod cli_support;

use cli_support::model;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Virtual memory a run may map: far more than any of these small inputs needs, far less than
/// an allocation sized by a lying header.
const MEMORY_CAP: &str = "--as=3221225472";
/// Wall time a run may take (debug-ish test builds on a loaded machine).
const TIME_LIMIT: Duration = Duration::from_secs(20);
/// Longest acceptable error line.
const MAX_LINE: usize = 300;

/// Signs of a library's `Debug` output leaking into a message.
const DEBUG_DUMP: [&str; 5] = ["{ kind:", "ParseIntError", "Some(", "Error {", "Os {"];

struct Outcome {
    code: Option<i32>,
    stderr: String,
    timed_out: bool,
}

/// Runs `delamesh args` under the memory cap (when `prlimit` exists) and the time limit.
fn run(args: &[String], capped: bool) -> Outcome {
    let bin = env!("CARGO_BIN_EXE_delamesh");
    let mut cmd = if capped {
        let mut c = Command::new("prlimit");
        c.arg(MEMORY_CAP).arg(bin);
        c
    } else {
        Command::new(bin)
    };
    let mut child = cmd
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn delamesh");
    let start = Instant::now();
    let mut timed_out = false;
    loop {
        if child.try_wait().expect("wait").is_some() {
            break;
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            timed_out = true;
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let out = child.wait_with_output().expect("output");
    Outcome {
        code: out.status.code(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        timed_out,
    }
}

/// A small xorshift generator: the corpus is the same on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// The corners of the unit cube and its twelve outward triangles.
fn cube() -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let v = (0..8)
        .map(|i| [(i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64])
        .collect();
    let f = vec![
        [0, 2, 3],
        [0, 3, 1],
        [4, 5, 7],
        [4, 7, 6],
        [0, 1, 5],
        [0, 5, 4],
        [2, 6, 7],
        [2, 7, 3],
        [1, 3, 7],
        [1, 7, 5],
        [0, 4, 6],
        [0, 6, 2],
    ];
    (v, f)
}

fn off(v: &[[f64; 3]], f: &[[usize; 3]]) -> String {
    let mut s = format!("OFF\n{} {} 0\n", v.len(), f.len());
    v.iter()
        .for_each(|p| s += &format!("{:?} {:?} {:?}\n", p[0], p[1], p[2]));
    f.iter()
        .for_each(|t| s += &format!("3 {} {} {}\n", t[0], t[1], t[2]));
    s
}

fn obj(v: &[[f64; 3]], f: &[[usize; 3]]) -> String {
    let mut s = String::from("# cube\n");
    v.iter()
        .for_each(|p| s += &format!("v {:?} {:?} {:?}\n", p[0], p[1], p[2]));
    f.iter()
        .for_each(|t| s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    s
}

fn stl(v: &[[f64; 3]], f: &[[usize; 3]]) -> String {
    let mut s = String::from("solid cube\n");
    for t in f {
        s += " facet normal 0 0 0\n  outer loop\n";
        for &i in t {
            s += &format!("   vertex {:?} {:?} {:?}\n", v[i][0], v[i][1], v[i][2]);
        }
        s += "  endloop\n endfacet\n";
    }
    s + "endsolid cube\n"
}

fn ply(v: &[[f64; 3]], f: &[[usize; 3]]) -> String {
    let mut s = format!(
        "ply\nformat ascii 1.0\ncomment cube\nelement vertex {}\nproperty double x\n\
         property double y\nproperty double z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        v.len(),
        f.len()
    );
    v.iter()
        .for_each(|p| s += &format!("{:?} {:?} {:?}\n", p[0], p[1], p[2]));
    f.iter()
        .for_each(|t| s += &format!("3 {} {} {}\n", t[0], t[1], t[2]));
    s
}

fn medit(v: &[[f64; 3]], f: &[[usize; 3]]) -> String {
    let mut s = format!(
        "MeshVersionFormatted 2\nDimension 3\nVertices\n{}\n",
        v.len()
    );
    v.iter()
        .for_each(|p| s += &format!("{:?} {:?} {:?} 0\n", p[0], p[1], p[2]));
    s += &format!("Triangles\n{}\n", f.len());
    f.iter()
        .for_each(|t| s += &format!("{} {} {} 1\n", t[0] + 1, t[1] + 1, t[2] + 1));
    s + "End\n"
}

fn vtk(v: &[[f64; 3]], f: &[[usize; 3]]) -> String {
    let mut s = format!(
        "# vtk DataFile Version 4.2\ncube\nASCII\nDATASET POLYDATA\nPOINTS {} double\n",
        v.len()
    );
    v.iter()
        .for_each(|p| s += &format!("{:?} {:?} {:?}\n", p[0], p[1], p[2]));
    s += &format!("POLYGONS {} {}\n", f.len(), 4 * f.len());
    f.iter()
        .for_each(|t| s += &format!("3 {} {} {}\n", t[0], t[1], t[2]));
    s
}

/// A glTF with its buffer in a data URI.
fn gltf(v: &[[f64; 3]], f: &[[usize; 3]]) -> String {
    let mut bytes = Vec::new();
    v.iter()
        .flatten()
        .for_each(|&x| bytes.extend((x as f32).to_le_bytes()));
    let vlen = bytes.len();
    f.iter()
        .flatten()
        .for_each(|&i| bytes.extend((i as u32).to_le_bytes()));
    gltf_json(
        &bytes,
        vlen,
        v.len(),
        3 * f.len(),
        &base64(&bytes),
        "[0]",
        "[{\"mesh\":0}]",
    )
}

fn gltf_json(
    bytes: &[u8],
    vlen: usize,
    nv: usize,
    ni: usize,
    data: &str,
    scene: &str,
    nodes: &str,
) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{scene}}}],"nodes":{nodes},
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{nv},"type":"VEC3","min":[0,0,0],"max":[1,1,1]}},
{{"bufferView":1,"componentType":5125,"count":{ni},"type":"SCALAR"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{vlen}}},{{"buffer":0,"byteOffset":{vlen},"byteLength":{}}}],
"buffers":[{{"byteLength":{},"uri":"{data}"}}]}}"#,
        bytes.len() - vlen,
        bytes.len()
    )
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::from("data:application/octet-stream;base64,");
    for c in bytes.chunks(3) {
        let n = c
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &b)| n | u32::from(b) << (16 - 8 * i));
        for k in 0..4 {
            s.push(if k <= c.len() {
                A[(n >> (18 - 6 * k) & 63) as usize] as char
            } else {
                '='
            });
        }
    }
    s
}

const SQUARE_POLY: &str =
    "4 2 0 0\n1 0 0\n2 1 0\n3 1 1\n4 0 1\n4 0\n1 1 2\n2 2 3\n3 3 4\n4 4 1\n0\n";

/// A raw-appended VTU whose zlib header announces 2^40 bytes from a few compressed ones.
fn vtu_zlib_bomb() -> Vec<u8> {
    let head = "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" \
        byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n\
        <UnstructuredGrid><Piece NumberOfPoints=\"1\" NumberOfCells=\"0\"><Points>\
        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/>\
        </Points></Piece></UnstructuredGrid>\n<AppendedData encoding=\"raw\">_";
    let mut b = head.as_bytes().to_vec();
    for v in [1u64, 1 << 40, 1 << 40, 16] {
        b.extend(v.to_le_bytes());
    }
    b.extend([0x78, 0x9c].iter().chain([0u8; 14].iter()));
    b.extend(b"\n</AppendedData></VTKFile>\n");
    b
}

/// One bad file: its name and bytes.
type Case = (String, Vec<u8>);

/// Seeded mutations of a valid file: truncations, bit flips, inflated counts, non-finite and
/// subnormal numbers, a BOM, a Latin-1 comment byte, NUL bytes.
fn mutations(name: &str, valid: &[u8], rng: &mut Rng, flips: usize) -> Vec<Case> {
    let (stem, ext) = name.split_once('.').unwrap_or((name, ""));
    let mut out = Vec::new();
    let mut add = |what: &str, bytes: Vec<u8>| out.push((format!("{stem}_{what}.{ext}"), bytes));
    for k in [1, 3, 7] {
        add(&format!("trunc{k}"), valid[..valid.len() * k / 8].to_vec());
    }
    for k in 0..flips {
        let mut b = valid.to_vec();
        let i = rng.below(b.len());
        b[i] ^= 1 << rng.below(8);
        add(&format!("flip{k}"), b);
    }
    let text = String::from_utf8_lossy(valid).into_owned();
    let numbers: Vec<(usize, usize)> = {
        let mut v = Vec::new();
        let bytes = text.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            if bytes[i].is_ascii_digit() && (i == 0 || !bytes[i - 1].is_ascii_alphanumeric()) {
                let j = (i..bytes.len())
                    .find(|&j| !(bytes[j].is_ascii_digit() || b".e-".contains(&bytes[j])))
                    .unwrap_or(bytes.len());
                v.push((i, j));
                i = j;
            } else {
                i += 1;
            }
        }
        v
    };
    for (what, replacement) in [
        ("huge", "4294967295000"),
        ("neg", "-7"),
        ("nan", "nan"),
        ("inf", "1e999"),
        ("subnormal", "1e-320"),
    ] {
        for _ in 0..2 {
            if numbers.is_empty() {
                break;
            }
            let (s, e) = numbers[rng.below(numbers.len().min(12))];
            add(
                what,
                format!("{}{replacement}{}", &text[..s], &text[e..]).into_bytes(),
            );
        }
    }
    add("bom", [b"\xEF\xBB\xBF".as_slice(), valid].concat());
    add("nul", vec![0; 1024]);
    add("empty", Vec::new());
    out
}

/// Whether a failed run's message obeys the rules; `None` when it does.
fn message_problem(stderr: &str, names: &[&str]) -> Option<String> {
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error")).collect();
    let [line] = errors.as_slice() else {
        return Some(format!("{} error lines", errors.len()));
    };
    if line.chars().count() > MAX_LINE {
        return Some(format!("{} characters", line.chars().count()));
    }
    if let Some(d) = DEBUG_DUMP.iter().find(|d| line.contains(*d)) {
        return Some(format!("debug dump {d:?}"));
    }
    if !names.iter().any(|n| line.contains(n)) {
        return Some(format!("names none of {names:?}"));
    }
    None
}

#[test]
fn bad_input_never_crashes_and_fails_cleanly() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let capped = Command::new("prlimit")
        .arg("--version")
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (v, f) = cube();
    let mut sub = v.clone();
    sub[0][0] = 1e-320;
    let tiny: Vec<[f64; 3]> = v.iter().map(|p| p.map(|x| x * 1e-310)).collect();

    // Readers: every 3D format, each mutated; plus the cases that once crashed.
    let mut files: Vec<Case> = Vec::new();
    let valid: Vec<(&str, String)> = vec![
        ("cube.off", off(&v, &f)),
        ("cube.obj", obj(&v, &f)),
        ("cube.stl", stl(&v, &f)),
        ("cube.ply", ply(&v, &f)),
        ("cube.mesh", medit(&v, &f)),
        ("cube.vtk", vtk(&v, &f)),
        ("cube.gltf", gltf(&v, &f)),
    ];
    for (name, text) in &valid {
        files.extend(mutations(name, text.as_bytes(), &mut rng, 6));
        let (stem, ext) = name.split_once('.').unwrap_or_default();
        files.push((format!("{stem}_latin1.{ext}"), latin1_comment(ext, text)));
    }
    files.push(("sub.off".into(), off(&sub, &f).into_bytes()));
    files.push(("sub.obj".into(), obj(&sub, &f).into_bytes()));
    files.push(("sub.ply".into(), ply(&sub, &f).into_bytes()));
    files.push(("sub.mesh".into(), medit(&sub, &f).into_bytes()));
    files.push(("tiny.off".into(), off(&tiny, &f).into_bytes()));
    files.push(("tiny.vtk".into(), vtk(&tiny, &f).into_bytes()));
    files.push((
        "bom_ascii.stl".into(),
        [b"\xEF\xBB\xBF".as_slice(), stl(&v, &f).as_bytes()].concat(),
    ));
    files.push((
        "cafe.obj".into(),
        [b"# caf\xE9\n".as_slice(), obj(&v, &f).as_bytes()].concat(),
    ));
    files.push((
        "polyline.obj".into(),
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nl 1 2 3 4 1\n".to_vec(),
    ));
    files.push((
        "two.obj".into(),
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n".to_vec(),
    ));
    files.push(("zlib_bomb.vtu".into(), vtu_zlib_bomb()));
    let dag: Vec<String> = (0..60)
        .map(|i| match i {
            59 => "{\"mesh\":0}".to_string(),
            58 => "{\"children\":[59]}".to_string(),
            _ => format!("{{\"children\":[{},{}]}}", i + 1, i + 2),
        })
        .collect();
    let mut bytes = Vec::new();
    v.iter()
        .flatten()
        .for_each(|&x| bytes.extend((x as f32).to_le_bytes()));
    let vlen = bytes.len();
    f.iter()
        .flatten()
        .for_each(|&i| bytes.extend((i as u32).to_le_bytes()));
    let nodes = format!("[{}]", dag.join(","));
    files.push((
        "dag.gltf".into(),
        gltf_json(&bytes, vlen, 8, 36, &base64(&bytes), "[0]", &nodes).into_bytes(),
    ));
    for (k, uri) in [
        "../../../../etc/passwd",
        "%2e%2e/%2e%2e/etc/passwd",
        "../../../../dev/zero",
    ]
    .iter()
    .enumerate()
    {
        let json = gltf_json(&bytes, vlen, 8, 36, uri, "[0]", "[{\"mesh\":0}]");
        files.push((format!("escape{k}.gltf"), json.into_bytes()));
    }

    let mut runs: Vec<(Vec<String>, Vec<PathBuf>, Vec<String>)> = Vec::new();
    let s = |p: &Path| p.to_string_lossy().into_owned();
    for (name, data) in &files {
        let path = d.join(name);
        std::fs::write(&path, data).expect("write case");
        let p = s(&path);
        runs.push((vec!["info".into(), p.clone()], vec![], vec![name.clone()]));
        runs.push((
            vec!["info".into(), "--json".into(), p.clone()],
            vec![],
            vec![name.clone()],
        ));
        let out = d.join(format!("{name}.out.off"));
        runs.push((
            vec!["convert".into(), p.clone(), s(&out)],
            vec![out],
            vec![name.clone()],
        ));
    }
    // Meshing: the valid cube with every absurd option, then each subnormal or tiny cube.
    let cube_off = d.join("cube.off");
    std::fs::write(&cube_off, off(&v, &f)).expect("write cube");
    let coarse = [
        "--facet-size",
        "0.5",
        "--cell-size",
        "0.6",
        "--facet-distance",
        "0.05",
    ];
    for (flag, value) in [
        ("--facet-size", "1e-300"),
        ("--facet-angle", "90"),
        ("--cell-radius-edge-ratio", "0.5"),
        ("--cell-size", "nan"),
        ("--facet-distance", "=-1"),
        ("--max-vertices", "5"),
    ] {
        let out = d.join("absurd.vtu");
        let mut args: Vec<String> = vec!["mesh".into(), s(&cube_off), "-o".into(), s(&out)];
        args.extend(coarse.iter().map(|a| a.to_string()));
        match value.strip_prefix('=') {
            Some(v) => args.push(format!("{flag}={v}")),
            None => args.extend([flag.to_string(), value.to_string()]),
        }
        let name = flag.trim_start_matches('-').to_string();
        runs.push((args, vec![out], vec![name]));
    }
    for name in [
        "sub.off",
        "sub.obj",
        "tiny.off",
        "cube_huge.off",
        "cube_subnormal.obj",
    ] {
        let out = d.join(format!("{name}.vtu"));
        let mut args: Vec<String> = vec!["mesh".into(), s(&d.join(name)), "-o".into(), s(&out)];
        args.extend(coarse.iter().map(|a| a.to_string()));
        runs.push((args, vec![out], vec![name.to_string()]));
    }
    let report = vec![
        "mesh".into(),
        s(&cube_off),
        "-o".into(),
        s(&d.join("r.vtu")),
        "--report".into(),
        s(&d.join("missing/r.json")),
    ];
    runs.push((report, vec![d.join("r.vtu")], vec!["missing".into()]));
    // Feature polylines: a count whose triple wraps, and mutations.
    let polylines = "2 0 0 0 1 0 0\n";
    let mut line_cases = mutations("f.polylines.txt", polylines.as_bytes(), &mut rng, 3);
    line_cases.push((
        "wrap.polylines.txt".into(),
        b"6148914691236517206 0 0\n".to_vec(),
    ));
    for (name, data) in &line_cases {
        let path = d.join(name);
        std::fs::write(&path, data).expect("write polylines");
        let out = d.join("feat.vtu");
        let mut args: Vec<String> = vec![
            "mesh".into(),
            s(&cube_off),
            "-o".into(),
            s(&out),
            "--features".into(),
            s(&path),
        ];
        args.extend(coarse.iter().map(|a| a.to_string()));
        runs.push((args, vec![out], vec![name.clone()]));
    }
    // Planar graphs and point sets.
    let mut planar = mutations("sq.poly", SQUARE_POLY.as_bytes(), &mut rng, 6);
    planar.push(("big.poly".into(), b"999999999 2 0 0\n1 0 0\n".to_vec()));
    let square = d.join("square.poly");
    std::fs::write(&square, SQUARE_POLY).expect("write square");
    for (name, data) in &planar {
        let path = d.join(name);
        std::fs::write(&path, data).expect("write poly");
        for cmd in ["mesh2d", "conform2d"] {
            let out = d.join(format!("{name}.{cmd}.vtu"));
            runs.push((
                vec![cmd.into(), s(&path), "-o".into(), s(&out)],
                vec![out],
                vec![name.clone()],
            ));
        }
    }
    for (flag, value) in [
        ("--max-vertices", "0"),
        ("--max-area", "1e-300"),
        ("--hole", "1e308,1e308"),
        ("--min-angle", "60"),
    ] {
        let out = d.join("sq.vtu");
        let args = vec![
            "mesh2d".into(),
            s(&square),
            "-o".into(),
            s(&out),
            flag.into(),
            value.into(),
        ];
        runs.push((
            args,
            vec![out],
            vec![flag.trim_start_matches('-').to_string()],
        ));
    }
    let xyz = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
    for (name, data) in mutations("p.xyz", xyz.as_bytes(), &mut rng, 4) {
        let path = d.join(&name);
        std::fs::write(&path, &data).expect("write xyz");
        let out = d.join(format!("{name}.vtu"));
        runs.push((
            vec!["delaunay".into(), s(&path), "-o".into(), s(&out)],
            vec![out],
            vec![name],
        ));
    }

    // An existing output must survive a failed run that targets it.
    let precious = d.join("precious.vtu");
    std::fs::write(&precious, b"precious").expect("write precious");
    runs.push((
        vec!["convert".into(), s(&d.join("cube_nul.off")), s(&precious)],
        vec![],
        vec!["cube_nul.off".into()],
    ));

    let (mut panics, mut signals, mut hangs, mut failures) = (0, 0, 0, Vec::new());
    let mut codes = std::collections::BTreeMap::new();
    for (args, outputs, names) in &runs {
        for o in outputs {
            let _ = std::fs::remove_file(o);
        }
        let r = run(args, capped);
        *codes.entry(r.code).or_insert(0) += 1;
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let problem = if r.timed_out {
            hangs += 1;
            Some("ran past the time limit".to_string())
        } else {
            match r.code {
                None => {
                    signals += 1;
                    Some("killed by a signal".into())
                }
                Some(0) => None,
                Some(1 | 2) => message_problem(&r.stderr, &names).or_else(|| {
                    outputs
                        .iter()
                        .find(|o| o.exists())
                        .map(|o| format!("left {} behind", o.display()))
                }),
                Some(c) => {
                    panics += usize::from(c == 101);
                    Some(format!("exit code {c}"))
                }
            }
        };
        if let Some(p) = problem {
            let last = r.stderr.lines().last().unwrap_or_default().to_string();
            failures.push(format!("{}: {p}\n    {}", args.join(" "), last));
        }
    }
    if std::fs::read(&precious).ok().as_deref() != Some(b"precious".as_slice()) {
        failures.push("an existing output was changed by a failed run".into());
    }
    eprintln!(
        "bad-input corpus: {} runs (memory cap: {capped}), exit codes {codes:?}, {panics} panics, \
         {signals} signals, {hangs} hangs",
        runs.len()
    );
    assert!(
        failures.is_empty(),
        "{} bad runs:\n{}",
        failures.len(),
        failures.join("\n")
    );
    // The generator must keep producing failures to check, and valid files must still read.
    assert!(codes.get(&Some(1)).copied().unwrap_or(0) > runs.len() / 3);
    let cube = model("torus.off");
    assert!(run(&["info".into(), s(&cube)], capped).code == Some(0));
}

/// The valid file with a Latin-1 `é` in a comment (or a name where the format has no comments).
fn latin1_comment(ext: &str, text: &str) -> Vec<u8> {
    let (at, line): (usize, &[u8]) = match ext {
        "off" | "obj" => (text.find('\n').map_or(0, |i| i + 1), b"# caf\xE9\n"),
        "vtk" => {
            let marked = text.replacen("\ncube\n", "\ncaf\u{1}\n", 1).into_bytes();
            return marked
                .into_iter()
                .map(|b| if b == 1 { 0xE9 } else { b })
                .collect();
        }
        "ply" => (text.find("comment").unwrap_or(0), b"comment caf\xE9\n"),
        "mesh" => (0, b"# caf\xE9\n"),
        "stl" => (0, b"solid caf\xE9\n"),
        _ => (0, b""),
    };
    let mut out = text.as_bytes()[..at].to_vec();
    out.extend(line);
    let rest = if ext == "stl" {
        &text[text.find('\n').map_or(0, |i| i + 1)..]
    } else {
        &text[at..]
    };
    out.extend(rest.as_bytes());
    out
}
