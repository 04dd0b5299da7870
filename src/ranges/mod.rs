//! The documented range of every number a user sets — one table.
//!
//! Each validator checks its fields against the entries here, so a message and its check cannot
//! drift apart; `shoal ranges` prints the table, and docs/MANUAL.md's "Ranges" section is that output (a
//! unit test keeps the two equal). A value outside its range is refused with the field, the value
//! and the range ("aperture_mm: 5000 is out of range (allowed: above 0, at most 2000 mm)"): exit
//! code 2 in the CLI, an inline refusal in the app.
//!
//! Paths are those of the run configuration as files and sweeps spell them
//! (`instrument.aperture_mm`; `[i]` stands for a list index; an enum variant's fields follow its
//! name, `instrument.kind.Spectrograph.start_nm`). The study section holds the requirement
//! thresholds of a study file.

mod editor;
pub mod limits;

pub use editor::{Editor, INSTRUMENT_EDITOR};

/// Shortest wavelength Shoal simulates, nm.
pub const MIN_SIMULATED_NM: f64 = 325.0;
/// Longest wavelength Shoal simulates, nm: the end of the solar spectrum, the SWIR gas table
/// and the aerosol table (`assets/solar/solar_tsis1_hsrs_1nm.csv`,
/// `assets/atmosphere/gas_transmittance_6sv.csv`, `assets/atmosphere/wmo_aerosol_mie.csv`).
pub const MAX_SIMULATED_NM: f64 = 2500.0;

mod range;

pub use range::Range;

macro_rules! ranges {
    ($( $(#[$doc:meta])* $name:ident = $range:expr; )*) => {
        $( $(#[$doc])* pub const $name: Range = $range; )*
        /// Every range, in table order.
        pub const ALL: &[Range] = &[$($name),*];
    };
}

ranges! {
    // Instrument (InstrumentSpec::validate).
    /// Orbit altitude.
    INSTRUMENT_ALTITUDE_KM = Range::closed("instrument.altitude_km", 200.0, 1500.0, "km", "orbit altitude")
        .edited(Editor { label: "Altitude", unit: "km", scale: 1.0, slider: (200.0, 1_500.0), log: false, tip: "Orbit altitude: GSD and ground speed" });
    /// Orbital heading.
    INSTRUMENT_HEADING_DEG = Range::closed("instrument.heading_deg", -360.0, 360.0, "degrees", "ground-track azimuth, clockwise from north");
    /// Entrance aperture.
    INSTRUMENT_APERTURE_MM = Range::above("instrument.aperture_mm", 0.0, 2000.0, "mm", "entrance pupil diameter")
        .edited(Editor { label: "Aperture", unit: "mm", scale: 1.0, slider: (10.0, 500.0), log: true, tip: "Entrance pupil diameter: photons grow with its square" });
    /// Pixel pitch.
    INSTRUMENT_PIXEL_PITCH_UM = Range::above("instrument.pixel_pitch_um", 0.0, 1000.0, "µm", "detector pixel pitch (MODIS's 1 km whiskbroom detectors: 540 µm)")
        .edited(Editor { label: "Pixel pitch", unit: "µm", scale: 1.0, slider: (1.0, 30.0), log: false, tip: "Detector pixel size: sets GSD with altitude and focal length" });
    /// Focal length.
    INSTRUMENT_FOCAL_LENGTH_MM = Range::above("instrument.focal_length_mm", 0.0, 10_000.0, "mm", "effective focal length")
        .edited(Editor { label: "Focal length", unit: "mm", scale: 1.0, slider: (20.0, 2_000.0), log: true, tip: "GSD = altitude × pitch / focal length" });
    /// Detectors across track.
    INSTRUMENT_DETECTORS = Range::count("instrument.detectors", 1.0, 20_000.0, "", "detectors across track (swath = detectors · GSD)")
        .edited(Editor { label: "Detectors", unit: "", scale: 1.0, slider: (16.0, 4_096.0), log: true, tip: "Detectors across track (swath = detectors × GSD)" });
    /// Exposure.
    INSTRUMENT_EXPOSURE_S = Range::above("instrument.exposure_s", 0.0, 10.0, "s", "integration time of one frame")
        .edited(Editor { label: "Exposure", unit: "ms", scale: 1_000.0, slider: (0.1, 20.0), log: true, tip: "Integration time per line" });
    /// Frames along track.
    INSTRUMENT_LINES = Range::count("instrument.lines", 1.0, 100_000.0, "", "lines (exposures) along track")
        .edited(Editor { label: "Lines", unit: "", scale: 1.0, slider: (16.0, 4_000.0), log: true, tip: "Exposures along track" });
    /// Forward tilt.
    INSTRUMENT_FORWARD_TILT_DEG = Range::closed("instrument.forward_tilt_deg", -60.0, 60.0, "degrees", "pointing along track (positive: forward)");
    /// Across-track tilt (roll).
    INSTRUMENT_ACROSS_TRACK_TILT_DEG = Range::closed("instrument.across_track_tilt_deg", -60.0, 60.0, "degrees", "pointing across track (positive: right of the ground track)");
    /// Read noise.
    INSTRUMENT_READ_NOISE_E = Range::closed("instrument.read_noise_e", 0.0, 1e5, "e-", "read noise, rms")
        .edited(Editor { label: "Read noise", unit: "e⁻", scale: 1.0, slider: (0.0, 100.0), log: false, tip: "Readout noise, electrons rms" });
    /// Full well.
    INSTRUMENT_WELL_DEPTH_E = Range::closed("instrument.well_depth_e", 1.0, 1e9, "e-", "full-well capacity (at least one electron: the signal over full scale divides by it)")
        .edited(Editor { label: "Well depth", unit: "e⁻", scale: 1.0, slider: (1_000.0, 2_000_000.0), log: true, tip: "Full-well capacity: saturation above it" });
    /// Conversion gain.
    INSTRUMENT_GAIN_E_PER_DN = Range::closed("instrument.gain_e_per_dn", 0.01, 1e4, "e-/DN", "conversion gain")
        .edited(Editor { label: "Gain", unit: "e⁻/DN", scale: 1.0, slider: (0.1, 100.0), log: true, tip: "Conversion gain: quantisation noise gain²/12" });
    /// ADC offset.
    INSTRUMENT_BIAS_DN = Range::closed("instrument.bias_dn", 0.0, 65_535.0, "DN", "ADC offset (below the ADC's largest count, 2^adc_bits − 1)").below_hi()
        .edited(Editor { label: "Bias", unit: "DN", scale: 1.0, slider: (0.0, 1_000.0), log: false, tip: "ADC offset" });
    /// ADC resolution.
    INSTRUMENT_ADC_BITS = Range::count("instrument.adc_bits", 1.0, 16.0, "bits", "ADC resolution")
        .edited(Editor { label: "ADC bits", unit: "", scale: 1.0, slider: (4.0, 16.0), log: false, tip: "Converter resolution: 2^bits − 1 is the largest count" });
    /// Optics transmission.
    INSTRUMENT_OPTICAL_TRANSMISSION = Range::above("instrument.optical_transmission", 0.0, 1.0, "", "optics transmission (spectrally flat factor)")
        .edited(Editor { label: "Optical transmission", unit: "", scale: 1.0, slider: (0.1, 1.0), log: false, tip: "Throughput of the optics and filters" });
    /// Dark current.
    INSTRUMENT_DARK_CURRENT_E_S = Range::closed("instrument.dark_current_e_s", 0.0, 1e9, "e-/s", "dark current per pixel");
    /// Photo-response non-uniformity.
    INSTRUMENT_PRNU = Range::closed("instrument.prnu", 0.0, 0.5, "", "photo-response non-uniformity, relative rms");
    /// Dark-signal non-uniformity.
    INSTRUMENT_DSNU_E = Range::closed("instrument.dsnu_e", 0.0, 1e6, "e-", "dark-signal non-uniformity, rms");
    /// Dark current: temperature it is specified at.
    DARK_REFERENCE_C = Range::closed("instrument.dark_temperature.reference_c", -273.0, 150.0, "°C", "temperature at which the dark current is specified");
    /// Dark current: operating temperature.
    DARK_OPERATING_C = Range::closed("instrument.dark_temperature.operating_c", -273.0, 150.0, "°C", "detector operating temperature");
    /// Dark current: doubling temperature step.
    DARK_DOUBLING_DELTA_C = Range::closed("instrument.dark_temperature.law.Doubling.delta_c", 0.5, 50.0, "°C", "temperature rise that doubles the dark current");
    /// Dark current: activation energy.
    DARK_ACTIVATION_EV = Range::closed("instrument.dark_temperature.law.Arrhenius.activation_ev", 0.05, 2.0, "eV", "activation energy of the dark current (Arrhenius law)");
    /// A further focal plane: pixel pitch.
    PLANE_PIXEL_PITCH_UM = Range::above("instrument.focal_planes[].pixel_pitch_um", 0.0, 1000.0, "µm", "the plane's pixel pitch (a whole multiple or fraction of the first plane's)");
    /// A further focal plane: detectors.
    PLANE_DETECTORS = Range::count("instrument.focal_planes[].detectors", 1.0, 40_000.0, "", "the plane's detectors across track (its swath must cover the first plane's)");
    /// A further focal plane: read noise.
    PLANE_READ_NOISE_E = Range::closed("instrument.focal_planes[].read_noise_e", 0.0, 1e5, "e-", "the plane's read noise, rms");
    /// A further focal plane: full well.
    PLANE_WELL_DEPTH_E = Range::closed("instrument.focal_planes[].well_depth_e", 1.0, 1e9, "e-", "the plane's full-well capacity (at least one electron)");
    /// A further focal plane: conversion gain.
    PLANE_GAIN_E_PER_DN = Range::closed("instrument.focal_planes[].gain_e_per_dn", 0.01, 1e4, "e-/DN", "the plane's conversion gain");
    /// A further focal plane: ADC offset.
    PLANE_BIAS_DN = Range::closed("instrument.focal_planes[].bias_dn", 0.0, 65_535.0, "DN", "the plane's ADC offset (below 2^adc_bits − 1)").below_hi();
    /// A further focal plane: ADC resolution.
    PLANE_ADC_BITS = Range::count("instrument.focal_planes[].adc_bits", 1.0, 16.0, "bits", "the plane's ADC resolution");
    /// A further focal plane: dark current.
    PLANE_DARK_CURRENT_E_S = Range::closed("instrument.focal_planes[].dark_current_e_s", 0.0, 1e9, "e-/s", "the plane's dark current per pixel (at dark_temperature.reference_c when given)");
    /// A further focal plane: PRNU.
    PLANE_PRNU = Range::closed("instrument.focal_planes[].prnu", 0.0, 0.5, "", "the plane's photo-response non-uniformity, relative rms");
    /// A further focal plane: integration time.
    PLANE_EXPOSURE_S = Range::above("instrument.focal_planes[].exposure_s", 0.0, 10.0, "s", "the plane's integration time (default: the instrument's times the pitch ratio)");
    /// A further focal plane: DSNU.
    PLANE_DSNU_E = Range::closed("instrument.focal_planes[].dsnu_e", 0.0, 1e6, "e-", "the plane's dark-signal non-uniformity, rms");
    /// Spectrograph: first band centre.
    SPECTROGRAPH_START_NM = Range::closed("instrument.kind.Spectrograph.start_nm", 350.0, 2500.0, "nm", "first band centre");
    /// Spectrograph: last band centre.
    SPECTROGRAPH_END_NM = Range::closed("instrument.kind.Spectrograph.end_nm", 350.0, 2500.0, "nm", "last band centre (not below start_nm; end_nm + 2.5·resolution_nm + abs(smile_nm) ≤ 2500 nm)");
    /// Spectrograph: sampling.
    SPECTROGRAPH_SAMPLING_NM = Range::above("instrument.kind.Spectrograph.sampling_nm", 0.0, 100.0, "nm", "spectral sampling per detector row (at most 2000 samples)");
    /// Spectrograph: resolution.
    SPECTROGRAPH_RESOLUTION_NM = Range::above("instrument.kind.Spectrograph.resolution_nm", 0.0, 100.0, "nm", "spectral resolution, FWHM (every band's response, centre ± 2.5 FWHM, within 325–2500 nm)");
    /// Spectrograph: smile.
    SPECTROGRAPH_SMILE_NM = Range::closed("instrument.kind.Spectrograph.smile_nm", -20.0, 20.0, "nm", "band-centre shift at the swath edges");
    /// Spectrograph: spectral samples summed per band.
    SPECTROGRAPH_CHANNELS_SUMMED = Range::count("instrument.kind.Spectrograph.channels_summed", 1.0, 64.0, "", "adjacent spectral samples summed into one band (spectral binning)");
    /// Spectrograph: keystone.
    SPECTROGRAPH_KEYSTONE_PX = Range::closed("instrument.kind.Spectrograph.keystone_px", -20.0, 20.0, "pixels", "across-track misregistration, first to last band");
    /// Filter imager: rows per band.
    FILTER_ROWS_PER_BAND = Range::count("instrument.kind.FilterImager.rows_per_band", 1.0, 10_000.0, "", "detector rows between band centres");

    // Instrument effects (instrument::effects; `effects[]` is the entry's index).
    /// Stray light: halo share at 550 nm.
    STRAY_HALO_FRACTION = Range::closed("instrument.effects[].StrayLight.halo_fraction", 0.0, 0.5, "", "share of the light the far-field halo spreads, at 550 nm");
    /// Stray light: the halo's knee.
    STRAY_KNEE_M = Range::above("instrument.effects[].StrayLight.knee_m", 0.0, 1e5, "m", "knee of the halo's Harvey profile on the ground");
    /// Stray light: the halo's slope.
    STRAY_SLOPE = Range::closed("instrument.effects[].StrayLight.slope", 0.5, 6.0, "", "power-law slope of the halo beyond its knee");
    /// Stray light: the halo's extent.
    STRAY_RADIUS_M = Range::above("instrument.effects[].StrayLight.radius_m", 0.0, 50_000.0, "m", "extent of the halo on the ground");
    /// Stray light: out-of-field veil.
    STRAY_OUT_OF_FIELD = Range::closed("instrument.effects[].StrayLight.out_of_field_fraction", 0.0, 0.5, "", "share of the light from beyond the field of view (a veil of the image's mean)");
    /// Stray light: wavelength law.
    STRAY_WAVELENGTH_EXPONENT = Range::closed("instrument.effects[].StrayLight.wavelength_exponent", 0.0, 4.0, "", "p in halo_fraction·(550/λ)^p (2: micro-roughness scatter)");
    /// Stray light: the processor's error.
    STRAY_KNOWLEDGE_ERROR = Range::closed("instrument.effects[].StrayLight.correction.error", -1.0, 1.0, "", "relative error of the processor's halo and veil");
    /// Polarisation sensitivity.
    POLARISATION_SENSITIVITY = Range::closed("instrument.effects[].Polarisation.sensitivity", 0.0, 0.2, "", "polarisation sensitivity √(m12² + m13²) of every band (or of each in per_band)");
    /// Polarisation axis.
    POLARISATION_AXIS_DEG = Range::closed("instrument.effects[].Polarisation.axis_deg", -180.0, 180.0, "degrees", "most transmitted polarisation, from the along-track axis");
    /// Polarisation: the processor's error.
    POLARISATION_KNOWLEDGE_ERROR = Range::closed("instrument.effects[].Polarisation.correction.error", -1.0, 1.0, "", "relative error of the processor's sensitivity");
    /// Spectral stray light: share scattered.
    SPECTRAL_STRAY_FRACTION = Range::closed("instrument.effects[].SpectralStrayLight.fraction", 0.0, 0.2, "", "share of each band's light scattered into the other bands");
    /// Spectral stray light: spectral scale.
    SPECTRAL_STRAY_WIDTH_NM = Range::above("instrument.effects[].SpectralStrayLight.width_nm", 0.0, 5000.0, "nm", "spectral scale of the scatter (large: spread evenly over the bands)");
    /// Spectral stray light: the processor's error.
    SPECTRAL_STRAY_KNOWLEDGE_ERROR = Range::closed("instrument.effects[].SpectralStrayLight.correction.error", -1.0, 1.0, "", "relative error of the processor's stray-light matrix");
    /// Non-linearity: quadratic term.
    NONLINEARITY_QUADRATIC = Range::closed("instrument.effects[].NonLinearity.quadratic", -0.2, 0.2, "", "a₂ of e′ = e(1 + a₂x + a₃x²), x = e/W: departure at full well from the quadratic term");
    /// Non-linearity: cubic term.
    NONLINEARITY_CUBIC = Range::closed("instrument.effects[].NonLinearity.cubic", -0.2, 0.2, "", "a₃ of the same curve");
    /// Non-linearity: column spread.
    NONLINEARITY_COLUMN_SPREAD = Range::closed("instrument.effects[].NonLinearity.column_spread", 0.0, 1.0, "", "relative rms of each column's curve about its band's");
    /// Non-linearity: the calibration's error.
    NONLINEARITY_KNOWLEDGE_ERROR = Range::closed("instrument.effects[].NonLinearity.correction.error", -1.0, 1.0, "", "relative error of the curve the calibration linearises with");
    /// Fixed patterns: gain drift.
    PATTERN_GAIN_DRIFT = Range::closed("instrument.effects[].FixedPatterns.gain_drift", 0.0, 0.1, "", "relative rms change of each element's gain since calibration (striping)");
    /// Fixed patterns: dark-signal drift.
    PATTERN_OFFSET_DRIFT_E = Range::closed("instrument.effects[].FixedPatterns.offset_drift_e", 0.0, 1000.0, "e⁻", "rms change of each element's dark signal since calibration");
    /// Fixed patterns: dead elements.
    PATTERN_DEAD_FRACTION = Range::closed("instrument.effects[].FixedPatterns.dead_fraction", 0.0, 0.2, "", "share of detector elements with no response");
    /// Fixed patterns: hot elements.
    PATTERN_HOT_FRACTION = Range::closed("instrument.effects[].FixedPatterns.hot_fraction", 0.0, 0.2, "", "share of detector elements with extra dark current");
    /// Fixed patterns: a hot element's extra dark current.
    PATTERN_HOT_DARK_E_S = Range::closed("instrument.effects[].FixedPatterns.hot_dark_current_e_s", 0.0, 1e6, "e⁻/s", "extra dark current of a hot element");
    /// Compression: error bound.
    COMPRESSION_MAX_ERROR_DN = Range::count("instrument.effects[].Compression.max_error_dn", 0.0, 4096.0, "DN", "largest reconstruction error of the near-lossless coder (0: lossless)");
    /// Compression: rate target.
    COMPRESSION_BITS_PER_SAMPLE = Range::closed("instrument.effects[].Compression.bits_per_sample", 0.0, 16.0, "bits", "rate the downlink allows (0: none; else the smallest error bound meeting it)");
    /// Misregistration: rms shift.
    MISREGISTRATION_SIGMA_PX = Range::closed("instrument.effects[].Misregistration.sigma_px", 0.0, 5.0, "pixels", "rms of each band's shift along and across track");
    /// Misregistration: the processor's error.
    MISREGISTRATION_KNOWLEDGE_ERROR = Range::closed("instrument.effects[].Misregistration.correction.error", -1.0, 1.0, "", "relative error of the shifts the co-registration believes");
    /// Binning: pixels summed along and across track.
    BINNING_FACTOR = Range::count("instrument.effects[].Binning.factor", 1.0, 16.0, "", "k: k × k pixels summed into one on board");
    /// Binning: spectral samples summed.
    BINNING_SPECTRAL = Range::count("instrument.effects[].Binning.spectral", 1.0, 16.0, "", "m: adjacent spectral samples summed on board (a spectrograph only)");
    /// Spectral knowledge: common centre error.
    SPECTRAL_CENTRE_NM = Range::closed("instrument.effects[].SpectralKnowledge.centre_nm", -10.0, 10.0, "nm", "every band's true centre minus the believed one (per_band_nm: each band's)");
    /// Spectral knowledge: drawn centre error.
    SPECTRAL_SIGMA_NM = Range::closed("instrument.effects[].SpectralKnowledge.sigma_nm", 0.0, 5.0, "nm", "rms of a further centre error drawn per band");
    /// Spectral knowledge: width error.
    SPECTRAL_WIDTH_PCT = Range::closed("instrument.effects[].SpectralKnowledge.width_pct", -50.0, 100.0, "%", "every band's true width relative to the believed");
    /// Spectral knowledge: smile error.
    SPECTRAL_SMILE_PCT = Range::closed("instrument.effects[].SpectralKnowledge.smile_pct", -100.0, 100.0, "%", "a spectrograph's true smile relative to the stated one");
    /// TDI: stages.
    TDI_STAGES = Range::count("instrument.effects[].Tdi.stages", 1.0, 256.0, "", "rows integrated per band");
    /// TDI: line-rate error.
    TDI_LINE_RATE_ERROR = Range::closed("instrument.effects[].Tdi.line_rate_error", -0.1, 0.1, "", "relative error of the line rate against the image's motion");
    /// TDI: charge transfer efficiency.
    TDI_CTE = Range::closed("instrument.effects[].Tdi.cte", 0.99, 1.0, "", "charge transfer efficiency per stage (charge-domain TDI)");
    /// MTF budget: central obstruction.
    MTF_OBSTRUCTION = Range::closed("instrument.effects[].SpatialResponse.obstruction", 0.0, 0.8, "", "secondary's diameter over the aperture's");
    /// MTF budget: wavefront error.
    MTF_WAVEFRONT_RMS_NM = Range::closed("instrument.effects[].SpatialResponse.wavefront_rms_nm", 0.0, 70.0, "nm", "RMS wavefront error (Shannon's fit holds to 0.18 waves: 72 nm at 400 nm)");
    /// MTF budget: pixel fill.
    MTF_PIXEL_FILL = Range::closed("instrument.effects[].SpatialResponse.pixel_fill", 0.3, 1.0, "", "width of a pixel's sensitive aperture over its pitch");
    /// MTF budget: charge diffusion.
    MTF_DIFFUSION_UM = Range::closed("instrument.effects[].SpatialResponse.diffusion_um", 0.0, 20.0, "µm", "Gaussian σ of charge diffusion in the focal plane");
    /// MTF budget: crosstalk.
    MTF_CROSSTALK = Range::closed("instrument.effects[].SpatialResponse.crosstalk", 0.0, 0.2, "", "share of a pixel's signal on each neighbour");
    /// MTF budget: jitter.
    MTF_JITTER_URAD = Range::closed("instrument.effects[].SpatialResponse.jitter_urad", 0.0, 100.0, "µrad", "RMS line-of-sight jitter during an exposure");

    // Scene (SceneSpec::validate and the maps' values in Scene::build).
    /// Scene width.
    SCENE_WIDTH = Range::count("scene.width", 1.0, 20_000.0, "cells", "cells along x (east)");
    /// Scene height.
    SCENE_HEIGHT = Range::count("scene.height", 1.0, 20_000.0, "cells", "cells along y (north)");
    /// Cell size.
    SCENE_CELL_M = Range::closed("scene.cell_m", 0.1, 10_000.0, "m", "ground size of a cell");
    /// Sun zenith.
    SCENE_SUN_ZENITH_DEG = Range::closed("scene.sun.zenith_deg", 0.0, 85.0, "degrees", "solar zenith angle");
    /// Chlorophyll-a map values.
    SCENE_CHL_MG_M3 = Range::closed("scene.chl_mg_m3", 0.0, limits::MAX_CHL_MG_M3, "mg m-3", "chlorophyll-a (every value of the map)");
    /// NAP map values.
    SCENE_NAP_G_M3 = Range::closed("scene.nap_g_m3", 0.0, limits::MAX_NAP_G_M3, "g m-3", "non-algal particles (every value of the map)");
    /// CDOM map values.
    SCENE_CDOM_PER_M = Range::closed("scene.cdom_per_m", 0.0, limits::MAX_CDOM_PER_M, "m-1", "CDOM absorption at the reference wavelength (every value)");
    /// Depth map values.
    SCENE_DEPTH_M = Range::above("scene.depth_m", 0.0, limits::MAX_DEPTH_M, "m", "water depth (every value of the map)");
    /// Land reflectance.
    SCENE_LAND_REFLECTANCE = Range::closed("scene.land.reflectance", 0.0, 1.0, "", "land surface reflectance (Lambertian; every value of the spectrum)");
    /// Substrate fraction map values.
    SCENE_SUBSTRATE_FRACTION = Range::closed("scene.substrates[i].fraction", 0.0, 1.0, "", "areal fraction of a substrate (every value)");
    /// Aerosol optical thickness map.
    SCENE_AOT550_MAP = Range::closed("scene.aot550_map", 0.0, 5.0, "", "aerosol optical thickness at 550 nm (every value of the map)");
    /// Cloud cover.
    SCENE_CLOUDS_COVER = Range::closed("scene.clouds.cover", 0.0, 1.0, "", "fraction of the scene under cloud");
    /// Cloud size.
    SCENE_CLOUDS_SIZE_M = Range::closed("scene.clouds.size_m", 50.0, 100_000.0, "m", "typical cloud size (the field's correlation length)");
    /// Cloud layer height.
    SCENE_CLOUDS_HEIGHT_M = Range::closed("scene.clouds.height_m", 0.0, 15_000.0, "m", "height of the cloud layer above the water (shadow and parallax)");
    /// Cloud optical thickness.
    SCENE_CLOUDS_OPTICAL_THICKNESS = Range::above("scene.clouds.optical_thickness", 0.0, 200.0, "", "cloud optical thickness at 550 nm (sets its albedo)");

    // Spectra written as formulas (SpectrumSource::PowerLaw and Exponential, wherever one is
    // given: SIOP sets, land reflectance, QE).
    /// Reference wavelength of an analytic spectrum.
    SPECTRUM_REFERENCE_NM = Range::closed("spectrum.reference_nm", 100.0, 3000.0, "nm", "reference wavelength of a PowerLaw or Exponential spectrum");

    // Atmosphere (AtmosphereSpec::validate, RtAccuracy::validate).
    /// Aerosol optical thickness.
    ATMOSPHERE_AOT550 = Range::closed("scene.atmosphere.aot550", 0.0, 5.0, "", "aerosol optical thickness at 550 nm");
    /// Surface pressure.
    ATMOSPHERE_PRESSURE_HPA = Range::closed("scene.atmosphere.pressure_hpa", 500.0, 1100.0, "hPa", "surface pressure");
    /// Ozone column.
    ATMOSPHERE_OZONE_ATM_CM = Range::closed("scene.atmosphere.gas_amounts.ozone_atm_cm", 0.0, 1.0, "atm-cm", "ozone column");
    /// Water-vapour column.
    ATMOSPHERE_WATER_VAPOUR_CM = Range::closed("scene.atmosphere.gas_amounts.water_vapour_cm", 0.0, 10.0, "cm", "precipitable water");
    /// Wind speed of a rough surface.
    ATMOSPHERE_WIND_SPEED_M_S = Range::closed("scene.atmosphere.surface.Wind.speed_m_s", 0.0, 30.0, "m/s", "wind speed (Cox–Munk surface)");
    /// A user's WMO mixture: dust-like fraction.
    ATMOSPHERE_MIXTURE_DUST_LIKE = Range::closed("scene.atmosphere.aerosol.Mixture.dust_like", 0.0, 1.0, "", "volume fraction of the dust-like component (the four are normalised by their sum, which must be above 0)");
    /// A user's WMO mixture: water-soluble fraction.
    ATMOSPHERE_MIXTURE_WATER_SOLUBLE = Range::closed("scene.atmosphere.aerosol.Mixture.water_soluble", 0.0, 1.0, "", "volume fraction of the water-soluble component");
    /// A user's WMO mixture: oceanic fraction.
    ATMOSPHERE_MIXTURE_OCEANIC = Range::closed("scene.atmosphere.aerosol.Mixture.oceanic", 0.0, 1.0, "", "volume fraction of the oceanic component");
    /// A user's log-normal mode: modal radius.
    AEROSOL_MODE_RADIUS_UM = Range::closed("scene.atmosphere.aerosol.LogNormal.fine.mode_radius_um", 0.005, 5.0, "um", "modal radius of a log-normal mode's number distribution (fine or coarse)");
    /// A user's log-normal mode: geometric standard deviation.
    AEROSOL_MODE_SIGMA_G = Range::closed("scene.atmosphere.aerosol.LogNormal.fine.sigma_g", 1.05, 2.6, "", "geometric standard deviation of a log-normal mode");
    /// A user's log-normal mode: real refractive index.
    AEROSOL_MODE_REFRACTIVE_REAL = Range::closed("scene.atmosphere.aerosol.LogNormal.fine.refractive_real", 1.3, 1.8, "", "real part of a mode's refractive index");
    /// A user's log-normal mode: imaginary refractive index.
    AEROSOL_MODE_REFRACTIVE_IMAG = Range::closed("scene.atmosphere.aerosol.LogNormal.fine.refractive_imag", 0.0, 0.5, "", "imaginary part of a mode's refractive index (absorption)");
    /// A user's log-normal aerosol: coarse volume fraction.
    AEROSOL_COARSE_VOLUME_FRACTION = Range::closed("scene.atmosphere.aerosol.LogNormal.coarse_volume_fraction", 0.0, 1.0, "", "share of the aerosol volume in the coarse mode");
    /// A user's WMO mixture: soot fraction.
    ATMOSPHERE_MIXTURE_SOOT = Range::closed("scene.atmosphere.aerosol.Mixture.soot", 0.0, 1.0, "", "volume fraction of the soot component");
    /// Latitude.
    ATMOSPHERE_LATITUDE_DEG = Range::closed("scene.atmosphere.latitude_deg", -90.0, 90.0, "degrees", "latitude (gravity in the Rayleigh depth)");
    /// Molecular scale height.
    ATMOSPHERE_RAYLEIGH_SCALE_HEIGHT_KM = Range::closed("scene.atmosphere.rayleigh_scale_height_km", 1.0, 20.0, "km", "molecular scale height");
    /// Aerosol scale height.
    ATMOSPHERE_AEROSOL_SCALE_HEIGHT_KM = Range::closed("scene.atmosphere.aerosol_scale_height_km", 0.1, 20.0, "km", "aerosol scale height");
    /// Water refractive index.
    ATMOSPHERE_WATER_REFRACTIVE_INDEX = Range::closed("scene.atmosphere.water_refractive_index", 1.0, 1.5, "", "refractive index of the water surface");

    // `shoal atmosphere` runs (AtmosphereRun: the atmosphere alone, at a geometry given in
    // degrees). A scene sets the day from its date and stops the sun at 85°; the radiative
    // transfer itself accepts the sun down to 89°.
    /// Day of the year of a `shoal atmosphere` run.
    ATMOSPHERE_DAY_OF_YEAR = Range::count("atmosphere_run.atmosphere.day_of_year", 1.0, 366.0, "", "day of the year (Sun–Earth distance); a scene sets it from its date");
    /// Sun zenith of a `shoal atmosphere` run.
    GEOMETRY_SUN_ZENITH_DEG = Range::closed("atmosphere_run.sun_zenith_deg", 0.0, 89.0, "degrees", "solar zenith (the plane-parallel model has no meaning at the horizon)");
    /// View zenith of a `shoal atmosphere` run.
    GEOMETRY_VIEW_ZENITH_DEG = Range::closed("atmosphere_run.view_zenith_deg", 0.0, 85.0, "degrees", "view zenith");
    /// Relative azimuth of a `shoal atmosphere` run.
    GEOMETRY_RELATIVE_AZIMUTH_DEG = Range::closed("atmosphere_run.relative_azimuth_deg", -360.0, 360.0, "degrees", "view azimuth minus sun azimuth");
    /// Discrete-ordinate streams.
    ACCURACY_STREAMS = Range::count("scene.atmosphere.accuracy.streams", 2.0, 48.0, "", "quadrature streams per hemisphere");
    /// Scattering orders.
    ACCURACY_MAX_ORDERS = Range::count("scene.atmosphere.accuracy.max_orders", 1.0, 500.0, "", "most orders of scattering");
    /// Fourier terms.
    ACCURACY_FOURIER_TERMS = Range::count("scene.atmosphere.accuracy.fourier_terms", 1.0, 96.0, "", "azimuthal Fourier terms");
    /// Layer optical depth.
    ACCURACY_MAX_LAYER_DEPTH = Range::closed("scene.atmosphere.accuracy.max_layer_depth", 0.0001, 1.0, "", "largest optical depth of one layer (thinner layers only multiply the work)");
    /// Fewest layers.
    ACCURACY_MIN_LAYERS = Range::count("scene.atmosphere.accuracy.min_layers", 1.0, 500.0, "", "fewest layers");
    /// Order tolerance.
    ACCURACY_ORDER_TOLERANCE = Range::above("scene.atmosphere.accuracy.order_tolerance", 0.0, 0.1, "", "stop when an order adds less than this fraction").below_hi();

    // Fidelity (Fidelity::validate).
    /// Spectral step.
    FIDELITY_SPECTRAL_STEP_NM = Range::closed("fidelity.spectral_step_nm", 0.1, 10.0, "nm", "spectral step of the simulation grids");
    /// Spatial-response quadrature.
    FIDELITY_SPATIAL_SAMPLES_PER_GSD = Range::count("fidelity.spatial_samples_per_gsd", 1.0, 8.0, "", "spatial-response points per GSD and axis");
    /// Per-pixel spectra at band nodes.
    FIDELITY_BAND_NODES = Range::count("fidelity.band_nodes", 0.0, 8.0, "", "water spectra per pixel at this many nodes per band (0: every grid wavelength)");
    /// Preview decimation.
    FIDELITY_DECIMATION = Range::count("fidelity.decimation", 1.0, 1000.0, "", "every n-th line and detector (1: full resolution)");
    /// LUT wavelength spacing.
    FIDELITY_LUT_WAVELENGTH_STEP_NM = Range::closed("fidelity.lut_wavelength_step_nm", 5.0, 50.0, "nm", "wavelength spacing of the atmosphere LUT");
    /// LUT view spacing.
    FIDELITY_LUT_VIEW_STEP_DEG = Range::closed("fidelity.lut_view_step_deg", 1.0, 20.0, "degrees", "view-zenith spacing of the atmosphere LUT");
    /// SNR frames.
    FIDELITY_SNR_FRAMES = Range::count("fidelity.snr_frames", 2.0, 10_000.0, "", "frames of the uniform patch that measures SNR");
    /// SNR detectors.
    FIDELITY_SNR_DETECTORS = Range::count("fidelity.snr_detectors", 1.0, 20_000.0, "", "detectors of the SNR patch, at most");

    // Calibration (CalibrationSpec::validate).
    /// Flat-field frames.
    CALIBRATION_LIGHT_FRAMES = Range::count("calibration.light_frames", 1.0, 10_000.0, "", "diffuser frames averaged");
    /// Dark frames.
    CALIBRATION_DARK_FRAMES = Range::count("calibration.dark_frames", 1.0, 10_000.0, "", "dark frames averaged");
    /// Dark exposure.
    CALIBRATION_DARK_EXPOSURE_S = Range::closed("calibration.dark_exposure_s", 0.0, 10.0, "s", "exposure of the dark frames (0, the paper's: no dark current; the scene's to see it)");
    /// Diffuser reflectance.
    CALIBRATION_DIFFUSER_REFLECTANCE = Range::above("calibration.diffuser_reflectance", 0.0, 1.0, "", "diffuser reflectance");
    /// Sun incidence on the diffuser.
    CALIBRATION_SUN_INCIDENCE_DEG = Range::closed("calibration.sun_incidence_deg", 0.0, 89.0, "degrees", "sun incidence on the diffuser").below_hi();
    /// Diffuser error.
    CALIBRATION_DIFFUSER_BIAS_PCT = Range::closed("calibration.diffuser_bias_pct", -50.0, 50.0, "%", "injected error of the diffuser's reflectance");
    /// Gain drift.
    CALIBRATION_GAIN_DRIFT_PCT = Range::closed("calibration.gain_drift_pct", -50.0, 50.0, "%", "injected gain drift after calibration");

    // Atmospheric correction (CorrectionSpec::validate).
    /// Approximation sample points.
    CORRECTION_APPROX_POINTS = Range::count("correction.approx_points", 1.0, 10_000.0, "", "water pixels of the per-scene approximation (paper: 20)");
    /// Error of the wind the exact correction assumes for the glint.
    CORRECTION_EXACT_GLINT_WIND_ERROR = Range::closed("correction.glint_wind_error_m_s", -20.0, 20.0, "m/s", "error of the wind the exact correction assumes for the glint it takes away (its wind: the scene's plus this, at least 0)");
    /// High-glint threshold of the exact correction.
    CORRECTION_EXACT_GLINT_THRESHOLD = Range::above("correction.glint_threshold_per_sr", 0.0, 1.0, "sr-1", "largest normalised glint radiance L_GN, from the wind the exact correction assumes, of a pixel it keeps (l2gen's glint_thresh; unset: every pixel kept)");
    /// Image-based correction: the aerosol pair's band centres.
    CORRECTION_PAIR_NM = Range::closed("correction.image.pair_nm", 600.0, 2500.0, "nm", "centres of the short and long band of the aerosol pair, short first (the instrument's nearest bands, within 30 nm)");
    /// Image-based correction: AOT nodes of the family's tables.
    CORRECTION_AOT_NODE = Range::above("correction.image.aot_nodes", 0.0, 5.0, "", "AOT(550) nodes of the aerosol family's tables, increasing (0 is always added)");
    /// Glint threshold of the image-based correction.
    CORRECTION_GLINT_THRESHOLD = Range::above("correction.image.glint_threshold_per_sr", 0.0, 1.0, "sr-1", "largest normalised glint radiance L_GN of a retrieved pixel (l2gen's glint_thresh)");
    /// Error of the wind the image-based correction assumes for the glint.
    CORRECTION_GLINT_WIND_ERROR = Range::closed("correction.image.glint_wind_error_m_s", -20.0, 20.0, "m/s", "error of the wind the processor assumes for the glint (its wind: the scene's plus this, at least 0)");
    /// The cloud screen's threshold.
    CORRECTION_CLOUD_THRESHOLD = Range::above("correction.image.clouds.threshold", 0.0, 1.0, "", "Rayleigh-corrected reflectance at 865 nm above which a pixel is cloud");
    /// The cloud height the shadow screen assumes.
    CORRECTION_CLOUD_HEIGHT_M = Range::closed("correction.image.clouds.height_m", 0.0, 15_000.0, "m", "cloud height the shadow projection assumes (0: no shadow screen)");
    /// Dark-spectrum fitting: tile side.
    CORRECTION_DARK_TILE_PX = Range::count("correction.image.dark.tile_px", 0.0, 100_000.0, "pixels", "tile side of dark-spectrum fitting (0: the whole scene)");
    /// Dark-spectrum fitting: darkest pixels.
    CORRECTION_DARK_PIXELS = Range::count("correction.image.dark.pixels", 2.0, 100_000.0, "", "darkest pixels per band in the intercept fit (ACOLITE: 200)");
    /// Dark-spectrum fitting: gas transmittance threshold.
    CORRECTION_DARK_MIN_GAS = Range::closed("correction.image.dark.min_gas_transmittance", 0.0, 1.0, "", "bands with a lower two-way gas transmittance are not fitted (ACOLITE: 0.85)");
    /// Dark-spectrum fitting: band range.
    CORRECTION_DARK_WAVE_RANGE_NM = Range::closed("correction.image.dark.wave_range_nm", 350.0, 2500.0, "nm", "bands fitted, shortest first (ACOLITE: 400-2500)");

    // Retrievals (RetrievalSpec::validate).
    /// aLMI rrs(u) linear coefficient.
    ALMI_G0 = Range::above("retrievals[i].Almi.settings.g0", 0.0, 1.0, "sr-1", "rrs(u) linear coefficient (Lee et al. 1999: 0.084)");
    /// aLMI rrs(u) quadratic coefficient.
    ALMI_G1 = Range::closed("retrievals[i].Almi.settings.g1", 0.0, 1.0, "sr-1", "rrs(u) quadratic coefficient (Lee et al. 1999: 0.17)");
    /// SAMBUCA iteration limit.
    SAMBUCA_MAX_ITERATIONS = Range::count("retrievals[i].Sambuca.settings.max_iterations", 1.0, 10_000.0, "", "iterations per start");
    /// SAMBUCA quadrature.
    SAMBUCA_NODES_PER_BAND = Range::count("retrievals[i].Sambuca.settings.nodes_per_band", 1.0, 8.0, "", "Gauss nodes per band in the forward model");
    /// An external retrieval's time limit.
    EXTERNAL_TIME_LIMIT_S = Range::closed("retrievals[i].External.time_limit_s", 1.0, 86_400.0, "s", "wall-clock time the program may take per run before it is stopped");

    // Study requirements (Requirements::validate).
    /// Largest allowed MAE.
    REQUIREMENT_MAE_PCT = Range::closed("requirements.products[i].mae_pct", 0.0, 1e4, "%", "largest log-space MAE a product may have");
    /// Largest allowed bias.
    REQUIREMENT_BIAS_PCT = Range::closed("requirements.products[i].bias_pct", 0.0, 1e4, "%", "largest log-space bias, either sign");
    /// Smallest returned share.
    REQUIREMENT_RETURNED_PCT = Range::closed("requirements.products[i].returned_pct", 0.0, 100.0, "%", "smallest share of water pixels retrieved");
    /// Smallest share of pixels whose dominant substrate is right.
    REQUIREMENT_SUBSTRATE_PCT = Range::closed("requirements.substrate_pct", 0.0, 100.0, "%", "smallest share of returned water pixels whose dominant substrate is the truth's");
    /// Largest allowed corrected-Rrs error per band.
    REQUIREMENT_RRS_MAE_PCT = Range::closed("requirements.rrs.mae_pct", 0.0, 1e4, "%", "largest log-space MAE of the corrected Rrs in every band centred from `from_nm` to `to_nm` (default 400–560 nm)");
    /// Smallest SNR.
    REQUIREMENT_SNR = Range::above("requirements.snr", 0.0, 1e6, "", "smallest SNR of every band at the typical radiance").below_hi();
}

mod table;

pub use table::markdown_table;

#[cfg(test)]
mod tests;
