//! Determinism: 1 and 2 threads give bit-identical results; a preview sees exactly the noise of
//! the same pixels at full resolution.

use crate::common::Kept;
use shoal::control::RunControl;
use shoal::engine::{Engine, RunConfig, RunOutput};

use super::{reef, small, small_lake};

fn run_on(threads: usize, config: &RunConfig) -> RunOutput {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| Engine::new().run(config, &RunControl::new()).unwrap())
}

#[test]
fn one_and_two_threads_give_identical_products() {
    for (scene, instrument) in [(small_lake(), "cubesat"), (reef(), "nominal")] {
        let mut config = RunConfig::new(scene, small(instrument, 80, 40));
        config.instrument.prnu = 0.01;
        config.instrument.dsnu_e = 5.0;
        config.instrument.dark_current_e_s = 1000.0;
        let (a, b) = (run_on(1, &config), run_on(2, &config));
        assert_eq!(a.kept().level0.dn, b.kept().level0.dn);
        assert_eq!(a.kept().level0.flags, b.kept().level0.flags);
        let bits = |x: &ndarray::Array3<f32>| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.kept().level1.radiance), bits(&b.kept().level1.radiance));
        assert_eq!(bits(&a.kept().rrs.rrs), bits(&b.kept().rrs.rrs));
        assert_eq!(bits(&a.kept().radiance.radiance), bits(&b.kept().radiance.radiance));
        let snr = |o: &RunOutput| o.snr.iter().map(|r| r.snr_measured.to_bits()).collect::<Vec<_>>();
        assert_eq!(snr(&a), snr(&b));
    }
}

#[test]
fn a_preview_sees_the_same_pixels_as_full_resolution() {
    let mut config = RunConfig::new(small_lake(), small("nominal", 64, 64));
    let full = Engine::new().run(&config, &RunControl::new()).unwrap();
    config.fidelity.decimation = 4;
    let preview = Engine::new().run(&config, &RunControl::new()).unwrap();
    let (rows, cols, nb) = preview.kept().level0.dn.dim();
    assert_eq!((rows, cols), (16, 16));
    for r in 0..rows {
        for c in 0..cols {
            for b in 0..nb {
                let (fr, fc) = (preview.viewing.line_index[r], preview.viewing.detector_index[c]);
                assert_eq!(preview.kept().level0.dn[[r, c, b]], full.kept().level0.dn[[fr, fc, b]], "({r},{c},{b})");
                assert_eq!(preview.kept().level1.radiance[[r, c, b]], full.kept().level1.radiance[[fr, fc, b]]);
            }
        }
    }
}
