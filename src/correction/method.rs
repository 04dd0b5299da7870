//! Which correction turns Level-1 into Rrs ([`Method`]: one of three, never two), how a
//! configuration writes it (unchanged: `use_approximation` and `image`, so every study file,
//! session and sweep path reads as before), and the named corrections the app's menu and
//! `shoal correct --correction` both offer ([`PRESETS`]).

use serde::{Deserialize, Serialize};

use super::image::{AerosolFit, ImageCorrection};

/// How Level-1 becomes Rrs.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Method {
    /// The forward model's own atmosphere, per pixel: the paper's perfect correction.
    #[default]
    Exact,
    /// The paper's per-scene approximation (Appendix A), from `approx_points` water pixels.
    PerScene,
    /// The image-based correction: the aerosol from the design's own bands ([`super::image`]).
    Image(ImageCorrection),
}

/// Correction settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "CorrectionFile", into = "CorrectionFile")]
pub struct CorrectionSpec {
    /// Random water pixels for the paper's per-scene approximation (Appendix A: 20).
    pub approx_points: usize,
    /// The correction delivered as the Rrs product.
    pub method: Method,
    /// The error of the wind the exact correction assumes for the glint it takes away, m/s: its
    /// wind is the scene's plus this (at least 0). The exact correction knows the atmosphere; a
    /// processor knows the wind only from ancillary fields, as l2gen does, so over a glinting
    /// scene this prices the wind alone ([`super::expected_glint`]). 0: the wind is known. The
    /// image-based correction states its own (`image.glint_wind_error_m_s`); the per-scene
    /// approximation, whose terms come from the scene's own pixels, takes none. Read only while
    /// the method is [`Method::Exact`] (the app's menu keeps it through a switch to another
    /// method and back) and written only then, so a file never holds it beside another method,
    /// which reading refuses.
    pub glint_wind_error_m_s: f64,
    /// The exact correction's high-glint mask: leave out the water pixels whose normalised glint
    /// L_GN = ρ_g·μ₀/π, expected from the wind it assumes, exceeds this, sr⁻¹ (l2gen's HIGLINT
    /// with its `glint_thresh`, 0.005; Wang & Bailey 2001). `None`, the default: the paper's
    /// perfect processor keeps every pixel. A season sets its own threshold here for the exact
    /// correction, as the image-based correction has its own (`image.glint_threshold_per_sr`).
    /// Read and written only with the exact method, as the wind error is.
    pub glint_threshold_per_sr: Option<f64>,
}

impl Default for CorrectionSpec {
    fn default() -> Self {
        Self { approx_points: 20, method: Method::Exact, glint_wind_error_m_s: 0.0, glint_threshold_per_sr: None }
    }
}

impl CorrectionSpec {
    /// The wind error the exact correction works with: [`Self::glint_wind_error_m_s`] when the
    /// method is exact, else 0.
    #[must_use]
    pub fn exact_wind_error_m_s(&self) -> f64 {
        if self.method == Method::Exact { self.glint_wind_error_m_s } else { 0.0 }
    }

    /// The exact correction's high-glint threshold: [`Self::glint_threshold_per_sr`] when the
    /// method is exact, else `None`.
    #[must_use]
    pub fn exact_glint_threshold_per_sr(&self) -> Option<f64> {
        if self.method == Method::Exact { self.glint_threshold_per_sr } else { None }
    }

    /// The image-based correction's settings, when that is the method.
    #[must_use]
    pub fn image(&self) -> Option<&ImageCorrection> {
        match &self.method {
            Method::Image(i) => Some(i),
            _ => None,
        }
    }
}

/// [`CorrectionSpec`] as a file writes it: `(approx_points: 20, use_approximation: false, image:
/// Some((…)))`, the two choices as a switch and an option (under the spec's own name, which a
/// file written with struct names states).
#[derive(Serialize, Deserialize)]
#[serde(rename = "CorrectionSpec", deny_unknown_fields, default)]
struct CorrectionFile {
    approx_points: usize,
    use_approximation: bool,
    image: Option<ImageCorrection>,
    glint_wind_error_m_s: f64,
    // Written only when set, so that every file written before reads and writes as it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    glint_threshold_per_sr: Option<f64>,
}

impl Default for CorrectionFile {
    fn default() -> Self {
        CorrectionSpec::default().into()
    }
}

impl TryFrom<CorrectionFile> for CorrectionSpec {
    type Error = String;

    fn try_from(f: CorrectionFile) -> Result<Self, String> {
        if f.glint_wind_error_m_s != 0.0 && (f.use_approximation || f.image.is_some()) {
            return Err("correction.glint_wind_error_m_s: the exact correction's wind error; the image-based \
                        correction states its own (correction.image.glint_wind_error_m_s), the per-scene \
                        approximation none"
                .into());
        }
        if f.glint_threshold_per_sr.is_some() && (f.use_approximation || f.image.is_some()) {
            return Err("correction.glint_threshold_per_sr: the exact correction's high-glint mask; the image-based \
                        correction states its own (correction.image.glint_threshold_per_sr), the per-scene \
                        approximation none"
                .into());
        }
        let method = match (f.use_approximation, f.image) {
            (false, None) => Method::Exact,
            (true, None) => Method::PerScene,
            (false, Some(i)) => Method::Image(i),
            (true, Some(_)) => {
                return Err("correction.image: choose one: the image-based correction (`image`) or the per-scene \
                            approximation (`use_approximation: true`)"
                    .into());
            }
        };
        Ok(Self {
            approx_points: f.approx_points,
            method,
            glint_wind_error_m_s: f.glint_wind_error_m_s,
            glint_threshold_per_sr: f.glint_threshold_per_sr,
        })
    }
}

impl From<CorrectionSpec> for CorrectionFile {
    fn from(s: CorrectionSpec) -> Self {
        let glint_wind_error_m_s = s.exact_wind_error_m_s();
        let glint_threshold_per_sr = s.exact_glint_threshold_per_sr();
        let (use_approximation, image) = match s.method {
            Method::Exact => (false, None),
            Method::PerScene => (true, None),
            Method::Image(i) => (false, Some(i)),
        };
        Self { approx_points: s.approx_points, use_approximation, image, glint_wind_error_m_s, glint_threshold_per_sr }
    }
}

/// A named correction: what the app's menu lists and `shoal correct --correction` takes.
#[derive(Debug, Clone, Copy)]
pub struct Preset {
    /// Its key on the command line (`pair`).
    pub key: &'static str,
    /// Its name in the app's menu and the reports.
    pub label: &'static str,
    /// What it does, with its sources (the menu's hover text).
    pub about: &'static str,
    /// The method.
    pub make: fn() -> Method,
}

impl Preset {
    /// `method` is this preset's (an image-based one with the same fit and, for a pair, the same
    /// bands, whatever its other settings).
    #[must_use]
    pub fn matches(&self, method: &Method) -> bool {
        match (method, (self.make)()) {
            (Method::Image(i), Method::Image(p)) => {
                i.fit == p.fit
                    && (p.fit == AerosolFit::DarkSpectrum
                        || (i.pair_nm == p.pair_nm && i.nir_iteration == p.nir_iteration))
            }
            (m, p) => *m == p,
        }
    }

    /// The preset of `key`.
    ///
    /// # Errors
    /// No such preset (the message lists the keys).
    pub fn of(key: &str) -> Result<&'static Self, String> {
        PRESETS.iter().find(|p| p.key == key).ok_or_else(|| {
            format!("no correction `{key}`: one of {}", PRESETS.iter().map(|p| p.key).collect::<Vec<_>>().join(", "))
        })
    }
}

/// The named corrections, in the order the app's menu lists them.
pub const PRESETS: [Preset; 6] = [
    Preset {
        key: "exact",
        label: "perfect processor (exact)",
        about: "The forward model's own atmosphere, per pixel: the paper's perfect correction (no mission knows its \
                atmosphere this well; the default corrects from the design's own bands)",
        make: || Method::Exact,
    },
    Preset {
        key: "per-scene",
        label: "per-scene (paper)",
        about: "Matthews et al. 2023, Appendix A: one set of terms from 20 water pixels",
        make: || Method::PerScene,
    },
    Preset {
        key: "pair",
        label: "image: 779/865 nm",
        about: "Aerosol from the design's 779 and 865 nm bands (Gordon & Wang 1994; l2gen's OLCI pair), the water's \
                NIR signal estimated from the red band (Bailey et al. 2010); a design without them uses its own \
                mission pair (MODIS 748/869 nm, or a SWIR pair)",
        make: || Method::Image(ImageCorrection::default()),
    },
    Preset {
        key: "pair-black",
        label: "image: 779/865 nm, NIR black",
        about: "The 779/865 nm pair with the water taken as black in the NIR (Gordon & Wang 1994, before Bailey et \
                al. 2010): what turbid water costs a processor without the NIR iteration",
        make: || Method::Image(ImageCorrection { nir_iteration: false, ..ImageCorrection::default() }),
    },
    Preset {
        key: "swir",
        label: "image: 1610/2200 nm",
        about: "Aerosol from a SWIR pair, black even over turbid water (Wang & Shi 2007)",
        // Water is black at 1610 and 2200 nm: no NIR iteration (MANUAL, the image-based correction).
        make: || {
            Method::Image(ImageCorrection {
                pair_nm: [1610.0, 2200.0],
                nir_iteration: false,
                ..ImageCorrection::default()
            })
        },
    },
    Preset {
        key: "dark",
        label: "image: dark spectrum",
        about: "One atmosphere for the scene from its darkest pixels in every band (ACOLITE; Vanhellemont & Ruddick \
                2018)",
        make: || Method::Image(ImageCorrection::dark_spectrum()),
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_reads_and_writes_as_before() {
        for (text, method) in [
            ("()", Method::Exact),
            ("(use_approximation: true)", Method::PerScene),
            ("(image: Some(()))", Method::Image(ImageCorrection::default())),
        ] {
            let spec: CorrectionSpec = ron::from_str(text).unwrap();
            assert_eq!(spec.method, method, "{text}");
            let back: CorrectionSpec = ron::from_str(&ron::to_string(&spec).unwrap()).unwrap();
            assert_eq!(back, spec);
        }
        let written = ron::to_string(&CorrectionSpec::default()).unwrap();
        assert_eq!(written, "(approx_points:20,use_approximation:false,image:None,glint_wind_error_m_s:0.0)");
        // With struct names (config.ron, study.ron, the library's studies), as an older Shoal
        // wrote them.
        let named = ron::ser::to_string_pretty(
            &CorrectionSpec::default(),
            ron::ser::PrettyConfig::default().struct_names(true),
        )
        .unwrap();
        assert!(named.starts_with("CorrectionSpec("), "{named}");
        let old: CorrectionSpec = ron::from_str("CorrectionSpec(approx_points: 20, use_approximation: true)").unwrap();
        assert_eq!(old.method, Method::PerScene);
    }

    #[test]
    fn two_methods_at_once_are_refused_naming_both() {
        let e = ron::from_str::<CorrectionSpec>("(use_approximation: true, image: Some(()))").unwrap_err();
        let e = e.to_string();
        assert!(e.contains("choose one") && e.contains("use_approximation"), "{e}");
        let e = ron::from_str::<CorrectionSpec>("(image: None, exact: true)").unwrap_err().to_string();
        assert!(e.contains("exact"), "{e}");
        // The exact correction's wind error beside another method: refused, naming the field.
        for text in
            ["(use_approximation: true, glint_wind_error_m_s: 1.0)", "(image: Some(()), glint_wind_error_m_s: 1.0)"]
        {
            let e = ron::from_str::<CorrectionSpec>(text).unwrap_err().to_string();
            assert!(e.contains("correction.glint_wind_error_m_s") && e.contains("correction.image"), "{e}");
        }
    }

    #[test]
    fn the_exact_correction_s_wind_error_reads_and_writes() {
        let spec: CorrectionSpec = ron::from_str("(glint_wind_error_m_s: -1.5)").unwrap();
        assert_eq!((spec.method.clone(), spec.glint_wind_error_m_s), (Method::Exact, -1.5));
        let text = ron::to_string(&spec).unwrap();
        assert_eq!(text, "(approx_points:20,use_approximation:false,image:None,glint_wind_error_m_s:-1.5)");
        assert_eq!(ron::from_str::<CorrectionSpec>(&text).unwrap(), spec);
        // Switched to another method (as the app's menu does), it is neither read nor written:
        // the file reads back.
        let image = CorrectionSpec { method: Method::Image(ImageCorrection::default()), ..spec };
        assert_eq!(image.exact_wind_error_m_s(), 0.0);
        let back: CorrectionSpec = ron::from_str(&ron::to_string(&image).unwrap()).unwrap();
        assert_eq!((back.method, back.glint_wind_error_m_s), (image.method, 0.0));
    }

    #[test]
    fn every_preset_matches_its_own_method_only() {
        for (i, p) in PRESETS.iter().enumerate() {
            for (j, q) in PRESETS.iter().enumerate() {
                assert_eq!(p.matches(&(q.make)()), i == j, "{} against {}", p.key, q.key);
            }
        }
        assert_eq!(Preset::of("dark").unwrap().label, "image: dark spectrum");
        let e = Preset::of("exactly").unwrap_err();
        assert!(e.contains("exact, per-scene, pair, pair-black, swir, dark"), "{e}");
    }
}
