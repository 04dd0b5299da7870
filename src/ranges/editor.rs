//! How editors offer a field of the range table: the label, displayed unit and scale, slider
//! span and tip each range of an editable field carries ([`Editor`]), and the order the app's
//! instrument editor shows them in ([`INSTRUMENT_EDITOR`]).

use super::*;

/// How an editor shows a field: the one description the app's sliders, its parameter table
/// and the sweep list read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Editor {
    /// Label ("Aperture").
    pub label: &'static str,
    /// Unit as shown ("ms"; empty: none).
    pub unit: &'static str,
    /// Shown = stored × scale (an exposure stored in s, shown in ms).
    pub scale: f64,
    /// The slider's span, shown units (a typed value may leave it; the range decides).
    pub slider: (f64, f64),
    /// A logarithmic slider.
    pub log: bool,
    /// What moving it does, for the hover text.
    pub tip: &'static str,
}

/// The instrument fields an editor offers, in its order (the app's sliders; the parameter
/// table of the app and the review slide).
pub const INSTRUMENT_EDITOR: [Range; 13] = [
    INSTRUMENT_APERTURE_MM,
    INSTRUMENT_PIXEL_PITCH_UM,
    INSTRUMENT_FOCAL_LENGTH_MM,
    INSTRUMENT_DETECTORS,
    INSTRUMENT_LINES,
    INSTRUMENT_EXPOSURE_S,
    INSTRUMENT_WELL_DEPTH_E,
    INSTRUMENT_GAIN_E_PER_DN,
    INSTRUMENT_READ_NOISE_E,
    INSTRUMENT_BIAS_DN,
    INSTRUMENT_ADC_BITS,
    INSTRUMENT_OPTICAL_TRANSMISSION,
    INSTRUMENT_ALTITUDE_KM,
];
