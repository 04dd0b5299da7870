//! What a cached product holds in memory: the stage cache keeps products within a byte budget
//! ([`super::Engine::with_cache_budget`]), counting the ones that grow with the image (cubes,
//! maps, products). A product that stays small whatever the image (a table, coefficients, a
//! LUT of a few hundred kilobytes) counts 0 and is bounded by its stage's capacity instead.

use ndarray::{ArrayBase, Data, Dimension};

use super::products::{Corrected, RetrievalOutput};
use crate::calibration::{Calibration, Level1};
use crate::instrument::feasibility::Feasibility;
use crate::instrument::sample::BandAtmosphere;
use crate::instrument::{AotNodes, Detector, Level0, RadianceCube, Response, SnrRow, Truth, Viewing};
use crate::retrieval::Product;
use crate::scene::Scene;
use crate::toa::SceneOptics;

/// Bytes a product holds (its large buffers; the struct itself and small fields are left out).
pub trait Footprint {
    /// Bytes held; 0 for a product that does not grow with the image.
    fn bytes(&self) -> usize {
        0
    }
}

/// Bytes of an array's elements.
pub(crate) fn array_bytes<S: Data, D: Dimension>(a: &ArrayBase<S, D>) -> usize {
    a.len() * std::mem::size_of::<S::Elem>()
}

fn opt<S: Data, D: Dimension>(a: Option<&ArrayBase<S, D>>) -> usize {
    a.map_or(0, array_bytes)
}

impl Footprint for Scene {
    fn bytes(&self) -> usize {
        self.map_bytes()
    }
}

impl Footprint for Truth {
    fn bytes(&self) -> usize {
        array_bytes(&self.chl_mg_m3)
            + array_bytes(&self.nap_g_m3)
            + array_bytes(&self.cdom_per_m)
            + opt(self.depth_m.as_ref())
            + opt(self.substrate_fractions.as_ref())
            + opt(self.aot550.as_ref())
            + self.surface.codes().len()
    }
}

impl Footprint for RadianceCube {
    fn bytes(&self) -> usize {
        array_bytes(&self.radiance) + array_bytes(&*self.truth_rrs) + self.truth.bytes()
    }
}

/// Electrons per pixel.
impl Footprint for ndarray::Array3<f32> {
    fn bytes(&self) -> usize {
        array_bytes(self)
    }
}

impl Footprint for Level0 {
    fn bytes(&self) -> usize {
        array_bytes(&self.dn) + opt(self.analog.as_ref()) + array_bytes(&self.flags)
    }
}

impl Footprint for Level1 {
    fn bytes(&self) -> usize {
        array_bytes(&self.radiance) + array_bytes(&self.flags)
    }
}

impl Footprint for Corrected {
    fn bytes(&self) -> usize {
        let aerosol = self.product.aerosol.as_ref().map_or(0, |a| array_bytes(&a.aot550) + array_bytes(&a.angstrom));
        array_bytes(&self.rrs.rrs) + array_bytes(&self.rrs.flags) + aerosol
    }
}

impl Footprint for Product {
    fn bytes(&self) -> usize {
        opt(self.chl_mg_m3.as_ref())
            + opt(self.cdom_per_m.as_ref())
            + opt(self.nap_g_m3.as_ref())
            + opt(self.depth_m.as_ref())
            + opt(self.substrate_fractions.as_ref())
            + opt(self.siop_set.as_ref())
            + array_bytes(&self.cost)
            + opt(self.sdi.as_ref())
            + opt(self.iterations.as_ref())
            + self.extras.iter().map(|(_, m)| array_bytes(m)).sum::<usize>()
            + array_bytes(&self.flags)
    }
}

impl Footprint for RetrievalOutput {
    fn bytes(&self) -> usize {
        self.product.bytes() + self.extra_truths.iter().map(|(_, m)| array_bytes(m)).sum::<usize>()
    }
}

// Products that do not grow with the image.
impl Footprint for Response {}
impl Footprint for Viewing {}
impl Footprint for crate::atmosphere::AtmosphereLut {}
impl Footprint for Vec<SceneOptics> {}
impl Footprint for BandAtmosphere {}
impl Footprint for AotNodes {}
impl Footprint for (f64, f64) {}
impl Footprint for Detector {}
impl Footprint for Feasibility {}
impl Footprint for Calibration {}
impl Footprint for crate::correction::FamilyLuts {}
impl Footprint for crate::correction::AerosolFamily {}
impl Footprint for Vec<SnrRow> {}
impl Footprint for crate::retrieval::Model {}
