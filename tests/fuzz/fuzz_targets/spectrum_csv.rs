//! cargo-fuzz target `spectrum_csv`: see `../targets.rs`, which `cargo test` also runs, bounded, over
//! the committed corpus (`tests/hard/fuzz.rs`).
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::spectrum_csv(data));
