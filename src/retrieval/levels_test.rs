//! The band model gives the same bits at every vector level: its node loop is written with
//! separate multiplies and adds, so a level only changes how many nodes an instruction takes
//! (and the padding of the node vectors to the widest level's width is never summed).

use super::band_model::{BandModel, BandResponse, Parameters};
use crate::simd::{Tier, capped};
use crate::water::{SiopSpec, SubstrateLibrary};

/// The bench's 28-band case (3 Gauss nodes a band, 84 nodes) and a 4-band one (12 nodes),
/// with a node count that is no multiple of 8 (5 bands × 3).
fn models() -> Vec<BandModel> {
    let spec = SiopSpec::preset("heron_island").unwrap();
    let lib = SubstrateLibrary::embedded().unwrap();
    [28, 4, 5]
        .into_iter()
        .map(|n: u32| {
            let bands: Vec<BandResponse> = (0..n)
                .map(|b| {
                    let c = 420.0 + 300.0 * f64::from(b) / f64::from(n);
                    let x: Vec<f64> = (0..21).map(|i| c - 10.0 + f64::from(i)).collect();
                    let w = x.iter().map(|x| (-0.5 * ((x - c) / 3.0).powi(2)).exp()).collect();
                    BandResponse { name: format!("B{b}"), wavelengths_nm: x, weights: w }
                })
                .collect();
            BandModel::new(&spec, None, &lib, &["sand".into(), "acropora".into(), "turf_algae".into()], &bands, 3)
                .unwrap()
        })
        .collect()
}

#[test]
fn every_level_gives_the_band_model_the_same_bits() {
    let inv_cos = (1.0 / 0.93, 1.0 / 0.98);
    for model in models() {
        let nb = model.n_bands();
        for depth_m in [None, Some(0.7), Some(6.0)] {
            let p = Parameters { chl: 0.6, cdom: 0.03, nap: 1.4, depth_m, substrates: (0, 2, 0.35) };
            let at = |tier: Tier| {
                capped(tier, || {
                    let (mut rrs, mut jacobian, mut plain) = (vec![0.0; nb], vec![[0.0; 5]; nb], vec![0.0; nb]);
                    model.evaluate(&p, inv_cos, &mut rrs, Some(&mut jacobian));
                    model.evaluate(&p, inv_cos, &mut plain, None);
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    (bits(&rrs), bits(&jacobian.concat()), bits(&plain))
                })
            };
            let widest = at(Tier::Avx512);
            assert!(widest.0.iter().all(|&b| f64::from_bits(b) > 0.0), "{nb} bands, depth {depth_m:?}");
            for tier in [Tier::Avx2, Tier::Baseline] {
                assert_eq!(at(tier), widest, "{nb} bands, depth {depth_m:?}, {tier:?}");
            }
        }
    }
}
