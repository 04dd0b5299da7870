//! The review pack (`shoal report`) in a real browser: Debian's Chromium (which `.ci/run`
//! installs) renders it headless; the page must not be blank, every image must load, and the
//! HTML must reference nothing outside itself.

use std::path::Path;
use std::process::Command;

fn shoal() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shoal"))
}

fn tempdir(name: &str) -> crate::common::TempDir {
    crate::common::TempDir::new("report", name)
}

fn ok(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap();
    assert!(out.status.success(), "{cmd:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Headless Chromium with the flags a closed network and a root user need (a fresh profile,
/// no sandbox, no background connections).
fn chromium(profile: &Path, args: &[String]) -> std::process::Output {
    Command::new("chromium")
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(args)
        .output()
        .unwrap_or_else(|e| {
            panic!("chromium does not run ({e}): install it (`apt-get install chromium`; .ci/run does)")
        })
}

/// Every `src="…"`, `href="…"` and `url(…)` of `html` that is not inside the file: not a
/// fragment, not a data URI, not a figure PNG written beside the page.
fn external_references(html: &str) -> Vec<String> {
    let mut found = Vec::new();
    for key in ["src=\"", "href=\"", "url("] {
        for (at, _) in html.match_indices(key) {
            let value: String = html[at + key.len()..].chars().take_while(|c| !matches!(c, '"' | ')')).collect();
            let local = value.starts_with('#') || value.starts_with("data:") || value.starts_with("figures/");
            if !local || value.contains("..") {
                found.push(value.chars().take(80).collect());
            }
        }
    }
    for marker in ["http://", "https://", "<script", "<link", "@import", "<iframe"] {
        if html.contains(marker) {
            found.push(marker.to_string());
        }
    }
    found
}

/// Checks the page from inside the browser after load: every `<image>` of the inline SVGs and
/// every `<img>` decoded to a non-empty bitmap, and every figure laid out with a size. Inserted
/// into a copy of the page only: the pack itself has no script.
const CHECKER: &str = r#"<script>
window.addEventListener('load', async () => {
  const hrefs = [...document.querySelectorAll('image, img')].map(e => e.getAttribute('href') || e.getAttribute('src'));
  let loaded = 0;
  await Promise.all(hrefs.map(h => new Promise(done => {
    const im = new Image();
    im.onload = () => { if (im.naturalWidth > 0 && im.naturalHeight > 0) loaded++; done(); };
    im.onerror = () => done();
    im.src = h;
  })));
  const svgs = [...document.querySelectorAll('figure svg')];
  const sized = svgs.filter(s => { const r = s.getBoundingClientRect(); return r.width > 100 && r.height > 100; }).length;
  document.body.setAttribute('data-check', `images ${loaded}/${hrefs.length} figures ${sized}/${svgs.length}`);
});
</script>"#;

#[test]
fn the_review_pack_renders_in_chromium_with_every_image_and_nothing_external() {
    if !crate::common::tool_available("chromium", "chromium") {
        return;
    }
    let dir = tempdir("pack");
    let results = dir.join("results");
    ok(shoal().args(["study", "cubesat_vs_smallsat", "--decimation", "8", "--no-cubes", "--out"]).arg(&results));
    let pack = dir.join("pack");
    ok(shoal().arg("report").arg(&results).arg("--out").arg(&pack));
    let html = std::fs::read_to_string(pack.join("index.html")).unwrap();

    // Self-contained: nothing outside the file but the PNG copies beside it.
    assert_eq!(external_references(&html), Vec::<String>::new());
    for f in std::fs::read_dir(results.join("figures")).unwrap() {
        let name = f.unwrap().file_name().to_string_lossy().into_owned();
        if let Some(stem) = name.strip_suffix(".svg") {
            assert!(html.contains(&format!("id=\"fig-{stem}\"")), "{stem} is not on the page");
            assert!(pack.join("figures").join(format!("{stem}.png")).is_file(), "{stem}.png");
        }
    }
    // What a reviewer looks for: the verdict (the CubeSat misses the chl-a MAE requirement),
    // both instruments, the commit, the configurations, the machine.
    assert!(html.contains("<th>cubesat</th>") && html.contains("<th>smallsat</th>"));
    assert!(html.contains("<td>SNR, every band ≥</td>"), "one SNR row, not one per band");
    assert!(html.contains("<b class=\"fail\">FAILS</b> — "), "a verdict card");
    assert!(html.contains(&format!("commit {}", shoal::report::commit())));
    assert!(html.contains("download=\"cubesat.ron\""));
    assert!(html.contains("Parameters that differ") && html.contains("aperture_mm"));
    assert!(html.contains("solar/solar_tsis1_hsrs_1nm.csv"), "the solar spectrum is a data source of every run");

    // Rendered by a real browser: a screenshot that is not blank.
    let profile = dir.join("profile");
    let shot = dir.join("shot.png");
    let out = chromium(
        &profile,
        &[
            "--window-size=1280,2400".into(),
            format!("--screenshot={}", shot.display()),
            format!("file://{}", pack.join("index.html").display()),
        ],
    );
    assert!(shot.is_file(), "no screenshot: {}", String::from_utf8_lossy(&out.stderr));
    let img = image::open(&shot).unwrap().to_rgb8();
    let n = (img.width() * img.height()) as f64;
    let luminance: Vec<f64> =
        img.pixels().map(|p| 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])).collect();
    let mean = luminance.iter().sum::<f64>() / n;
    let sd = (luminance.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / n).sqrt();
    let inked = luminance.iter().filter(|l| **l < 200.0).count() as f64 / n;
    let coloured = img.pixels().filter(|p| p[0].abs_diff(p[1]) > 40 || p[1].abs_diff(p[2]) > 40).count() as f64 / n;
    assert!(sd > 20.0 && inked > 0.03, "the page looks blank: luminance sd {sd:.1}, inked {:.1} %", 100.0 * inked);
    assert!(coloured > 0.002, "no colour on the first screen (the verdict's pass/fail): {:.2} %", 100.0 * coloured);

    // Every image loaded, every figure laid out (checked from inside the page, on a copy).
    let check = pack.join("check.html");
    // The copy drops the page's Content-Security-Policy, which (rightly) blocks the checker too.
    let csp_start = html.find("<meta http-equiv=\"Content-Security-Policy\"").expect("the page states its CSP");
    let csp_end = csp_start + html[csp_start..].find('>').unwrap() + 1;
    let unlocked = format!("{}{}", &html[..csp_start], &html[csp_end..]);
    std::fs::write(&check, unlocked.replace("</body>", &format!("{CHECKER}</body>"))).unwrap();
    let out = chromium(
        &profile,
        &["--virtual-time-budget=15000".into(), "--dump-dom".into(), format!("file://{}", check.display())],
    );
    let dom = String::from_utf8_lossy(&out.stdout);
    let result = dom.split("data-check=\"").nth(1).and_then(|s| s.split('"').next()).unwrap_or_else(|| {
        panic!(
            "the checker did not run: {}",
            String::from_utf8_lossy(&out.stderr).chars().take(2000).collect::<String>()
        )
    });
    let numbers: Vec<usize> = result.split(|c: char| !c.is_ascii_digit()).filter_map(|s| s.parse().ok()).collect();
    let [loaded, images, sized, figures] = numbers[..] else { panic!("{result}") };
    assert!(images > 0 && loaded == images, "images: {result}");
    assert!(figures > 10 && sized == figures, "figures: {result}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_report_straight_from_a_study_carries_its_error_budget_and_bad_targets_are_refused() {
    let dir = tempdir("budget");
    let pack = dir.join("pack");
    ok(shoal().args(["report", "reef_survey_depth", "--decimation", "8", "--budget", "--out"]).arg(&pack));
    let html = std::fs::read_to_string(pack.join("index.html")).unwrap();
    assert!(html.contains("id=\"budget\"") && html.contains("noise and quantisation"), "budget section");
    // Bottom type: the dominant substrate's maps, where it is right, the confusion table and
    // the depth error per true substrate.
    for part in [
        "id=\"substrate\"",
        "dominant substrate right in",
        "id=\"fig-maps_sambuca_substrate\"",
        "id=\"fig-agreement_sambuca_substrate\"",
        "true \\ retrieved",
        "depth over",
    ] {
        assert!(html.contains(part), "the pack has no `{part}`");
    }
    assert!(html.contains("Reduced resolution:"), "a pack at 1/8 says so at the top");
    assert!(html.contains("EPSG:32756"), "the raster scene's place");
    assert!(html.contains("The study states no requirements"));
    assert_eq!(external_references(&html), Vec::<String>::new());
    // A results directory `shoal study` wrote makes a page without rerunning (no budget: the
    // study did not run one).
    // With a sweep's curves beside the study's figures.
    let again = dir.join("again");
    let from_dir = dir.join("results");
    ok(shoal().args(["study", "reef_survey_depth", "--decimation", "8", "--no-cubes", "--out"]).arg(&from_dir));
    let sweep_file = dir.join("tiny_sweep.ron");
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/presets/sweeps/aperture_lake_hume.ron"))
        .unwrap()
        .replace("Range(from: 40, to: 300, steps: 8, log: true)", "List([50, 250])")
        .replace("seeds: [1, 2, 3, 4, 5]", "seeds: [1]");
    std::fs::write(&sweep_file, text).unwrap();
    let sweep = dir.join("aperture");
    ok(shoal().arg("sweep").arg(&sweep_file).args(["--decimation", "32", "--out"]).arg(&sweep));
    ok(shoal().arg("report").arg(&from_dir).arg("--sweep").arg(&sweep).arg("--out").arg(&again));
    let page = std::fs::read_to_string(again.join("index.html")).unwrap();
    assert!(page.contains("id=\"fig-maps_sambuca_depth_m\"") && !page.contains("id=\"budget\""));
    assert!(
        page.contains("Trade-off curves") && page.contains("id=\"fig-sweep_chl_mg_m3_aperture\""),
        "the sweep's curve"
    );
    let out =
        shoal().arg("report").arg(&from_dir).arg("--sweep").arg(&from_dir).arg("--out").arg(&again).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no figures (sweep_*.svg)"));

    let empty = tempdir("empty");
    let out = shoal().arg("report").arg(&empty).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no review.json"));
    let out = shoal().args(["report", "no_such_study"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&empty);
}

/// A season's summary and figures go into the pack; what its folder holds is escaped, and a
/// folder without a season, or with a summary that is not one, is refused naming it.
#[test]
fn a_season_goes_into_the_pack_escaped() {
    let dir = tempdir("season");
    let season = dir.join("season");
    ok(shoal()
        .args(["season", "lake_hume_year", "--from", "2023-03-01", "--to", "2023-03-31", "--max-runs", "1"])
        .args(["--decimation", "32", "--out"])
        .arg(&season));
    // What another person's folder could hold: markup in the season's description.
    let json = season.join("season.json");
    let text = std::fs::read_to_string(&json).unwrap();
    let planted = text.replacen("\"description\": \"", "\"description\": \"<script>alert(1)</script>", 1);
    assert_ne!(planted, text);
    std::fs::write(&json, planted).unwrap();
    let pack = dir.join("pack");
    ok(shoal()
        .args(["report", "cubesat_vs_smallsat_image", "--decimation", "32", "--season"])
        .arg(&season)
        .arg("--out")
        .arg(&pack));
    let html = std::fs::read_to_string(pack.join("index.html")).unwrap();
    for part in [
        "id=\"seasons\"",
        "<h3>lake_hume_year</h3>",
        "&lt;script&gt;alert(1)&lt;/script&gt;",
        "id=\"fig-season_valid_looks_season\"",
        "MAE % median",
        "returned % median",
    ] {
        assert!(html.contains(part), "the pack has no `{part}`");
    }
    assert!(!html.contains("<script>"), "a planted script reached the page raw");
    assert_eq!(external_references(&html), Vec::<String>::new());
    std::fs::write(&json, "{\"name\": 3}").unwrap();
    let out = shoal().args(["report", "cubesat_vs_smallsat_image", "--season"]).arg(&season).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a season summary"), "{out:?}");
    let out = shoal().args(["report", "cubesat_vs_smallsat_image", "--season"]).arg(&dir).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("season.json"), "{out:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A figure planted in a results folder with a script, an event handler and an image from a
/// server on this machine: in Chromium no script runs and no request reaches the server — both
/// for the pack as written (the figure is left out) and for a copy with the planted SVG pasted
/// into the page raw, which only the page's Content-Security-Policy then stops.
#[test]
fn a_planted_figure_runs_no_script_and_calls_nowhere_in_chromium() {
    if !crate::common::tool_available("chromium", "chromium") {
        return;
    }
    use std::io::Read as _;
    let dir = tempdir("planted");
    let results = dir.join("results");
    ok(shoal().args(["study", "cubesat_vs_smallsat", "--decimation", "16", "--no-cubes", "--out"]).arg(&results));
    // A server that records whether anything connects.
    let server = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    server.set_nonblocking(true).unwrap();
    let port = server.local_addr().unwrap().port();
    let planted = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"50\" height=\"50\" onload=\"document.body.setAttribute('data-pwned','onload')\">\
         <script>document.body.setAttribute('data-pwned','script')</script>\
         <image href=\"http://127.0.0.1:{port}/leak.png\" width=\"10\" height=\"10\"/>\
         <rect width=\"10\" height=\"10\" style=\"fill:url(http://127.0.0.1:{port}/css)\"/></svg>"
    );
    std::fs::write(results.join("figures/snr.svg"), &planted).unwrap();
    let pack = dir.join("pack");
    ok(shoal().arg("report").arg(&results).arg("--out").arg(&pack));
    let page = std::fs::read_to_string(pack.join("index.html")).unwrap();
    assert!(page.contains("Figure snr left out: not a figure Shoal draws"), "the reviewer is told");
    // The second wall: the same page with the hostile SVG pasted in raw.
    let raw = pack.join("raw.html");
    std::fs::write(&raw, page.replacen("<section id=\"figures\">", &format!("<section id=\"figures\">{planted}"), 1))
        .unwrap();
    let profile = dir.join("profile");
    for file in [pack.join("index.html"), raw] {
        let out = chromium(
            &profile,
            &["--virtual-time-budget=5000".into(), "--dump-dom".into(), format!("file://{}", file.display())],
        );
        let dom = String::from_utf8_lossy(&out.stdout);
        assert!(dom.contains("Shoal review pack"), "{}: not rendered", file.display());
        // The attribute the planted script sets (its source text quotes it with ' only).
        assert!(!dom.contains("data-pwned=\""), "{}: a planted script ran", file.display());
    }
    let mut request = Vec::new();
    match server.accept() {
        Ok((mut s, _)) => {
            let _ = s.read_to_end(&mut request);
            panic!("the page called out: {}", String::from_utf8_lossy(&request));
        }
        Err(e) => assert_eq!(e.kind(), std::io::ErrorKind::WouldBlock, "{e}"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}
