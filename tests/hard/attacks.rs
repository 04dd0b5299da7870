//! Presets, rasters, sessions and results folders travel between colleagues and cluster jobs:
//! what is inside them is untrusted. This suite attacks the `shoal` binary the way a hostile or
//! broken file would — mutated RON of every preset kind, names that are paths, planted figures,
//! reused and interrupted output folders, runs sized to exhaust the machine, values at the gaps
//! of the range table — and counts, per category, the cases handled cleanly: exit 0, or exit 2
//! with one `error:` line; never a signal, a panic, exit 1 for the user's input, a write outside
//! `--out`, a script in the review pack, or a run that outlives its time limit.
//!
//! `SHOAL_ATTACK_BIN=path/to/shoal` runs it against another build (the table of an earlier
//! commit); the assertions then report what that build gets wrong.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

mod files;
mod runs;
use files::{budgets_everywhere, netcdf_bombs, shard_records, special_and_oversized};
use runs::{folders, gaps, resources};

/// The binary under attack.
fn shoal_bin() -> PathBuf {
    std::env::var_os("SHOAL_ATTACK_BIN").map_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_shoal")), PathBuf::from)
}

fn presets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("presets")
}

fn tempdir(name: &str) -> crate::common::TempDir {
    crate::common::TempDir::new("attack", name)
}

/// How one invocation ended.
#[derive(Debug)]
struct Outcome {
    code: Option<i32>,
    stderr: String,
    seconds: f64,
}

impl Outcome {
    /// Exit 0, or exit 2 with exactly one `error:` line and no panic; within `limit_s`.
    fn clean(&self, limit_s: f64) -> Result<(), String> {
        let errors = self.stderr.lines().filter(|l| l.starts_with("error: ")).count();
        let first = self.stderr.lines().find(|l| l.starts_with("error: ")).unwrap_or_default();
        match self.code {
            _ if self.seconds > limit_s => Err(format!("took {:.1} s (limit {limit_s} s)", self.seconds)),
            _ if self.stderr.contains("panicked") => Err(format!("panicked: {}", tail(&self.stderr))),
            Some(0) => Ok(()),
            Some(2) if errors == 1 => Ok(()),
            Some(2) => Err(format!("exit 2 with {errors} error lines: {}", tail(&self.stderr))),
            Some(c) => Err(format!("exit {c}: {} {}", first, tail(&self.stderr))),
            None => Err(format!("killed by a signal: {}", tail(&self.stderr))),
        }
    }

    /// Refused as the user's input (exit 2, one line) mentioning `said`.
    fn refused(&self, said: &str, limit_s: f64) -> Result<(), String> {
        self.clean(limit_s)?;
        if self.code != Some(2) {
            return Err(format!("accepted (exit {:?}), expected a refusal naming `{said}`", self.code));
        }
        if !self.stderr.contains(said) {
            return Err(format!("refused without naming `{said}`: {}", tail(&self.stderr)));
        }
        Ok(())
    }
}

fn tail(s: &str) -> String {
    let lines: Vec<&str> = s.lines().filter(|l| !l.trim().is_empty()).collect();
    lines[lines.len().saturating_sub(2)..].join(" | ").chars().take(300).collect()
}

/// Run the binary with `args` in `dir`, under a 6 GB address-space cap (a run that ignores its
/// budget aborts there instead of swapping the machine) and a wall-clock limit.
fn run(dir: &Path, args: &[&str], env: &[(&str, &str)], limit: Duration) -> Outcome {
    let mut cmd = Command::new("sh");
    cmd.arg("-c").arg("ulimit -v 6000000; exec \"$0\" \"$@\"").arg(shoal_bin()).args(args).current_dir(dir);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.stdout(std::process::Stdio::null()).stderr(std::process::Stdio::piped());
    let start = Instant::now();
    let mut child = cmd.spawn().unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let reader = std::thread::Builder::new()
        .name("attack-stderr".into())
        .spawn(move || {
            let mut s = String::new();
            let _ = std::io::Read::read_to_string(&mut stderr, &mut s);
            s
        })
        .unwrap();
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break Some(-1);
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Outcome { code, stderr: reader.join().unwrap_or_default(), seconds: start.elapsed().as_secs_f64() }
}

/// Counts per category: tried, handled cleanly, and the failures' descriptions.
#[derive(Default)]
struct Tally(BTreeMap<&'static str, (usize, usize, Vec<String>)>);

impl Tally {
    fn record(&mut self, category: &'static str, case: &str, result: Result<(), String>) {
        let e = self.0.entry(category).or_default();
        e.0 += 1;
        match result {
            Ok(()) => e.1 += 1,
            Err(why) => e.2.push(format!("{case}: {why}")),
        }
    }

    fn finish(self) {
        let mut table = String::from("\n| category | tried | handled cleanly | failed |\n|---|---|---|---|\n");
        let mut failures = Vec::new();
        for (cat, (tried, ok, fails)) in &self.0 {
            table.push_str(&format!("| {cat} | {tried} | {ok} | {} |\n", tried - ok));
            failures.extend(fails.iter().map(|f| format!("[{cat}] {f}")));
        }
        eprintln!("{table}");
        assert!(failures.is_empty(), "{} cases not handled cleanly:\n{}", failures.len(), failures.join("\n"));
    }
}

/// A deterministic generator (xorshift64*): the same mutations on every machine.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    pub(crate) fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Mutation `k` of RON `text`: a number made hostile, a string made a path or a script, a
/// character deleted, a line doubled, the text cut, a bracket swapped, garbage inserted.
fn mutate(text: &str, rng: &mut Rng) -> String {
    let bytes: Vec<(usize, char)> = text.char_indices().collect();
    let numbers: Vec<(usize, usize)> = {
        let mut v = Vec::new();
        let mut i = 0;
        while i < bytes.len() {
            let (at, c) = bytes[i];
            let prev = if i > 0 { bytes[i - 1].1 } else { ' ' };
            if c.is_ascii_digit() && !prev.is_alphanumeric() && prev != '_' && prev != '"' {
                let mut j = i;
                while j < bytes.len() && (bytes[j].1.is_ascii_digit() || ".e-".contains(bytes[j].1)) {
                    j += 1;
                }
                let end = if j < bytes.len() { bytes[j].0 } else { text.len() };
                v.push((at, end));
                i = j;
            } else {
                i += 1;
            }
        }
        v
    };
    let strings: Vec<(usize, usize)> =
        text.match_indices('"').map(|(i, _)| i).collect::<Vec<_>>().chunks_exact(2).map(|p| (p[0] + 1, p[1])).collect();
    match rng.below(8) {
        0 | 1 if !numbers.is_empty() => {
            let (a, b) = numbers[rng.below(numbers.len())];
            let hostile = ["NaN", "inf", "-inf", "-1", "0", "1e308", "-1e308", "1e-308", "99999999999", "0.5", "65536"];
            format!("{}{}{}", &text[..a], hostile[rng.below(hostile.len())], &text[b..])
        }
        2 if !strings.is_empty() => {
            let (a, b) = strings[rng.below(strings.len())];
            let long = "a".repeat(300);
            let hostile = ["../../escaped", "/tmp/abs", "a\\u{0}b", &long, "<script>alert(1)</script>", "", " .. "];
            format!("{}{}{}", &text[..a], hostile[rng.below(hostile.len())], &text[b..])
        }
        3 => {
            let (at, c) = bytes[rng.below(bytes.len())];
            format!("{}{}", &text[..at], &text[at + c.len_utf8()..])
        }
        4 => {
            let lines: Vec<&str> = text.lines().collect();
            let k = rng.below(lines.len());
            let mut out: Vec<&str> = lines.clone();
            out.insert(k, lines[k]);
            out.join("\n")
        }
        5 => text[..bytes[rng.below(bytes.len())].0].to_string(),
        6 => text.replacen('(', "[", 1 + rng.below(3)),
        _ => {
            let (at, _) = bytes[rng.below(bytes.len())];
            let junk = [",,", "}", "(", "\u{0}", "\u{FEFF}", "𝄞", "r#\"", "/*"];
            format!("{}{}{}", &text[..at], junk[rng.below(junk.len())], &text[at..])
        }
    }
}

/// The sweep preset cut to two apertures and one seed (a mutated sweep must not run 80 runs).
fn small_sweep() -> String {
    std::fs::read_to_string(presets().join("sweeps/aperture_lake_hume.ron"))
        .unwrap()
        .replace("Range(from: 40, to: 300, steps: 8, log: true)", "List([50, 250])")
        .replace("seeds: [1, 2, 3, 4, 5]", "seeds: [1]")
}

fn ron_files(folder: &str) -> Vec<(String, String)> {
    let mut v: Vec<(String, String)> = std::fs::read_dir(presets().join(folder))
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read_to_string(&p).unwrap()))
        .collect();
    v.sort();
    v
}

/// RON mutations of every preset kind, each run as its command would run it (at 1/64).
fn mutations(tally: &mut Tally, per_kind: usize) {
    let dir = tempdir("mutations");
    std::os::unix::fs::symlink(presets().join("scenes/rasters"), dir.join("rasters")).unwrap();
    let mut rng = Rng(0x05EE_D0F5_A0A1);
    let kinds: [(&'static str, Vec<(String, String)>); 4] = [
        ("RON mutations: instruments", ron_files("instruments")),
        ("RON mutations: scenes", ron_files("scenes")),
        ("RON mutations: studies", ron_files("studies")),
        ("RON mutations: sweeps", vec![("aperture_lake_hume.ron".into(), small_sweep())]),
    ];
    for (category, files) in &kinds {
        for k in 0..per_kind {
            let (name, text) = &files[k % files.len()];
            let file = dir.join(format!("m{k}_{name}"));
            std::fs::write(&file, mutate(text, &mut rng)).unwrap();
            let f = file.to_string_lossy().into_owned();
            let out = dir.join(format!("out{k}"));
            let o = out.to_string_lossy().into_owned();
            let args: Vec<&str> = match *category {
                "RON mutations: instruments" => {
                    vec![
                        "simulate",
                        "--instrument",
                        &f,
                        "--scene",
                        "lake_hume_bloom",
                        "--decimation",
                        "64",
                        "--out",
                        &o,
                    ]
                }
                "RON mutations: scenes" => {
                    vec!["simulate", "--scene", &f, "--instrument", "cubesat", "--decimation", "64", "--out", &o]
                }
                "RON mutations: studies" => {
                    vec!["study", &f, "--decimation", "64", "--no-cubes", "--no-figures", "--out", &o]
                }
                _ => vec!["sweep", &f, "--decimation", "64", "--no-figures", "--out", &o],
            };
            let outcome = run(&dir, &args, &[("SHOAL_MEMORY_BUDGET", "3G")], Duration::from_secs(120));
            let mut result = outcome.clean(120.0);
            if result.is_ok() {
                result = nothing_outside(&dir, &["rasters"]);
            }
            tally.record(category, &format!("{name} mutation {k}"), result);
            let _ = std::fs::remove_dir_all(&out);
            let _ = std::fs::remove_file(&file);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Only the test's own files (`m*`, `out*`) and `allowed` are in `dir`, and nothing of Shoal's
/// was written into its parent.
fn nothing_outside(dir: &Path, allowed: &[&str]) -> Result<(), String> {
    for e in std::fs::read_dir(dir).unwrap().filter_map(Result::ok) {
        let n = e.file_name().to_string_lossy().into_owned();
        if !(n.starts_with('m') || n.starts_with("out") || allowed.contains(&n.as_str())) {
            return Err(format!("wrote `{n}` outside --out"));
        }
    }
    Ok(())
}

/// An instrument or study whose name is a path; output folders that are not Shoal's.
fn hostile_paths(tally: &mut Tally) {
    let root = tempdir("paths");
    let work = root.join("a/b");
    std::fs::create_dir_all(&work).unwrap();
    let cubesat = std::fs::read_to_string(presets().join("instruments/cubesat.ron")).unwrap();
    for name in ["../../X", "/tmp/shoal-abs", "..", "a/../../b", ".hidden", "nul\\u{0}"] {
        std::fs::write(work.join("inst.ron"), cubesat.replace("name: \"cubesat\"", &format!("name: \"{name}\"")))
            .unwrap();
        let study = "StudySpec(name: \"s\", scene: Preset(\"lake_hume_bloom\"), instruments: [File(\"inst.ron\")], retrievals: [Almi()])";
        std::fs::write(work.join("s.ron"), study).unwrap();
        let o = run(
            &work,
            &["study", "s.ron", "--decimation", "64", "--no-figures", "--out", "out"],
            &[],
            Duration::from_secs(60),
        );
        let mut result = o.refused("name", 60.0);
        let escaped: Vec<String> = walk(&root)
            .into_iter()
            .filter(|p| !p.starts_with(work.join("out")) && !p.ends_with("inst.ron") && !p.ends_with("s.ron"))
            .map(|p| p.display().to_string())
            .collect();
        if !escaped.is_empty() {
            result = Err(format!("wrote outside --out: {escaped:?}"));
        }
        tally.record("hostile names and paths", &format!("instrument named {name:?}"), result);
        let _ = std::fs::remove_dir_all(work.join("out"));
    }
    // --out that is not a folder of Shoal's: a foreign folder, a file, the current directory.
    std::fs::create_dir_all(work.join("thesis")).unwrap();
    std::fs::write(work.join("thesis/chapter1.tex"), "mine").unwrap();
    std::fs::write(work.join("file.txt"), "mine").unwrap();
    for (out, said) in [("thesis", "did not write"), ("file.txt", "is a file"), (".", "--out"), ("..", "--out")] {
        let o = run(
            &work,
            &["study", "--decimation", "64", "--no-cubes", "--no-figures", "--out", out],
            &[],
            Duration::from_secs(60),
        );
        let mut result = o.refused(said, 60.0);
        if std::fs::read_to_string(work.join("thesis/chapter1.tex")).ok().as_deref() != Some("mine") {
            result = Err("the user's file was changed".into());
        }
        tally.record("hostile names and paths", &format!("--out {out}"), result);
    }
    let _ = std::fs::remove_dir_all(&root);
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).into_iter().flatten().filter_map(Result::ok) {
        let p = e.path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

/// Planted figures and a tampered review.json: nothing from the folder reaches the page raw.
fn review_pack_injection(tally: &mut Tally) {
    let dir = tempdir("inject");
    let results = dir.join("results");
    let o =
        run(&dir, &["study", "--decimation", "16", "--no-cubes", "--out", "results"], &[], Duration::from_secs(120));
    assert_eq!(o.code, Some(0), "{}", o.stderr);
    let planted = [
        ("script", "<svg xmlns=\"http://www.w3.org/2000/svg\"><script>document.title='pwned'</script></svg>"),
        ("onload", "<svg onload=\"document.title='pwned'\"><rect/></svg>"),
        ("remote image", "<svg><image href=\"http://127.0.0.1:9/x.png\" width=\"1\" height=\"1\"/></svg>"),
        ("css url", "<svg><rect style=\"fill:url(http://127.0.0.1:9/#a)\"/></svg>"),
        ("entity", "<!DOCTYPE svg [<!ENTITY x SYSTEM \"file:///etc/passwd\">]><svg><text>&x;</text></svg>"),
        ("foreign object", "<svg><foreignObject><iframe src=\"http://127.0.0.1:9\"/></foreignObject></svg>"),
        ("javascript href", "<svg><a href=\"javascript:alert(1)\"><text>x</text></a></svg>"),
    ];
    let original = std::fs::read(results.join("figures/snr.svg")).unwrap();
    for (what, svg) in planted {
        std::fs::write(results.join("figures/snr.svg"), svg).unwrap();
        std::fs::write(results.join("figures/zz_planted.svg"), svg).unwrap();
        let _ = std::fs::remove_dir_all(dir.join("pack"));
        let o = run(&dir, &["report", "results", "--out", "pack"], &[], Duration::from_secs(60));
        let result = o.clean(60.0).and_then(|()| {
            let html = std::fs::read_to_string(dir.join("pack/index.html")).map_err(|e| e.to_string())?;
            // The note that says why a figure was left out quotes what was met, escaped (inert
            // text); everything else on the page must be free of it.
            let html = without_notes(&html);
            if !html.contains("left out") {
                return Err("no note says the planted figure was left out".into());
            }
            let bad = ["<script", "onload", "http://127.0.0.1", "javascript:", "foreignObject", "passwd", "pwned"]
                .into_iter()
                .filter(|m| html.contains(m))
                .collect::<Vec<_>>();
            if !bad.is_empty() {
                return Err(format!("the page holds {bad:?}"));
            }
            if html.contains("zz_planted") {
                return Err("an unlisted figure was read".into());
            }
            Ok(())
        });
        tally.record("review pack injection", what, result);
    }
    std::fs::write(results.join("figures/snr.svg"), original).unwrap();
    // review.json naming files outside the folder, or not parsing at all.
    let json = std::fs::read_to_string(results.join("review.json")).unwrap();
    // Cut in half at a character boundary (the file holds units such as sr⁻¹).
    let half = (0..=json.len() / 2).rev().find(|&i| json.is_char_boundary(i)).unwrap_or(0);
    let cases = [
        ("figure name ../../", json.replacen("\"snr\"", "\"../../../../etc/passwd\"", 1), "review.json"),
        ("figure name absolute", json.replacen("\"snr\"", "\"/etc/hostname\"", 1), "review.json"),
        ("truncated review.json", json[..half].to_string(), "review.json"),
        ("review.json not JSON", "\u{FEFF}<html>".to_string(), "review.json"),
    ];
    for (what, text, said) in cases {
        std::fs::write(results.join("review.json"), text).unwrap();
        let _ = std::fs::remove_dir_all(dir.join("pack"));
        let o = run(&dir, &["report", "results", "--out", "pack"], &[], Duration::from_secs(60));
        tally.record("review pack injection", what, o.refused(said, 60.0));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `html` with the text of each "Figure … left out: …" note replaced by "left out".
fn without_notes(html: &str) -> String {
    let mut out = String::new();
    let mut rest = html;
    while let Some(at) = rest.find("left out: ") {
        out.push_str(&rest[..at]);
        out.push_str("left out");
        rest = &rest[at..];
        rest = &rest[rest.find("</p>").unwrap_or(rest.len())..];
    }
    out.push_str(rest);
    out
}

#[test]
fn untrusted_files_and_folders_are_handled_cleanly() {
    let mut tally = Tally::default();
    let per_kind = std::env::var("SHOAL_ATTACK_MUTATIONS").ok().and_then(|v| v.parse().ok()).unwrap_or(40);
    hostile_paths(&mut tally);
    review_pack_injection(&mut tally);
    resources(&mut tally);
    gaps(&mut tally);
    folders(&mut tally);
    shard_records(&mut tally);
    netcdf_bombs(&mut tally);
    special_and_oversized(&mut tally);
    budgets_everywhere(&mut tally);
    mutations(&mut tally, per_kind);
    tally.finish();
}
