//! The fuzz targets (`tests/fuzz/targets.rs`, one per reader of someone else's file) run on
//! stable, bounded: every file of a target's committed corpus (`tests/fuzz/corpus/NAME/`) as it
//! is, then deterministic mutations of them — bits flipped, bytes and 32-bit words set to the
//! values headers are attacked with, ranges cut, repeated and spliced from another seed, the file
//! truncated — until the target's case count or time is spent. An error is fine; a panic fails
//! the test with the input saved to reproduce it, and a case that runs past the time limit fails
//! it as a hang. The coverage-guided run of the same targets is cargo-fuzz's (nightly; see
//! docs/ARCHITECTURE.md, "Fuzzing").

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::attacks::Rng;

#[path = "../fuzz/targets.rs"]
pub(crate) mod targets;

/// Cases per target at most, and its time at most (CI runs every target on 2 cores).
const CASES: usize = 50_000;
const TIME: Duration = Duration::from_secs(5);
/// One case longer than this is a hang.
const HANG: Duration = Duration::from_secs(20);

/// One to four stacked mutations of `seed` (with `other`, another seed, to splice from).
fn mutate(seed: &[u8], other: &[u8], rng: &mut Rng) -> Vec<u8> {
    const WORDS: [u32; 8] = [0, 1, 0x7f, 0xff, 0x7fff_ffff, 0x8000_0000, 0xffff_ffff, 0x0001_0000];
    let mut d = seed.to_vec();
    for _ in 0..1 + rng.below(4) {
        if d.is_empty() {
            d.push(0);
        }
        let at = rng.below(d.len());
        match rng.below(8) {
            0 => d[at] ^= 1 << rng.below(8),
            1 => d[at] = [0u8, 0xff, 0x7f, 0x80, 1, b'-', b'9', b'\n'][rng.below(8)],
            2 if d.len() >= at + 4 => {
                let w = WORDS[rng.below(WORDS.len())];
                let bytes = if rng.below(2) == 0 { w.to_be_bytes() } else { w.to_le_bytes() };
                d[at..at + 4].copy_from_slice(&bytes);
            }
            3 => {
                let end = (at + 1 + rng.below(64)).min(d.len());
                d.drain(at..end);
            }
            4 => {
                let end = (at + 1 + rng.below(64)).min(d.len());
                let part = d[at..end].to_vec();
                let to = rng.below(d.len());
                d.splice(to..to, part);
            }
            5 if !other.is_empty() => {
                let from = rng.below(other.len());
                let end = (from + 1 + rng.below(256)).min(other.len());
                let to = (at + other[from..end].len()).min(d.len());
                d.splice(at..to, other[from..end].iter().copied());
            }
            6 => d.truncate(at),
            _ => {
                let junk: Vec<u8> = (0..1 + rng.below(8)).map(|_| rng.next() as u8).collect();
                d.splice(at..at, junk);
            }
        }
    }
    d
}

fn corpus(name: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz/corpus").join(name);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files.into_iter().map(|p| (p.clone(), std::fs::read(&p).unwrap())).collect()
}

/// Run `target` over its corpus and its mutations on a thread of its own; the count of cases
/// run, or the failure.
fn fuzz(name: &'static str, target: fn(&[u8])) -> Result<usize, String> {
    let seeds = corpus(name);
    assert!(!seeds.is_empty(), "the corpus of `{name}` is empty");
    let (send, receive) = std::sync::mpsc::sync_channel::<Result<usize, String>>(1);
    let last = std::sync::Arc::new(std::sync::Mutex::new(Vec::<u8>::new()));
    let in_hand = std::sync::Arc::clone(&last);
    std::thread::Builder::new()
        .name(format!("fuzz-{name}"))
        .spawn(move || {
            let mut rng = Rng(0xF022_5EED ^ name.len() as u64);
            let start = Instant::now();
            let mut cases = 0;
            let mut k = 0usize;
            while cases < CASES && start.elapsed() < TIME {
                let input = if cases < seeds.len() {
                    seeds[cases].1.clone()
                } else {
                    let (a, b) = (&seeds[k % seeds.len()].1, &seeds[rng.below(seeds.len())].1);
                    k += 1;
                    mutate(a, b, &mut rng)
                };
                *in_hand.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = input.clone();
                let outcome = std::panic::catch_unwind(|| target(&input));
                if outcome.is_err() {
                    let _ = send.send(Err(format!("panicked on case {cases} ({})", save(name, &input))));
                    return;
                }
                cases += 1;
            }
            let _ = send.send(Ok(cases));
        })
        .unwrap();
    // The run's time, then the longest a single case may take.
    match receive.recv_timeout(TIME + HANG) {
        Ok(result) => result,
        Err(_) => {
            let input = last.lock().unwrap_or_else(std::sync::PoisonError::into_inner).clone();
            Err(format!("a case ran past {HANG:?} ({})", save(name, &input)))
        }
    }
}

/// Keep a failing input where the message says, to reproduce it.
fn save(name: &str, input: &[u8]) -> String {
    let dir = std::env::temp_dir().join("shoal-fuzz-failures");
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join(format!("{name}-{}.bin", input.len()));
    match std::fs::write(&path, input) {
        Ok(()) => format!("input saved to {}", path.display()),
        Err(e) => format!("input not saved: {e}"),
    }
}

#[test]
fn every_reader_survives_its_corpus_and_mutations_of_it() {
    let mut failures = Vec::new();
    let mut table = String::from("\n| target | cases | result |\n|---|---|---|\n");
    for (name, target) in targets::TARGETS {
        let start = Instant::now();
        let result = fuzz(name, target);
        let cases = result.as_ref().map_or(0, |n| *n);
        table.push_str(&format!(
            "| {name} | {cases} | {} ({:.1} s) |\n",
            result.as_ref().err().map_or("ok", String::as_str),
            start.elapsed().as_secs_f64()
        ));
        if let Err(e) = result {
            failures.push(format!("{name}: {e}"));
        }
    }
    eprintln!("{table}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
