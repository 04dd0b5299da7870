//! Tests of [`super`]: the lanes against the scalar `almi::invert`, bit for bit.

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

use super::*;
use crate::retrieval::almi::invert;
use crate::retrieval::band_model::BandIops;

/// `n` sets of six bands with IOPs scattered around plausible values.
fn sets(n: usize, rng: &mut Xoshiro256PlusPlus) -> Vec<AlmiSet> {
    let base = BandIops {
        a_w: vec![0.007, 0.015, 0.062, 0.43, 0.80, 2.1],
        bb_w: vec![0.0024, 0.0016, 0.0010, 0.0005, 0.0004, 0.0003],
        a_ph: vec![0.060, 0.040, 0.015, 0.018, 0.004, 0.001],
        a_cdom: vec![1.0, 0.45, 0.14, 0.028, 0.012, 0.004],
        a_nap: vec![0.045, 0.030, 0.014, 0.005, 0.003, 0.002],
        bb_ph: vec![0.0011, 0.0010, 0.0009, 0.0008, 0.0007, 0.0006],
        bb_nap: vec![0.0095, 0.0087, 0.0079, 0.0066, 0.0062, 0.0058],
    };
    (0..n)
        .map(|i| {
            let mut f = || rng.random_range(0.5..2.0);
            let mut o = base.clone();
            for v in [&mut o.a_ph, &mut o.a_cdom, &mut o.a_nap, &mut o.bb_ph, &mut o.bb_nap] {
                let scale = f();
                v.iter_mut().for_each(|x| *x *= scale);
            }
            AlmiSet { name: format!("set {i}"), iops: o }
        })
        .collect()
}

#[test]
fn packed_lanes_give_the_scalar_pixels_bit_for_bit() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    // 8 sets (one full chunk), 11 (a partial second chunk) and 3 (a partial first one).
    for n_sets in [8, 11, 3] {
        let sets = sets(n_sets, &mut rng);
        let packed = PackedSets::new(&sets);
        let mut scratch = Scratch::default();
        // Pixels whose chosen set ended on a bound: the enumeration of supports was used.
        let mut bounded = 0;
        for weighting in [true, false] {
            let settings = AlmiSettings { noise_weighting: weighting, ..AlmiSettings::default() };
            for _ in 0..500 {
                let rrs: Vec<f64> = (0..6).map(|k| rng.random_range(0.0005..0.02) / (1.0 + k as f64)).collect();
                let mut valid = vec![true; 6];
                // Now and then a band left out, or a pixel with too few bands.
                if rng.random_range(0.0..1.0) < 0.2 {
                    valid[rng.random_range(0..6)] = false;
                }
                let nedr: Vec<f64> = rrs.iter().map(|v| 0.02 * v).collect();
                let a = invert(&sets, &settings, &rrs, &valid, &nedr);
                let b = invert_packed(&mut scratch, &packed, &settings, &rrs, &valid, &nedr);
                // The portable build too, where the CPU would have taken the AVX2 one.
                let c = invert_lanes(&mut scratch, &packed, &settings, &rrs, &valid, &nedr);
                assert_eq!(format!("{b:?}"), format!("{c:?}"), "AVX2 and portable builds differ");
                assert_eq!(a.set, b.set, "{n_sets} sets: chosen set");
                assert_eq!(a.flags, b.flags);
                bounded += usize::from(a.flags & AlmiFlags::AT_BOUND != 0);
                for (x, y) in [(a.chl, b.chl), (a.cdom, b.cdom), (a.nap, b.nap), (a.cost, b.cost)] {
                    assert_eq!(x.to_bits(), y.to_bits(), "{n_sets} sets: {a:?} vs {b:?}");
                }
            }
        }
        assert!(
            bounded > 500,
            "{n_sets} sets: only {bounded} of 1000 pixels on a bound (the enumeration of supports barely tested)"
        );
    }
}
