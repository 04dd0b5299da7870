//! The band model at every vector level: the levels with FMA (AVX2, AVX-512) give the same bits,
//! as a level only changes how many nodes an instruction takes (and the padding of the node
//! vectors to the widest level's width is never summed); the baseline, whose multiply-adds round
//! twice, agrees to rounding.

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
fn the_fused_levels_agree_to_the_bit_and_the_baseline_to_rounding() {
    let inv_cos = (1.0 / 0.93, 1.0 / 0.98);
    let mut worst = (0.0f64, 0.0f64);
    for model in models() {
        let nb = model.n_bands();
        for depth_m in [None, Some(0.7), Some(6.0)] {
            let p = Parameters { chl: 0.6, cdom: 0.03, nap: 1.4, depth_m, substrates: (0, 2, 0.35) };
            let at = |tier: Tier| {
                capped(tier, || {
                    let (mut rrs, mut jacobian, mut plain) = (vec![0.0; nb], vec![[0.0; 5]; nb], vec![0.0; nb]);
                    model.evaluate(&p, inv_cos, &mut rrs, Some(&mut jacobian));
                    model.evaluate(&p, inv_cos, &mut plain, None);
                    (rrs, jacobian, plain)
                })
            };
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let widest = at(Tier::Avx512);
            assert!(widest.0.iter().all(|&v| v > 0.0), "{nb} bands, depth {depth_m:?}");
            // AVX2 and AVX-512 fuse the same multiply-adds: the same operations per node.
            let avx2 = at(Tier::Avx2);
            assert_eq!(bits(&avx2.0), bits(&widest.0), "{nb} bands, depth {depth_m:?}");
            assert_eq!(bits(&avx2.1.concat()), bits(&widest.1.concat()), "{nb} bands, depth {depth_m:?}");
            assert_eq!(bits(&avx2.2), bits(&widest.2), "{nb} bands, depth {depth_m:?}");
            // Without FMA each fused multiply-add rounds twice.
            let base = at(Tier::Baseline);
            for b in 0..nb {
                let rel = |x: f64, y: f64| (x - y).abs() / y.abs();
                worst.0 = worst.0.max(rel(base.0[b], widest.0[b])).max(rel(base.2[b], widest.2[b]));
                // A Jacobian entry can be a difference of near-equal terms: relative to the
                // band's largest entry.
                let scale = widest.1[b].iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for k in 0..5 {
                    worst.1 = worst.1.max((base.1[b][k] - widest.1[b][k]).abs() / scale);
                }
            }
        }
    }
    // A fused multiply-add differs from the two roundings by at most one rounding of its
    // product; a node's Rrs passes through about twenty of them, its exponentials included
    // (measured: 3.6·10⁻¹⁶ on Rrs, 4.9·10⁻¹⁶ on the Jacobian). 4·10⁻¹⁵ is twenty such
    // roundings (2⁻⁵² each), well short of what a wrong term would move.
    assert!(worst.0 < 4e-15, "Rrs: baseline against fused {:.2e}", worst.0);
    assert!(worst.1 < 4e-15, "Jacobian: baseline against fused {:.2e}", worst.1);
}
