//! A season split into shards and merged gives the whole run's result and files, byte for
//! byte; shard files that do not belong together, or were altered, are refused by name.

use shoal::control::RunControl;
use shoal::season::SeasonSpec;
use shoal::season::run::{designs, plan_season, run_season};
use shoal::season::shard::{self, ShardRuns};
use shoal::sweep::Shard;

/// Heron Island in spring, a few chain runs per design at a coarse decimation.
fn spring() -> SeasonSpec {
    let mut s = SeasonSpec::preset("heron_island_year").unwrap();
    s.from = "2023-04-01".into();
    s.to = "2023-05-31".into();
    s.max_runs = 3;
    s.decimation = 16;
    s
}

/// Runs `season` as shard `index/count` and returns its runs file, read back from its RON text
/// (so the test covers what a second machine would read).
fn shard_of(season: &SeasonSpec, index: usize, count: usize) -> ShardRuns {
    let (study, ds) = designs(season, None).unwrap();
    let s = Shard { index, count };
    let result = run_season(season, &study, &ds, s, &RunControl::new(), |_, _| {}).unwrap();
    let plan = plan_season(season, &study, &ds).unwrap();
    let runs = shard::shard_runs(&plan, shard::key(&plan, &ds), s, &result);
    let text = shard::to_ron(&runs);
    ron::from_str(&text).unwrap()
}

#[test]
fn merged_shards_equal_the_whole_run_and_bad_ones_are_refused() {
    let season = spring();
    let (study, ds) = designs(&season, None).unwrap();
    let whole = run_season(&season, &study, &ds, Shard::ALL, &RunControl::new(), |_, _| {}).unwrap();
    let plan = plan_season(&season, &study, &ds).unwrap();
    let key = shard::key(&plan, &ds);
    assert!(plan.jobs.len() >= 4, "{} runs: too few to split", plan.jobs.len());
    let parts = vec![("b".to_string(), shard_of(&season, 1, 2)), ("a".to_string(), shard_of(&season, 0, 2))];
    assert_eq!(parts[0].1.runs.len() + parts[1].1.runs.len(), plan.jobs.len());
    let merged = shard::merge(&plan, &key, &parts).unwrap();
    assert_eq!(merged, whole, "the merge differs from the whole run");

    let refused = |parts: &[(String, ShardRuns)], expect: &str| {
        let e = shard::merge(&plan, &key, parts).unwrap_err().to_string();
        assert!(e.contains(expect), "expected `{expect}` in: {e}");
    };
    refused(&parts[..1], "shard 0/2 not given");
    refused(&[parts[0].clone(), parts[0].clone()], "are both shard 1/2");
    // Another season's (or another period's) shard.
    let mut other = parts.clone();
    other[1].1.key = "0123456789abcdef".into();
    refused(&other, "a is a shard of another season");
    // A run dropped (a shard that did not finish).
    let mut short = parts.clone();
    short[1].1.runs.pop();
    refused(&short, "did not finish it");
    // A run moved to another look, its numbers altered, its message with a control character.
    let mut moved = parts.clone();
    moved[1].1.runs[0].look += 1;
    refused(&moved, "but this season's run");
    let mut nan = parts.clone();
    nan[1].1.runs[0].errors[0].mae_pct = f64::NAN;
    refused(&nan, "allowed: MAE ≥ 0");
    let mut named = parts.clone();
    named[1].1.runs[0].errors[0].variable = "../chl".into();
    refused(&named, "holds '/'");
    let mut message = parts.clone();
    message[1].1.runs[0].failure = Some("\u{1b}[2Jcleared".into());
    refused(&message, "control characters");
    // A run given by the wrong shard.
    let mut stolen = parts.clone();
    let run = stolen[1].1.runs[0].clone();
    stolen[0].1.runs.push(run);
    refused(&stolen, "is not shard 1/2's");
}

/// The command line: two shards and their merge write the whole run's tables.
#[test]
fn season_command_shards_and_merges() {
    let base = std::env::temp_dir().join(format!("shoal-season-shards-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&base);
    let season = |extra: &[&str], out: &str| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_shoal"))
            .args(["season", "lake_hume_year", "--from", "2023-03-01", "--to", "2023-03-20"])
            .args(["--max-runs", "2", "--decimation", "32", "--no-figures", "--threads", "1"])
            .args(extra)
            .arg("--out")
            .arg(base.join(out))
            .output()
            .unwrap();
        (o.status.success(), String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr))
    };
    let (ok, text) = season(&[], "whole");
    assert!(ok, "{text}");
    for i in 0..2 {
        let (ok, text) = season(&["--shard", &format!("{i}/2")], &format!("s{i}"));
        assert!(ok && text.contains(&format!("shard {i}/2")), "{text}");
        assert!(!base.join(format!("s{i}/looks.csv")).exists(), "a shard writes its runs only");
    }
    let (s0, s1) = (base.join("s0").display().to_string(), base.join("s1").display().to_string());
    let (ok, text) = season(&["--merge", &s0, &s1], "merged");
    assert!(ok, "{text}");
    let looks = std::fs::read_to_string(base.join("merged/looks.csv")).unwrap();
    assert_eq!(looks.matches(",valid,yes,").count(), 4, "two runs per design: {looks}");
    for file in ["looks.csv", "months.csv", "runs.ron", "season.ron", "season.json"] {
        let read = |dir: &str| std::fs::read(base.join(dir).join(file)).unwrap();
        assert!(read("whole") == read("merged"), "{file} differs between the whole run and the merge");
    }
    // The merge with other options than the shards ran with is refused.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["season", "lake_hume_year", "--from", "2023-03-01", "--to", "2023-03-31", "--max-runs", "2"])
        .args(["--decimation", "32", "--merge", &s0, &s1, "--out"])
        .arg(base.join("bad"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("shard of another season"), "{o:?}");
    let _ = std::fs::remove_dir_all(&base);
}
