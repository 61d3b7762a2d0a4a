//! A bounded run of every fuzz target (`fuzz/targets.rs`) in each CI build: the
//! inputs kept in the repository (`fuzz/corpus/<target>/`, seeds; and
//! `fuzz/regressions/<target>/`, inputs that once failed), then mutations of them
//! (bit flips, interesting bytes and numbers, cut, repeated and spliced ranges) from a
//! fixed seed. Each must end in an answer; no single allocation may exceed 1 GiB.
//! The coverage-guided runs with far more inputs are `cargo fuzz` (nightly), see
//! `fuzz/README.md`.
//!
//! `TALUS_FUZZ_SMOKE=N` sets the mutations per target (default 1500).

#[path = "../fuzz/targets.rs"]
mod targets;

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// The system allocator, keeping the largest single allocation asked for.
struct Largest;

static LARGEST: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is passed to the system allocator unchanged.
unsafe impl GlobalAlloc for Largest {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Largest = Largest;

const LIMIT: usize = 1 << 30;

/// The kept inputs of `target`: its corpus and its regressions.
fn kept(target: &str) -> Vec<(String, Vec<u8>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut inputs = Vec::new();
    for dir in ["corpus", "regressions"] {
        let Ok(entries) = std::fs::read_dir(root.join(dir).join(target)) else {
            continue;
        };
        let mut paths: Vec<_> = entries.map(|e| e.unwrap().path()).collect();
        paths.sort();
        for p in paths {
            inputs.push((p.display().to_string(), std::fs::read(&p).unwrap()));
        }
    }
    inputs
}

/// Numbers and words that break parsers, as text.
const WORDS: [&[u8]; 14] = [
    b"nan",
    b"inf",
    b"-inf",
    b"1e308",
    b"-1e308",
    b"1e-300",
    b"0",
    b"-0",
    b"4294967297",
    b"18446744073709551615",
    b"-1",
    b"1e9",
    b"\"",
    b"[",
];

/// One mutation of `input` (another kept input may be spliced in).
fn mutate(rng: &mut StdRng, input: &[u8], other: &[u8]) -> Vec<u8> {
    let mut v = input.to_vec();
    for _ in 0..rng.random_range(1..=4) {
        let len = v.len();
        let at = if len == 0 {
            0
        } else {
            rng.random_range(0..len)
        };
        match rng.random_range(0..8) {
            0 if len > 0 => v[at] ^= 1 << rng.random_range(0..8),
            1 if len > 0 => v[at] = [0, 0xff, 0x7f, 0x80, b'9', b'\n'][rng.random_range(0..6)],
            2 => {
                let w = WORDS[rng.random_range(0..WORDS.len())];
                v.splice(at..at, w.iter().copied());
            }
            3 if len > 0 => {
                // Replace a number-looking run of characters by a word.
                let end = (at..len)
                    .find(|&k| !(v[k].is_ascii_digit() || b".-+e".contains(&v[k])))
                    .unwrap_or(len);
                let w = WORDS[rng.random_range(0..WORDS.len())];
                v.splice(at..end, w.iter().copied());
            }
            4 if len > 0 => {
                let end = (at + rng.random_range(1..=64)).min(len);
                v.drain(at..end);
            }
            5 if len > 0 => {
                let end = (at + rng.random_range(1..=64)).min(len);
                let copy = v[at..end].to_vec();
                v.splice(at..at, copy);
            }
            6 if !other.is_empty() => {
                let from = rng.random_range(0..other.len());
                let end = (from + rng.random_range(1..=256)).min(other.len());
                v.splice(at..at, other[from..end].iter().copied());
            }
            _ if len >= 8 => {
                // Eight raw bytes (a binary count or float).
                let at = rng.random_range(0..len - 7);
                let x: u64 =
                    [0, u32::MAX as u64, u64::MAX, 1 << 40, rng.random()][rng.random_range(0..5)];
                v[at..at + 8].copy_from_slice(&x.to_le_bytes());
            }
            _ => v.push(rng.random()),
        }
    }
    v
}

fn smoke(target: &str, run: fn(&[u8]), extra_seeds: Vec<Vec<u8>>) {
    let mut seeds: Vec<Vec<u8>> = kept(target).into_iter().map(|(_, b)| b).collect();
    seeds.extend(extra_seeds);
    seeds.extend(targets::seeds(target));
    assert!(!seeds.is_empty(), "{target}: no corpus");
    let started = Instant::now();
    LARGEST.store(0, Ordering::Relaxed);
    for (name, input) in kept(target) {
        let result = std::panic::catch_unwind(|| run(&input));
        assert!(result.is_ok(), "{target}: kept input {name} failed");
    }
    let count: usize = std::env::var("TALUS_FUZZ_SMOKE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1500);
    let mut rng = StdRng::seed_from_u64(0x7a1_5eed_u64.wrapping_mul(target.len() as u64 + 1));
    for k in 0..count {
        let input = &seeds[k % seeds.len()];
        let other = &seeds[rng.random_range(0..seeds.len())];
        let mutated = mutate(&mut rng, input, other);
        let failed = std::panic::catch_unwind(|| run(&mutated)).is_err();
        let largest = LARGEST.load(Ordering::Relaxed);
        if failed || largest >= LIMIT {
            let file = std::env::temp_dir().join(format!("talus-fuzz-{target}-{k}"));
            std::fs::write(&file, &mutated).unwrap();
            panic!(
                "{target}: mutated input {k} {}; kept in {} (add it to fuzz/regressions/{target}/ once fixed)",
                if failed {
                    "failed".to_string()
                } else {
                    format!("allocated {largest} bytes at once")
                },
                file.display()
            );
        }
    }
    let largest = LARGEST.load(Ordering::Relaxed);
    println!(
        "{target}: {} kept and {count} mutated inputs in {:.2} s; largest allocation {largest} bytes",
        kept(target).len(),
        started.elapsed().as_secs_f64()
    );
    assert!(
        largest < LIMIT,
        "{target}: an allocation of {largest} bytes"
    );
}

/// Writes the seeds talus makes (`targets::seeds`) into `fuzz/corpus/` for
/// `cargo fuzz`: `cargo test --features zenoh --test fuzz_smoke -- --ignored`.
#[test]
#[ignore]
fn write_seeds() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    for target in ["state_bytes", "component_calls", "zenoh_messages"] {
        for (k, seed) in targets::seeds(target).iter().enumerate() {
            std::fs::write(root.join(target).join(format!("seed-{k}")), seed).unwrap();
        }
    }
}

/// Every target in turn (one at a time, so that each answers for its own
/// allocations).
#[test]
fn every_target_answers_every_input() {
    smoke(
        "scene_toml",
        targets::scene_toml,
        vec![targets::TINY_SCENE.into()],
    );
    smoke("stl", targets::stl, vec![]);
    smoke("obj", targets::obj, vec![]);
    smoke("particle_csv", targets::particle_csv, vec![]);
    smoke("poses_csv", targets::poses_csv, vec![]);
    smoke("state_bytes", targets::state_bytes, vec![]);
    smoke("component_calls", targets::component_calls, vec![]);
    #[cfg(feature = "zenoh")]
    smoke("zenoh_messages", targets::zenoh_messages, vec![]);
}
