//! QAA v6 in the chain: a study retrieval like any other — every water pixel returned or
//! failed, never both; returned values finite and positive; its IOPs written beside its chl;
//! one and two threads bit-identical; and an instrument without the bands it reads refused by
//! name, never a panic. (Its arithmetic against the IOCCG spreadsheet: tests/physics/qaa.rs.)

use shoal::control::RunControl;
use shoal::engine::{Engine, RunConfig, RunOutput};
use shoal::retrieval::qaa::QaaSettings;
use shoal::retrieval::{ProductFlags, RetrievalSpec};

use super::{small, small_lake};

fn config() -> RunConfig {
    let mut c = RunConfig::new(small_lake(), small("cubesat", 48, 32));
    c.retrievals = vec![RetrievalSpec::Qaa { settings: QaaSettings::default() }];
    c
}

fn run_on(threads: usize, config: &RunConfig) -> RunOutput {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| Engine::new().run(config, &RunControl::new()).unwrap())
}

#[test]
fn qaa_returns_chl_and_its_iops_on_every_pixel_it_can_and_flags_the_rest() {
    let c = config();
    let (one, two) = (run_on(1, &c), run_on(2, &c));
    let p = &one.retrievals[0].product;
    assert_eq!(p.name, "QAA v6");
    let chl = p.chl_mg_m3.as_ref().unwrap();
    let keys: Vec<&str> = p.extras.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(keys, ["adg443_per_m", "aph443_per_m", "bbp555_per_m"]);
    let land = &one.truth.surface.codes();
    let mut returned = 0;
    for ((r, col), f) in p.flags.indexed_iter() {
        if land[[r, col]] != 0 {
            assert_eq!(*f, ProductFlags::LAND);
            continue;
        }
        assert!((f & ProductFlags::FAILED != 0) != (f & ProductFlags::RETURNED != 0), "({r}, {col}): {f}");
        if p.returned(r, col) {
            returned += 1;
            assert!(chl[[r, col]].is_finite() && chl[[r, col]] > 0.0);
            for (_, m) in &p.extras {
                assert!(m[[r, col]].is_finite() && m[[r, col]] > 0.0, "an IOP of ({r}, {col}) is {}", m[[r, col]]);
            }
        }
    }
    assert!(returned > 0, "QAA returned no pixel of the lake");
    let metrics = one.retrievals[0].metrics.get("chl_mg_m3").unwrap();
    assert_eq!(metrics.n, returned, "the metrics score the returned pixels");
    assert!(metrics.mae_pct().is_finite());
    // Its IOPs are scored against the ones the scene's SIOP set gives the true concentrations.
    for key in ["adg443_per_m", "aph443_per_m", "bbp555_per_m"] {
        let m = one.retrievals[0].metrics.get(key).unwrap_or_else(|| panic!("{key} not scored"));
        assert_eq!(m.n, returned, "{key}");
        assert!(m.mae_pct().is_finite() && m.bias_pct().is_finite(), "{key}: {m:?}");
    }
    // Determinism: the same bits on one and two threads.
    let q = &two.retrievals[0].product;
    let bits = |p: &shoal::retrieval::Product| -> Vec<u32> {
        p.maps().iter().flat_map(|(_, m)| m.iter().map(|v| v.to_bits())).collect()
    };
    assert_eq!(bits(p), bits(q));
    assert_eq!(p.flags, q.flags);
}

#[test]
fn an_instrument_without_the_bands_qaa_reads_is_refused_by_name() {
    let mut c = config();
    // Sentinel-2 MSI has no band within 15 nm of 412 nm (its first is at 443 nm).
    c.instrument = shoal::instrument::InstrumentSpec::preset("sentinel2a_msi").unwrap();
    c.instrument.detectors = 32;
    c.instrument.lines = 32;
    let e = Engine::new().run(&c, &RunControl::new()).unwrap_err().to_string();
    assert!(e.contains("412 nm") && e.contains("QAA needs a band"), "{e}");
}
