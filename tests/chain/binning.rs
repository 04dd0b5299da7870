//! On-board binning through the chain (`instrument::effects::binning`): the engine simulates
//! the instrument as flown, and SNR, GSD and the data budget follow.

use crate::common::Kept;

use shoal::engine::RunConfig;
use shoal::instrument::InstrumentEffect;
use shoal::instrument::budgets::BudgetModels;
use shoal::instrument::effects::Binning;

use super::{on_one_and_two_threads, run, small, small_lake};

fn config(binning: Option<Binning>) -> RunConfig {
    let mut instrument = small("cubesat", 96, 64);
    instrument.effects = binning.map(InstrumentEffect::Binning).into_iter().collect();
    RunConfig::new(small_lake(), instrument)
}

#[test]
fn a_binned_run_is_the_instrument_as_flown() {
    let binning = Binning { factor: 2, spectral: 1, digital: false };
    let binned = run(&config(Some(binning)));
    // The same run as the flown instrument stated by hand: the same bits.
    let mut by_hand = config(None);
    by_hand.instrument = binning.flown(&by_hand.instrument);
    let flown = run(&by_hand);
    assert_eq!(binned.kept().level1.radiance, flown.kept().level1.radiance);
    // Half the pixels each way, each twice the GSD.
    let native = run(&config(None));
    let (r0, c0, _) = native.kept().level1.radiance.dim();
    let (r1, c1, _) = binned.kept().level1.radiance.dim();
    assert_eq!((r1, c1), (r0 / 2, c0 / 2));
    assert!((binned.config.instrument.gsd_m() / native.config.instrument.gsd_m() - 2.0).abs() < 1e-12);
    // The SNR at the scene's typical radiance: 2 × 2 in charge gains from 2 (shot-limited)
    // towards 4 (read-limited: four pixels' signal, one read), less the coarser rounding.
    for (a, b) in binned.snr.iter().zip(native.snr.iter()) {
        let gain = a.snr_analytic / b.snr_analytic;
        eprintln!("{}: SNR {:.0} → {:.0} (× {gain:.2})", a.band, b.snr_analytic, a.snr_analytic);
        assert!((1.5..=4.0).contains(&gain), "{}: {gain}", a.band);
    }
    // The data a day fall by k² (the same bits per sample).
    let models = BudgetModels::preset("cubesat_class").unwrap();
    let data = |c: &RunConfig, out: &shoal::engine::RunOutput| {
        models.assess(&c.instrument.as_flown(), &out.response.plane_of_band).data.daily_gbit
    };
    let ratio = data(&config(Some(binning)), &binned) / data(&config(None), &native);
    assert!((ratio - 0.25).abs() < 0.02, "{ratio}");
}

#[test]
fn binning_does_not_depend_on_threads() {
    let c = config(Some(Binning { factor: 3, spectral: 1, digital: true }));
    let (one, two) = on_one_and_two_threads(&c);
    assert_eq!(one.kept().level0.dn, two.kept().level0.dn);
    assert_eq!(one.kept().level1.radiance, two.kept().level1.radiance);
}

#[test]
fn a_binning_the_array_cannot_make_is_refused_by_name() {
    let mut c = config(Some(Binning { factor: 16, spectral: 1, digital: false }));
    c.instrument.detectors = 10;
    let e = c.validate().unwrap_err().to_string();
    assert!(e.contains("Binning.factor") && e.contains("10 detectors"), "{e}");
    let c = config(Some(Binning { factor: 40, spectral: 1, digital: false }));
    let e = c.validate().unwrap_err().to_string();
    assert!(e.contains("Binning.factor") && e.contains("16"), "{e}");
}

#[test]
fn a_spectrograph_binned_spectrally_runs_with_half_the_bands() {
    let mut instrument = small("hyperspectral", 48, 32);
    instrument.effects = vec![InstrumentEffect::Binning(Binning { factor: 1, spectral: 2, digital: true })];
    let binned = run(&RunConfig::new(small_lake(), instrument));
    let native = run(&RunConfig::new(small_lake(), small("hyperspectral", 48, 32)));
    let (nb, bb) = (native.kept().level1.radiance.dim().2, binned.kept().level1.radiance.dim().2);
    assert_eq!(bb, nb / 2);
    // Two samples' light in each band, with two reads: the SNR at the scene's typical radiance
    // gains between √2 (read noise negligible) and 2 (read-limited: twice the signal, √2 the
    // read noise), band by band against the two samples it sums.
    for (i, row) in binned.snr.iter().enumerate() {
        let pair = (native.snr[2 * i].snr_analytic + native.snr[2 * i + 1].snr_analytic) / 2.0;
        let gain = row.snr_analytic / pair;
        assert!((1.3..=2.1).contains(&gain), "{}: {gain}", row.band);
    }
}
