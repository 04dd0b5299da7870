//! The structural edits the coherence tests apply: fields the range table does not hold (enums,
//! lists, names, switches), each with the description a failure prints.

use super::*;

/// An edit of a configuration, with the description a failure prints.
pub(super) type Edit = (&'static str, fn(&mut RunConfig));

/// Edits of the fields the range table does not hold (enums, lists, names, switches).
pub(super) fn structural_edits() -> Vec<Edit> {
    vec![
        ("instrument bands: an OLCI subset", |c| {
            let bands = (1..=12).map(|i| format!("Oa{i:02}")).collect();
            c.instrument.kind = shoal::instrument::InstrumentKind::Multispectral {
                bands: shoal::spectral::BandSetSpec::Olci { platform: Default::default(), bands: Some(bands) },
            };
        }),
        ("instrument bands: OLCI S3B", |c| {
            c.instrument.kind = shoal::instrument::InstrumentKind::Multispectral {
                bands: shoal::spectral::BandSetSpec::Olci { platform: shoal::spectral::Platform::B, bands: None },
            };
        }),
        ("instrument quantum efficiency", |c| {
            c.instrument.quantum_efficiency = shoal::spectral::SpectrumSource::Constant(0.5);
        }),
        ("detector noise off", |c| c.detector.noise = false),
        ("quantisation off", |c| c.detector.quantise = false),
        ("calibration perfect", |c| c.calibration.perfect = true),
        ("correction uses the approximation", |c| c.correction.method = shoal::correction::Method::PerScene),
        ("aerosol continental", |c| c.scene.atmosphere.aerosol = shoal::atmosphere::AerosolType::Continental),
        ("flat surface (and so no glint)", |c| {
            c.scene.atmosphere.surface = shoal::atmosphere::SeaSurface::Flat;
            c.scene.effects.retain(|e| *e != Effect::SunGlint);
        }),
        ("gases off", |c| c.scene.atmosphere.gases = false),
        ("OSOAA Rayleigh depth", |c| {
            c.scene.atmosphere.rayleigh = shoal::atmosphere::RayleighDepth::OsoaaHansenTravis;
        }),
        ("sun azimuth", |c| c.scene.sun.azimuth_deg += 40.0),
        ("date", |c| c.scene.date = "2018-06-27".into()),
        ("no adjacency", |c| c.scene.effects.retain(|e| *e != Effect::Adjacency)),
        ("no glint", |c| c.scene.effects.retain(|e| *e != Effect::SunGlint)),
        ("no spatial response", |c| c.scene.effects.retain(|e| *e != Effect::SpatialResponse)),
        ("no shallow bottom", |c| c.scene.effects.retain(|e| *e != Effect::ShallowBottom)),
        ("scene SIOP set", |c| c.scene.siop = shoal::water::SiopSource::Preset("cyanobacteria_reservoir".into())),
        ("a substrate renamed", |c| c.scene.substrates[0].name = "brown_acropora".into()),
        ("depth map replaced by a constant 3 m", |c| c.scene.depth_m = Some(MapSpec::Constant(3.0))),
        ("noise seed", |c| c.seed += 1),
        ("aLMI with four sets", |c| {
            if let RetrievalSpec::Almi { siop_sets, .. } = &mut c.retrievals[0] {
                siop_sets.truncate(4);
            }
        }),
        ("aLMI without noise weighting", |c| {
            if let RetrievalSpec::Almi { settings, .. } = &mut c.retrievals[0] {
                settings.noise_weighting = !settings.noise_weighting;
            }
        }),
        ("aLMI reference mode", |c| {
            if let RetrievalSpec::Almi { settings, .. } = &mut c.retrievals[0] {
                settings.mode = shoal::retrieval::Mode::Reference;
            }
        }),
        ("aLMI bands", |c| {
            if let RetrievalSpec::Almi { settings, .. } = &mut c.retrievals[0] {
                settings.bands = Some(["Oa03", "Oa05", "Oa06", "Oa08", "Oa11"].map(String::from).to_vec());
            }
        }),
        ("SAMBUCA reference mode", |c| {
            if let RetrievalSpec::Sambuca { settings, .. } = &mut c.retrievals[1] {
                settings.mode = shoal::retrieval::Mode::Reference;
            }
        }),
        ("SAMBUCA substrates", |c| {
            if let RetrievalSpec::Sambuca { substrates, .. } = &mut c.retrievals[1] {
                *substrates = Some(vec!["sand".into(), "acropora".into()]);
            }
        }),
        ("SAMBUCA SIOP set", |c| {
            if let RetrievalSpec::Sambuca { siop, .. } = &mut c.retrievals[1] {
                *siop = Some(shoal::water::SiopSource::Preset("cyanobacteria_reservoir".into()));
            }
        }),
        ("SAMBUCA objective", |c| {
            if let RetrievalSpec::Sambuca { settings, .. } = &mut c.retrievals[1] {
                settings.objective = shoal::retrieval::Objective::Lsq;
            }
        }),
        ("SAMBUCA starts", |c| {
            // Deep starts on every pixel (the base's Adaptive never needs them on a 1.5 m flat).
            if let RetrievalSpec::Sambuca { settings, .. } = &mut c.retrievals[1] {
                settings.starts = shoal::retrieval::Starts::ShallowAndDeep;
            }
        }),
        ("SAMBUCA depth bounds", |c| {
            if let RetrievalSpec::Sambuca { settings, .. } = &mut c.retrievals[1] {
                settings.bounds.depth_m.1 = 12.0;
            }
        }),
        ("one retrieval only", |c| {
            c.retrievals.truncate(1);
        }),
        ("instrument.name", |c| c.instrument.name = "renamed".into()),
        ("instrument.description", |c| c.instrument.description = "described".into()),
    ]
}
