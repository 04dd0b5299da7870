//! Seasons: the valid looks against an independent count, a look's chain run at its geometry,
//! the command line, and bad season files.

use shoal::control::RunControl;
use shoal::orbit::{Site, SunSynchronous, accesses, days_since_j2000};
use shoal::season::SeasonSpec;
use shoal::season::looks::{Verdict, half_field_of_view_rad};
use shoal::season::run::{designs, look_config, phase_spread, run_season};
use shoal::sweep::Shard;

fn spring(max_runs: usize) -> SeasonSpec {
    let mut s = SeasonSpec::preset("heron_island_year").unwrap();
    s.from = "2023-04-01".into();
    s.to = "2023-06-30".into();
    s.max_runs = max_runs;
    s.decimation = 16;
    s
}

/// A season's months are the site's: over a site at 170° E (local mean time 11 h 20 min ahead of
/// UT) a 09:30 descending pass is at about 22:10 UT the day before, so a look on the 1st of a
/// month falls in the month before by UT's date. Each month's count is the count by the site's
/// date (written out here: UT + 170/360 days), which differs from UT's in some month of the year;
/// and each look's cloud cover is its local month's (a climatology of alternately clear and
/// overcast months: the draw of a fraction of 0 is 0, of 1 is 1).
#[test]
fn a_seasons_months_are_the_sites_local_dates() {
    let mut season = spring(0);
    season.site = (-23.44, 170.0);
    season.orbit.descending_node_h = 9.5;
    season.from = "2023-01-01".into();
    season.to = "2023-12-31".into();
    let alternate: Vec<f64> = (0..12).map(|m| f64::from(m % 2)).collect();
    season.clouds = Some(shoal::season::CloudSpec {
        monthly_fraction: alternate.clone(),
        source: "test".into(),
        concentration: 1.0,
    });
    let (study, ds) = designs(&season, None).unwrap();
    let result = run_season(&season, &study, &ds, Shard::ALL, &RunControl::new(), |_, _| {}).unwrap();
    let month_of = |days: f64| {
        let (y, m, _) = shoal::orbit::sun::calendar_date(days);
        (y, m)
    };
    for d in &result.designs {
        let months = d.per_month(None, result.period, season.local_offset_days());
        assert_eq!(months.len(), 12, "{}", d.label);
        let by_local: Vec<usize> = months
            .iter()
            .map(|(k, _)| d.looks.iter().filter(|l| month_of(l.access.days + 170.0 / 360.0) == *k).count())
            .collect();
        let by_ut: Vec<usize> =
            months.iter().map(|(k, _)| d.looks.iter().filter(|l| month_of(l.access.days) == *k).count()).collect();
        assert_eq!(months.iter().map(|m| m.1).collect::<Vec<_>>(), by_local, "{}", d.label);
        assert_ne!(by_local, by_ut, "{}: no look on a month's first day to tell the dates apart", d.label);
        assert_eq!(by_local.iter().sum::<usize>(), d.looks.len(), "{}: a look outside the site's year", d.label);
        for l in &d.looks {
            let (_, month) = month_of(l.access.days + 170.0 / 360.0);
            assert_eq!(l.cloud_cover, alternate[month as usize - 1], "{}: look at {}", d.label, l.access.days);
        }
    }
}

/// Cox–Munk glint written out here from the slope statistics (not through the crate's glint
/// code): facet normal h = s + v, tan²β = (h_x² + h_y²)/h_z², p = exp(−tan²β/σ²)/(πσ²),
/// L_GN = R_F p / (4 cos θ_v cos⁴β) with the Fresnel reflectance of unpolarised light.
fn glint_lgn(sun_zenith: f64, view_zenith: f64, relative_azimuth: f64, wind: f64) -> f64 {
    let s = [sun_zenith.sin(), 0.0, sun_zenith.cos()];
    let v = [view_zenith.sin() * relative_azimuth.cos(), view_zenith.sin() * relative_azimuth.sin(), view_zenith.cos()];
    let h = [s[0] + v[0], s[1] + v[1], s[2] + v[2]];
    let norm = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    let cos_beta = h[2] / norm;
    let tan2 = (h[0] * h[0] + h[1] * h[1]) / (h[2] * h[2]);
    let sigma2 = 0.003 + 0.005_12 * wind;
    let p = (-tan2 / sigma2).exp() / (std::f64::consts::PI * sigma2);
    let ci = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) / norm;
    let n = 1.34;
    let ct = (1.0 - (1.0 - ci * ci) / (n * n)).sqrt();
    let rs = ((ci - n * ct) / (ci + n * ct)).powi(2);
    let rp = ((n * ci - ct) / (n * ci + ct)).powi(2);
    0.5 * (rs + rp) * p / (4.0 * view_zenith.cos() * cos_beta.powi(4))
}

/// Each design's looks are the accesses inside its swath (at any allowed roll), and a look is
/// valid exactly when the sun is high enough, the glint (computed here) below the threshold and
/// the cover leaves enough of the site clear.
#[test]
fn valid_looks_match_an_independent_count() {
    let season = spring(0);
    let (study, ds) = designs(&season, None).unwrap();
    let result = run_season(&season, &study, &ds, Shard::ALL, &RunControl::new(), |_, _| {}).unwrap();
    assert_eq!(result.designs.len(), 2);
    // The site's dates: its local mean midnight is longitude / 360 days ahead of UT's.
    let local = season.site.1 / 360.0;
    let from = days_since_j2000(&season.from).unwrap() - local;
    let to = days_since_j2000(&season.to).unwrap() + 1.0 - local;
    let site = Site::from_degrees(season.site.0, season.site.1);
    let mut any_valid = false;
    for (d, (_, config)) in result.designs.iter().zip(&ds) {
        let orbit = SunSynchronous {
            altitude_m: config.instrument.altitude_km * 1e3,
            descending_node_h: season.orbit.descending_node_h,
            phase_rad: 0.0,
            epoch_days: days_since_j2000("2023-01-01").unwrap(),
        };
        let half = half_field_of_view_rad(&config.instrument);
        let reach = season.max_roll_deg.to_radians() + half;
        let passes: Vec<_> =
            accesses(&orbit, &site, from, to, reach).into_iter().filter(|a| a.off_nadir_rad.abs() <= reach).collect();
        assert_eq!(d.looks.len(), passes.len(), "{}", d.label);
        let mut valid = 0;
        for (look, pass) in d.looks.iter().zip(&passes) {
            assert_eq!(look.access, *pass);
            let g = &look.geometry;
            let glint = glint_lgn(g.sun_zenith_rad, g.view_zenith_rad, g.relative_azimuth_rad, season.wind_m_s);
            let sun_ok = pass.sun.zenith_rad <= season.max_sun_zenith_deg.to_radians();
            if sun_ok {
                // Relative 1e-9: the same formula in another order.
                assert!(
                    (glint - look.glint_per_sr).abs() <= 1e-9 * glint.max(1e-12),
                    "{glint} vs {}",
                    look.glint_per_sr
                );
            }
            let clear = 100.0 * (1.0 - look.cloud_cover) >= season.min_clear_pct;
            let expected = if !sun_ok {
                Verdict::SunLow
            } else if g.view_zenith_rad > season.max_view_zenith_deg.to_radians() {
                Verdict::ViewOblique
            } else if glint > season.glint_threshold_per_sr {
                Verdict::Glint
            } else if !clear {
                Verdict::Cloud
            } else {
                Verdict::Valid
            };
            assert_eq!(look.verdict, expected);
            valid += usize::from(expected == Verdict::Valid);
        }
        assert_eq!(d.valid_days().len(), valid);
        any_valid |= valid > 0;
        // Months of the period, April to June, each counted.
        let months = d.per_month(None, (from, to), season.local_offset_days());
        assert_eq!(months.len(), 3);
        assert_eq!(months.iter().map(|m| m.1).sum::<usize>(), d.looks.len());
        assert_eq!(d.phases.len(), shoal::season::run::PHASE_SAMPLES);
    }
    assert!(any_valid, "autumn 2023 over Heron Island has valid looks at phase 0");
    // Both designs fly 560 km: the same passes under the same weather.
    let cover = |d: &shoal::season::run::DesignSeason| d.looks.iter().map(|l| l.cloud_cover).collect::<Vec<_>>();
    assert_eq!(cover(&result.designs[0]), cover(&result.designs[1]));
}

/// A look's run is the study's configuration at the look's sun, date, heading and pointing, and
/// its products are scored (decimation 16: the test checks the wiring, not the numbers).
#[test]
fn a_valid_look_runs_the_chain_at_its_geometry() {
    let season = spring(1);
    let (study, ds) = designs(&season, None).unwrap();
    let result = run_season(&season, &study, &ds[..1], Shard::ALL, &RunControl::new(), |_, _| {}).unwrap();
    let d = &result.designs[0];
    assert_eq!(d.runs.len(), 1);
    let run = &d.runs[0];
    assert!(run.failure.is_none(), "{:?}", run.failure);
    let look = &d.looks[run.look];
    assert_eq!(look.verdict, Verdict::Valid);
    let config = look_config(&ds[0].1, look, 16);
    assert!((config.scene.sun.zenith_deg - look.access.sun.zenith_rad.to_degrees()).abs() < 1e-12);
    assert!((config.instrument.across_track_tilt_deg - look.access.off_nadir_rad.to_degrees()).abs() < 1e-12);
    assert!(config.scene.date.starts_with("2023-0"));
    // The surface the look's glint was judged on, with its glint in the chain.
    assert!(config.scene.effects.contains(&shoal::scene::Effect::SunGlint));
    assert_eq!(config.scene.atmosphere.surface, shoal::atmosphere::SeaSurface::Wind { speed_m_s: look.wind_m_s });
    let depth = run.errors.iter().find(|e| e.variable == "depth_m").expect("SAMBUCA's depth");
    assert!(depth.mae_pct.is_finite() && depth.returned_pct > 50.0, "{depth:?}");
}

/// A look's drawn cloud cover is in its scene, seeded by the hour of the pass: the same field for
/// every design flying that pass, another for the next pass, none for a clear look.
#[test]
fn a_look_s_clouds_are_in_its_scene() {
    let season = spring(0);
    let (study, ds) = designs(&season, None).unwrap();
    let result = run_season(&season, &study, &ds, Shard::ALL, &RunControl::new(), |_, _| {}).unwrap();
    let (a, b) = (&result.designs[0], &result.designs[1]);
    let cloudy: Vec<usize> =
        (0..a.looks.len()).filter(|&k| a.looks[k].cloud_cover > 0.0 && a.looks[k].verdict == Verdict::Valid).collect();
    assert!(cloudy.len() >= 2, "{} partly cloudy valid looks", cloudy.len());
    let clouds = |d: &shoal::season::run::DesignSeason, k: usize| look_config(&ds[0].1, &d.looks[k], 16).scene.clouds;
    let first = clouds(a, cloudy[0]).expect("a cloud layer");
    assert_eq!(first.cover, a.looks[cloudy[0]].cloud_cover);
    // The same pass seen by the second design: the same field.
    let same = b.looks.iter().position(|l| (l.access.days - a.looks[cloudy[0]].access.days).abs() < 1e-9).unwrap();
    assert_eq!(clouds(b, same), Some(first.clone()));
    assert_ne!(clouds(a, cloudy[1]).unwrap().seed, first.seed);
    if let Some(clear) = a.looks.iter().position(|l| l.cloud_cover == 0.0) {
        assert!(clouds(a, clear).is_none());
    }
}

#[test]
fn bad_seasons_are_refused_by_field() {
    let base = spring(0);
    let refused = |edit: &dyn Fn(&mut SeasonSpec), field: &str| {
        let mut s = base.clone();
        edit(&mut s);
        let e = s.validate().unwrap_err();
        assert!(e.field.contains(field), "{field}: {e}");
    };
    refused(&|s| s.site.0 = 95.0, "latitude");
    refused(&|s| s.to = "2023-02-30".into(), "to");
    refused(&|s| s.to = "2022-12-01".into(), "to");
    refused(&|s| s.from = "yesterday".into(), "from");
    refused(&|s| s.max_roll_deg = 80.0, "max_roll_deg");
    refused(&|s| s.decimation = 0, "decimation");
    refused(
        &|s| s.clouds.as_mut().unwrap().monthly_fraction.pop().map(|_| ()).unwrap_or(()),
        "clouds.monthly_fraction",
    );
    refused(&|s| s.clouds.as_mut().unwrap().monthly_fraction[3] = 1.5, "clouds.monthly_fraction");
    refused(&|s| s.revisit = Some(shoal::season::RevisitRequirement { days: 0.0, pct: 80.0 }), "revisit.days");
    assert!(SeasonSpec::from_ron("SeasonSpec(name: \"x\")", "x.ron").is_err());
}

#[test]
fn season_command_writes_looks_and_months() {
    let dir = std::env::temp_dir().join(format!("shoal-season-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["season", "lake_hume_year", "--from", "2023-03-01", "--to", "2023-03-31", "--max-runs", "0", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("valid looks per month: 2023-03"), "{stdout}");
    assert!(stdout.contains("over 12 orbit phases"), "{stdout}");
    let looks = std::fs::read_to_string(dir.join("looks.csv")).unwrap();
    assert!(looks.starts_with("design,date_ut,time_ut,date_local,descending,sun_zenith_deg"));
    let months = std::fs::read_to_string(dir.join("months.csv")).unwrap();
    assert_eq!(months.lines().count(), 3, "{months}");
    assert!(dir.join("season_valid_looks.svg").exists() && dir.join("season_valid_looks.png").exists());
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["season", "lake_hume_year", "--to", "2023-13-01", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("month 13"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The looks, their cloud draws and the phase spread do not depend on the threads.
#[test]
fn a_season_does_not_depend_on_the_threads() {
    let season = spring(0);
    let (study, ds) = designs(&season, None).unwrap();
    let on = |n: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(|| run_season(&season, &study, &ds, Shard::ALL, &RunControl::new(), |_, _| {}).unwrap())
    };
    assert_eq!(on(1).designs, on(2).designs);
}

/// The spread over orbit phases (twelve seasons' looks) stops when its run is cancelled, as
/// the app's Stop does; uncancelled, it samples every phase.
#[test]
fn the_phase_spread_stops_when_cancelled() {
    let season = spring(0);
    let (_, ds) = designs(&season, None).unwrap();
    let period = season.period_days().unwrap();
    let stopped = RunControl::new();
    stopped.cancel();
    assert!(matches!(phase_spread(&season, &ds, period, &stopped), Err(shoal::study::StudyError::Cancelled)));
    let spread = phase_spread(&season, &ds, period, &RunControl::new()).unwrap();
    assert_eq!(spread.len(), ds.len());
    assert!(spread.iter().all(|d| d.len() == shoal::season::run::PHASE_SAMPLES), "{spread:?}");
}

/// `line` (68 characters) with its modulo-10 checksum.
fn with_checksum(line: &str) -> String {
    let sum: u32 = line.chars().map(|c| if c == '-' { 1 } else { c.to_digit(10).unwrap_or(0) }).sum();
    format!("{line}{}", sum % 10)
}

/// A Landsat-8-like element set (705 km, 98.2°, no drag) with its epoch on 2023-04-10.
fn element_set() -> (String, String) {
    (
        with_checksum("1 39084U 13008A   23100.00000000  .00000000  00000-0  00000-0 0  999"),
        with_checksum("2 39084  98.2000 100.0000 0001000  90.0000 270.0000 14.57107000 5000"),
    )
}

/// Every design flies the element set: its looks are the SGP4 orbit's passes over the site (found
/// here again through `shoal::orbit`), each run at the spacecraft's altitude at the pass, the
/// same for both designs whatever their own altitude.
#[test]
fn a_season_on_two_line_elements_flies_the_spacecraft() {
    let mut season = spring(0);
    (season.from, season.to) = ("2023-04-01".into(), "2023-04-30".into());
    season.orbit.tle = Some(element_set());
    season.validate().unwrap();
    let (study, ds) = designs(&season, None).unwrap();
    let result = run_season(&season, &study, &ds, Shard::ALL, &RunControl::new(), |_, _| {}).unwrap();
    let tle = shoal::orbit::TleOrbit::from_lines(&element_set().0, &element_set().1).unwrap();
    let site = Site::from_degrees(season.site.0, season.site.1);
    let (from, to) = season.period_days().unwrap();
    let times: Vec<Vec<f64>> = result.designs.iter().map(|d| d.looks.iter().map(|l| l.access.days).collect()).collect();
    assert!(!times[0].is_empty(), "no pass of the element set over the site in April");
    for (d, (_, config)) in result.designs.iter().zip(&ds) {
        let reach = season.max_roll_deg.to_radians() + half_field_of_view_rad(&config.instrument);
        let passes = accesses(&tle, &site, from, to, reach);
        let want: Vec<f64> = passes.iter().map(|a| a.days).collect();
        let got: Vec<f64> = d.looks.iter().map(|l| l.access.days).collect();
        assert_eq!(got, want, "{}", config.instrument.name);
        for look in &d.looks {
            let h = look.altitude_m.expect("a look on elements has the spacecraft's altitude");
            assert!((h - 705e3).abs() < 20e3, "{h}");
            let run = look_config(config, look, 16);
            assert_eq!(run.instrument.altitude_km, h / 1e3);
        }
    }
    // One spacecraft: where the designs' fields of view are alike, so are their passes.
    assert_eq!(times[0].first(), times[1].first());
}

#[test]
fn element_sets_far_from_the_period_or_malformed_are_refused() {
    let mut season = spring(0);
    season.orbit.tle = Some(element_set());
    // The spring season runs to the end of June, 81 days after the epoch.
    let e = season.validate().unwrap_err();
    assert!(e.field == "orbit.tle" && e.message.contains("2023-04-10") && e.message.contains("30"), "{e}");
    season.to = "2023-04-20".into();
    season.orbit.tle = Some((element_set().0.replace("23100.", "23101."), element_set().1));
    let e = season.validate().unwrap_err();
    assert!(e.field == "orbit.tle" && e.message.contains("checksum"), "{e}");
}

/// A season whose looks would spend longer in radiative transfer than the machine's budget is
/// refused before any run, naming `max_runs` and the budget; within the budget it runs.
#[test]
fn a_season_past_the_time_budget_is_refused_before_it_runs() {
    let dir = std::env::temp_dir().join(format!("shoal-season-budget-{}", std::process::id()));
    let run = |budget: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_shoal"))
            .args(["season", "lake_hume_year", "--max-runs", "400", "--decimation", "16", "--no-figures", "--out"])
            .arg(&dir)
            .env("SHOAL_TIME_BUDGET_S", budget)
            .output()
            .unwrap()
    };
    let started = std::time::Instant::now();
    let out = run("30");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("max_runs") && stderr.contains("SHOAL_TIME_BUDGET_S"), "{stderr}");
    // Refused from the plan, not after running looks (a year's looks take minutes).
    assert!(started.elapsed().as_secs_f64() < 60.0, "{:?}", started.elapsed());
    assert!(!dir.join("looks.csv").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A processor's wind error drawn per look: the looks, their covers and verdicts as without
/// one; the errors spread as asked (RMS within 20 % of 2 m/s over a year's passes, a sampling
/// bound for ~100 draws); and a look's run corrects with its error.
#[test]
fn a_look_s_processor_wind_error_is_drawn_from_its_weather() {
    let mut season = SeasonSpec::preset("lake_hume_year").unwrap();
    season.max_runs = 0;
    let (study, ds) = designs(&season, None).unwrap();
    let exact = run_season(&season, &study, &ds[..1], Shard::ALL, &RunControl::new(), |_, _| {}).unwrap();
    season.processor_wind_rms_m_s = 2.0;
    let wrong = run_season(&season, &study, &ds[..1], Shard::ALL, &RunControl::new(), |_, _| {}).unwrap();
    let (a, b) = (&exact.designs[0].looks, &wrong.designs[0].looks);
    assert_eq!(a.len(), b.len());
    assert!(a.iter().zip(b).all(|(x, y)| x.cloud_cover == y.cloud_cover && x.verdict == y.verdict));
    assert!(a.iter().all(|l| l.processor_wind_error_m_s == 0.0));
    let rms = (b.iter().map(|l| l.processor_wind_error_m_s.powi(2)).sum::<f64>() / b.len() as f64).sqrt();
    println!("{} looks, wind error RMS {rms:.2} m/s", b.len());
    assert!(b.len() >= 80 && (rms / 2.0 - 1.0).abs() < 0.2, "{} looks, RMS {rms}", b.len());
    let look = b.iter().find(|l| l.processor_wind_error_m_s != 0.0).unwrap();
    let config = look_config(&ds[0].1, look, 16);
    let shoal::correction::Method::Image(image) = &config.correction.method else { panic!("an image correction") };
    assert_eq!(image.glint_wind_error_m_s, look.processor_wind_error_m_s);
    // With the exact correction, the look's error is the exact correction's own.
    let mut exact = ds[0].1.clone();
    exact.correction.method = shoal::correction::Method::Exact;
    let config = look_config(&exact, look, 16);
    assert_eq!(config.correction.method, shoal::correction::Method::Exact);
    assert_eq!(config.correction.glint_wind_error_m_s, look.processor_wind_error_m_s);
    // It masks high glint at the season's threshold, as the look was judged.
    assert_eq!(config.correction.glint_threshold_per_sr, Some(look.glint_threshold_per_sr));
    config.validate().unwrap();
    season.processor_wind_rms_m_s = 11.0;
    assert!(season.validate().unwrap_err().to_string().contains("processor_wind_rms_m_s"));
}
