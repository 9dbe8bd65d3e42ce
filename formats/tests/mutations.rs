//! A small deterministic fuzzer on stable Rust: random byte flips, insertions, deletions and splices of
//! the sample models, fed to every reader. The cargo-fuzz targets in fuzz/ go further; this keeps
//! the no-panic property under `cargo test`.

use delamesh_formats::image::{ImageFormat, read_image_bytes};
use delamesh_formats::poly::parse_poly;
use delamesh_formats::{Format, parse_xyz, read_bytes};
use std::path::{Path, PathBuf};

/// xorshift64*: a fixed seed keeps runs reproducible.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Bytes that matter to parsers: digits, signs, separators, keywords' letters, extreme values.
const INTERESTING: &[&[u8]] = &[
    b"0",
    b"-1",
    b"9999999999",
    b"nan",
    b"inf",
    b" ",
    b"\n",
    b"\xff\xff\xff\x7f",
    b"\0\0\0\0",
    b"e308",
    b"\"",
    b"<",
    b">",
    b"}",
];

fn mutate(rng: &mut Rng, seed: &[u8]) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(b.len() + 1);
        match rng.below(5) {
            0 if !b.is_empty() => {
                let i = rng.below(b.len());
                b[i] ^= 1 << rng.below(8);
            }
            1 => {
                let piece = INTERESTING[rng.below(INTERESTING.len())];
                b.splice(at..at, piece.iter().copied());
            }
            2 if at < b.len() => {
                let end = (at + 1 + rng.below(16)).min(b.len());
                b.drain(at..end);
            }
            3 if !b.is_empty() => {
                let i = rng.below(b.len());
                b[i] = rng.next() as u8;
            }
            _ => b.truncate(at),
        }
    }
    b
}

/// A reader fed with bytes; its outcome does not matter, only that it returns.
type Reader = Box<dyn Fn(&[u8])>;

/// The reader a seed folder of `fuzz/seeds` is for (`None`: a reader outside this crate).
fn reader(folder: &str) -> Option<Reader> {
    let name = folder.trim_start_matches("read_");
    let image = |format: ImageFormat| -> Option<Reader> {
        Some(Box::new(move |b: &[u8]| {
            if let Ok(image) = read_image_bytes(b, format, None) {
                let _ = image.validate();
            }
        }))
    };
    match name {
        "inr" => image(ImageFormat::Inr),
        "nifti" => image(ImageFormat::Nifti),
        "vti" => image(ImageFormat::Vti),
        "nrrd" => image(ImageFormat::Nrrd),
        "xyz" => Some(Box::new(|b: &[u8]| {
            let _ = parse_xyz(b);
        })),
        "poly" => Some(Box::new(|b: &[u8]| {
            let node = || Ok((String::new(), PathBuf::from("mutated.node")));
            if let Ok(pslg) = parse_poly(&String::from_utf8_lossy(b), Path::new("m.poly"), node) {
                let _ = pslg.validate();
            }
        })),
        _ => {
            let format: Format = name.parse().ok()?;
            Some(Box::new(move |b: &[u8]| {
                let _ = read_bytes(b, format, None);
            }))
        }
    }
}

#[test]
fn mutated_sample_files_never_panic() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/seeds");
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut seeds = 0;
    let mut folders: Vec<PathBuf> = std::fs::read_dir(&data)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    folders.sort();
    for target in folders {
        let Some(read) = reader(&target.file_name().unwrap().to_string_lossy()) else {
            continue;
        };
        for file in std::fs::read_dir(&target).unwrap() {
            let seed = std::fs::read(file.unwrap().path()).unwrap();
            seeds += 1;
            for _ in 0..300 {
                // Either outcome is fine; a panic fails the test.
                read(&mutate(&mut rng, &seed));
            }
        }
    }
    assert!(seeds >= 20, "the fuzz seeds were not found");
}
