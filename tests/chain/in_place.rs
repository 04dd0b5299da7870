//! A correction handed its Level-1 (`correction::Level1Input::Owned`, what a run that keeps no
//! cubes does) writes the Rrs over it: the same bits as a correction that reads it, for the
//! image-based correction (band pair and dark-spectrum fitting), the exact one and the paper's
//! per-scene approximation. And the approximation's diagnostic against the exact correction made
//! pixel by pixel (what lets either product take the Level-1 after it) equals the one between the
//! two cubes.

use crate::common::Kept;
use shoal::atmosphere::AerosolType;
use shoal::calibration::Level1;
use shoal::control::RunControl;
use shoal::correction::{
    AerosolFit, ExactTerms, ImageCorrection, Level1Input, Method, Reflectance, compare, correct_exact, correct_image,
    no_water, no_water_compared_with_exact,
};
use shoal::engine::RunOutput;
use shoal::instrument::DetectorMode;

use super::image_correction::clear_water;
use super::run;

/// The same Rrs and flags, bit for bit.
fn assert_same(a: &Reflectance, b: &Reflectance, what: &str) {
    assert_eq!(a.flags, b.flags, "{what}: flags");
    assert!(a.rrs.iter().zip(&b.rrs).all(|(x, y)| x.to_bits() == y.to_bits()), "{what}: Rrs");
}

/// The same values, NaN where the other is NaN.
fn same_bits(a: &ndarray::Array2<f32>, b: &ndarray::Array2<f32>) -> bool {
    a.dim() == b.dim() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn an_image_correction_handed_its_level1_gives_the_bits_of_one_reading_it() {
    for fit in [AerosolFit::BandPair, AerosolFit::DarkSpectrum] {
        let mut c = clear_water(AerosolType::Continental, 0.15);
        // Noise on, so that flags and values differ from pixel to pixel.
        c.detector = DetectorMode::default();
        let settings = ImageCorrection { fit, ..ImageCorrection::default() };
        c.correction.method = Method::Image(settings.clone());
        let out = run(&c);
        let family = out.correction.family.clone().expect("the family");
        let (bands, surface, control) = (&out.response.bands, &out.truth.surface, RunControl::new());
        let level1 = (*out.kept().level1).clone();
        let (read, aerosol_read) = correct_image(&level1, &family, &settings, bands, surface, &control).unwrap();
        let handed = Level1Input::Owned(level1.clone());
        let (owned, aerosol_owned) = correct_image(handed, &family, &settings, bands, surface, &control).unwrap();
        let what = format!("{fit:?}");
        assert_same(&read, &owned, &what);
        assert!(same_bits(&aerosol_read.aot550, &aerosol_owned.aot550), "{what}: AOT map");
        assert!(same_bits(&aerosol_read.angstrom, &aerosol_owned.angstrom), "{what}: Ångström map");
        assert_eq!(aerosol_read.outside_family, aerosol_owned.outside_family);
        let bits = |e: (f64, f64, f64)| [e.0.to_bits(), e.1.to_bits(), e.2.to_bits()];
        assert_eq!(bits(aerosol_read.epsilon), bits(aerosol_owned.epsilon));
        // And what the run itself delivered (its Level-1 shared with the kept cubes).
        assert_same(&read, &out.kept().rrs, &format!("{what}, the run's product"));
        assert!(read.flags.iter().any(|f| *f == 0), "{what}: some pixels retrieved");
    }
}

/// The approximation's diagnostic of `out` (a run at full resolution) between the two cubes
/// (`compare`), with both made pixel by pixel, and as the run reported it: the same counts,
/// medians, maxima and (summed in the same fixed blocks) means. Returns the terms of the exact
/// correction and its cube.
fn assert_the_diagnostic_is_the_cubes<'a>(
    out: &'a shoal::engine::RunOutput,
    level1: &'a shoal::calibration::Level1,
) -> (ExactTerms<'a>, Reflectance) {
    let (surface, control) = (&out.truth.surface, RunControl::new());
    let approximation = out.correction.approximation.as_ref().expect("a lake has water");
    let atmosphere = (out.band_atmosphere.as_ref(), None);
    let exact = correct_exact(level1, atmosphere, None, surface, &control).unwrap();
    let approximate = approximation.correct(level1, surface, &control).unwrap();
    let between_cubes = compare(&approximate, &exact.rrs, Some(&exact.flags));
    let (_, cols, nb) = level1.radiance.dim();
    let terms = ExactTerms::new(atmosphere, None, surface, (cols, nb)).unwrap();
    assert_eq!(between_cubes, approximation.compare_with_exact(level1, surface, &terms).unwrap());
    assert_eq!(between_cubes, out.correction.approximation_vs_exact, "the run's diagnostic");
    assert!(between_cubes.iter().all(|d| d.n > 0));
    (terms, exact)
}

/// A noisy run over clear water at full resolution with `method`, and a copy of its Level-1.
fn run_with(method: Method) -> (RunOutput, Level1) {
    let mut c = clear_water(AerosolType::Continental, 0.15);
    c.detector = DetectorMode::default();
    c.correction.method = method;
    let out = run(&c);
    let level1 = (*out.kept().level1).clone();
    (out, level1)
}

#[test]
fn the_exact_correction_handed_its_level1_gives_the_same_bits_and_the_same_diagnostic() {
    let (out, level1) = run_with(Method::Exact);
    let (surface, control) = (&out.truth.surface, RunControl::new());
    let atmosphere = (out.band_atmosphere.as_ref(), None);
    let read = correct_exact(&level1, atmosphere, None, surface, &control).unwrap();
    let owned = correct_exact(Level1Input::Owned(level1.clone()), atmosphere, None, surface, &control).unwrap();
    assert_same(&read, &owned, "exact");
    assert_same(&read, &out.kept().rrs, "exact, the run's product");
    assert_the_diagnostic_is_the_cubes(&out, &level1);
}

#[test]
fn the_per_scene_product_handed_its_level1_gives_the_same_bits_and_the_same_diagnostic() {
    let (out, level1) = run_with(Method::PerScene);
    let (surface, control) = (&out.truth.surface, RunControl::new());
    let approximation = out.correction.approximation.as_ref().expect("a lake has water");
    let read = approximation.correct(&level1, surface, &control).unwrap();
    let owned = approximation.correct(Level1Input::Owned(level1.clone()), surface, &control).unwrap();
    assert_same(&read, &owned, "per-scene");
    assert_same(&read, &out.kept().rrs, "per-scene, the run's product");
    assert!(read.flags.iter().any(|f| *f == 0), "some pixels retrieved");
    let (terms, exact) = assert_the_diagnostic_is_the_cubes(&out, &level1);
    // An image with no water: its product (every pixel left out) against the exact correction.
    let none = no_water(&level1).unwrap();
    let expected = compare(&none, &exact.rrs, Some(&exact.flags));
    assert_eq!(expected, no_water_compared_with_exact(&level1, &terms).unwrap());
    assert!(expected.iter().all(|d| d.n == 0), "nothing of it is valid");
}
