//! The molecular (Rayleigh) scattering kernels of a solar solve, computed once and shared by
//! every solve with the same streams, sun and surface.
//!
//! A solve's Rayleigh kernels — the scalar phase-function kernel of each Fourier term and the
//! (I, Q, U) kernels of the polarisation correction (`kernels::vector_rayleigh_kernels`) — are
//! functions of the quadrature streams, the view cosines, the sun's cosine, the air's
//! depolarisation and the water's refractive index only: not of the wavelength's optical depths
//! or its aerosol. A LUT solves every wavelength at each sun node, and the image-based
//! correction's family builds sixteen LUTs on the same nodes; computed per solve, the vector
//! kernels alone (16 azimuth steps of the Rayleigh phase matrix, with its rotations, for every
//! pair of directions) took a quarter of `shoal correct`'s time in perf. The values are the same
//! function of the same inputs whichever solve computes them first, so sharing them changes no
//! result.
//!
//! The same holds for an aerosol's phase-function moments ([`phase_moments`]): a function of
//! its table alone, which every solve of a wavelength expands (per sun node of a LUT, and again
//! for the transmittances), as does each of the family's five atmospheres per aerosol model,
//! whose tables differ only in optical depth, not in phase function.

use std::collections::HashMap;
use std::sync::{Arc, LazyLock, Mutex, OnceLock, PoisonError};

use super::kernels::{scalar_kernel, vector_rayleigh_kernels};
use super::phase::PhaseFunction;
use super::sos::{Kernel, Streams};

/// The most kernel sets held (about 0.6 MB each at 12 streams and 19 view cosines; a LUT has
/// a few sun nodes, so this holds every node of a family's builds). When full, the cache is
/// emptied and refilled: a later solve recomputes what it needs.
const MAX_SETS: usize = 32;

/// The Rayleigh kernels of one (streams, view cosines, sun, depolarisation, water index), each
/// computed the first time a solve asks for it.
pub(super) struct RayleighKernels {
    mu0: f64,
    depolarization: f64,
    water_index: f64,
    /// The scalar kernel of Fourier term m.
    scalar: Vec<OnceLock<Kernel<1>>>,
    /// The (I, Q, U) kernels for m = 0, 1, 2.
    vector: OnceLock<Vec<Kernel<3>>>,
}

impl RayleighKernels {
    /// The scalar kernel of Fourier term `m` ([`scalar_kernel`] with the Rayleigh moments).
    pub fn scalar(&self, streams: &Streams, m: usize) -> std::borrow::Cow<'_, Kernel<1>> {
        let compute = || {
            let beta = PhaseFunction::Rayleigh { depolarization: self.depolarization }.moments(2);
            scalar_kernel(streams, &beta, m, self.mu0, self.water_index)
        };
        match self.scalar.get(m) {
            Some(cell) => std::borrow::Cow::Borrowed(cell.get_or_init(compute)),
            None => std::borrow::Cow::Owned(compute()),
        }
    }

    /// The (I, Q, U) kernels for m = 0, 1, 2 ([`vector_rayleigh_kernels`]).
    pub fn vector(&self, streams: &Streams) -> &[Kernel<3>] {
        self.vector.get_or_init(|| vector_rayleigh_kernels(streams, self.depolarization, self.mu0, self.water_index))
    }
}

/// What the kernels depend on, bit for bit.
#[derive(PartialEq, Eq, Hash)]
struct Key {
    streams: usize,
    user_mu: Vec<u64>,
    mu0: u64,
    depolarization: u64,
    water_index: u64,
}

static CACHE: LazyLock<Mutex<HashMap<Key, Arc<RayleighKernels>>>> = LazyLock::new(Mutex::default);

/// The shared Rayleigh kernels for `streams`, sun cosine `mu0`, depolarisation ratio and water
/// refractive index. Every Fourier term a solve with these streams can ask for has its cell
/// (m < 2n: `solve_sun` stops at `min(fourier_terms, 2n) − 1`), whichever solve comes first: a
/// Rayleigh atmosphere's solve (three terms) makes the set the aerosol solves after it fill.
pub(super) fn rayleigh_kernels(
    streams: &Streams,
    mu0: f64,
    depolarization: f64,
    water_index: f64,
) -> Arc<RayleighKernels> {
    let key = Key {
        streams: streams.n(),
        user_mu: streams.user_mu.iter().map(|m| m.to_bits()).collect(),
        mu0: mu0.to_bits(),
        depolarization: depolarization.to_bits(),
        water_index: water_index.to_bits(),
    };
    let mut cache = CACHE.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(found) = cache.get(&key) {
        return found.clone();
    }
    if cache.len() >= MAX_SETS {
        cache.clear();
    }
    let kernels = Arc::new(RayleighKernels {
        mu0,
        depolarization,
        water_index,
        scalar: (0..(2 * streams.n()).max(3)).map(|_| OnceLock::new()).collect(),
        vector: OnceLock::new(),
    });
    cache.insert(key, kernels.clone());
    kernels
}

/// The most phase expansions held. An entry keeps its table's bits (the built-in tables' 128
/// angles: 2 kB), so the cache stays under a few MB; the built-in models at a LUT's wavelengths
/// take some tens of entries. When full, the cache is emptied and refilled.
const MAX_EXPANSIONS: usize = 1024;

/// A phase function's table and the expansion's order, bit for bit.
type MomentsKey = (usize, Vec<u64>);

static MOMENTS: LazyLock<Mutex<HashMap<MomentsKey, Arc<[f64]>>>> = LazyLock::new(Mutex::default);

/// [`PhaseFunction::moments`] of `phase` to order `l_max`, expanded once per table and order
/// (the Rayleigh function's, analytic, are not kept).
pub(super) fn phase_moments(phase: &PhaseFunction, l_max: usize) -> Arc<[f64]> {
    let PhaseFunction::Tabulated { angles_rad, ln_values } = phase else {
        return phase.moments(l_max).into();
    };
    let key: MomentsKey = (l_max, angles_rad.iter().chain(ln_values).map(|v| v.to_bits()).collect());
    if let Some(found) = MOMENTS.lock().unwrap_or_else(PoisonError::into_inner).get(&key) {
        return found.clone();
    }
    // Expanded outside the lock, so that solves of other tables do not wait on it.
    let beta: Arc<[f64]> = phase.moments(l_max).into();
    let mut cache = MOMENTS.lock().unwrap_or_else(PoisonError::into_inner);
    if cache.len() >= MAX_EXPANSIONS {
        cache.clear();
    }
    cache.insert(key, beta.clone());
    beta
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_kernels_equal_fresh_ones_bit_for_bit() {
        let streams = Streams::new(8, vec![1.0, 0.9, 0.7]);
        let (mu0, rho, n) = (0.6, 0.0279, 1.34);
        let shared = rayleigh_kernels(&streams, mu0, rho, n);
        let again = rayleigh_kernels(&streams, mu0, rho, n);
        assert!(Arc::ptr_eq(&shared, &again), "the same inputs share one set");
        let beta = PhaseFunction::Rayleigh { depolarization: rho }.moments(2);
        for m in [0, 1, 2, 5, 15, 20] {
            assert_eq!(*shared.scalar(&streams, m), scalar_kernel(&streams, &beta, m, mu0, n), "m = {m}");
        }
        // Every term a solve with 8 streams can reach (m ≤ 15) is held, so a later solve reads
        // it; beyond, a kernel is made for the caller alone.
        assert!(matches!(shared.scalar(&streams, 15), std::borrow::Cow::Borrowed(_)));
        assert!(matches!(shared.scalar(&streams, 16), std::borrow::Cow::Owned(_)));
        assert_eq!(shared.vector(&streams), vector_rayleigh_kernels(&streams, rho, mu0, n).as_slice());
        let other = rayleigh_kernels(&streams, 0.5, rho, n);
        assert!(!Arc::ptr_eq(&shared, &other), "another sun, another set");
    }

    #[test]
    fn shared_phase_moments_equal_fresh_ones_bit_for_bit() {
        let phase = PhaseFunction::from_table(&[0.0, 10.0, 45.0, 90.0, 180.0], &[40.0, 8.0, 1.0, 0.3, 0.5]).unwrap();
        let shared = phase_moments(&phase, 24);
        assert!(Arc::ptr_eq(&shared, &phase_moments(&phase, 24)), "the same table and order share one expansion");
        let fresh = phase.moments(24);
        assert!(shared.iter().zip(&fresh).all(|(a, b)| a.to_bits() == b.to_bits()) && shared.len() == fresh.len());
        assert_eq!(phase_moments(&phase, 8).len(), 9, "another order, another expansion");
        let other = PhaseFunction::from_table(&[0.0, 10.0, 45.0, 90.0, 180.0], &[30.0, 8.0, 1.0, 0.3, 0.5]).unwrap();
        assert_ne!(&*phase_moments(&other, 24), &*shared, "another table, its own moments");
        let rayleigh = PhaseFunction::Rayleigh { depolarization: 0.0279 };
        assert_eq!(&*phase_moments(&rayleigh, 4), rayleigh.moments(4).as_slice());
    }
}
