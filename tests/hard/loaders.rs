//! The loaders against hostile text: mutated presets and arbitrary strings never panic, and the
//! crashes the fuzzer found stay fixed (regressions at the end). The coverage-guided fuzzer
//! itself lives in tests/fuzz (docs/ARCHITECTURE.md, "Fuzzing").

use proptest::prelude::*;

/// Every loader on `text`: errors are fine, panics are not.
fn load_all(text: &str) {
    super::fuzz::targets::preset_loaders(text.as_bytes());
    super::fuzz::targets::spectrum_csv(text.as_bytes());
}

/// The built-in files the mutations start from.
fn seeds() -> Vec<&'static str> {
    let mut v = Vec::new();
    for folder in ["instruments", "scenes", "studies", "sweeps", "siop"] {
        for name in shoal::assets::preset_names(folder) {
            if let Some(a) = shoal::assets::preset(&format!("{folder}/{name}.ron")) {
                v.push(a.text);
            }
        }
    }
    v.push("wavelength_nm,a,b\n400,1,2\n500,nan,3\n600,1e308,-4\n");
    v
}

/// An edit: (position as a fraction of the length, bytes to delete, text to insert).
type Edit = (f64, usize, String);

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut s: Vec<char> = text.chars().collect();
    for (at, delete, insert) in edits {
        let i = ((*at * s.len() as f64) as usize).min(s.len());
        let j = (i + delete).min(s.len());
        s.splice(i..j, insert.chars());
    }
    s.into_iter().collect()
}

fn insertion() -> impl Strategy<Value = String> {
    prop_oneof![
        Just(String::new()),
        Just("-".to_string()),
        Just("1e308".to_string()),
        Just("NaN".to_string()),
        Just("-inf".to_string()),
        Just("0".to_string()),
        Just("99999999999999999999".to_string()),
        Just(")".to_string()),
        Just("(".to_string()),
        Just(",".to_string()),
        Just("\"".to_string()),
        Just("Some(".to_string()),
        Just("[]".to_string()),
        any::<char>().prop_map(|c| c.to_string()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(super::proptest_cases(256)))]

    #[test]
    fn mutated_presets_never_panic(
        which in any::<prop::sample::Index>(),
        edits in prop::collection::vec((0.0f64..=1.0, 0usize..8, insertion()), 1..6),
    ) {
        let seeds = seeds();
        let text = apply(seeds[which.index(seeds.len())], &edits);
        load_all(&text);
    }

    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        load_all(&text);
    }
}

#[test]
fn the_seeds_load() {
    // The mutation corpus is real: the instrument, scene and study presets parse unmutated.
    let seeds = seeds();
    assert!(seeds.len() >= 15, "{}", seeds.len());
    let parsed = seeds.iter().filter(|t| shoal::instrument::InstrumentSpec::from_ron(t, "t").is_ok()).count();
    assert!(parsed >= 5, "{parsed}");
}
