//! Any bytes, read as each kind of preset file (instrument, scene, study, sweep, full run
//! configuration), parsed and validated: an error is fine, a panic is a bug.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(i) = shoal::instrument::InstrumentSpec::from_ron(text, "fuzz") {
        let _ = i.validate();
        if i.validate().is_ok() {
            let _ = (i.gsd_m(), i.etendue_m2_sr(), i.dn_max());
        }
    }
    if let Ok(s) = shoal::scene::SceneSpec::from_ron(text, "fuzz") {
        let _ = s.validate();
    }
    if let Ok(c) = shoal::engine::RunConfig::from_ron(text, "fuzz") {
        // Every range of the configuration (instrument, scene, atmosphere, fidelity, calibration,
        // correction, retrievals).
        let _ = c.validate();
    }
    if let Ok(s) = shoal::study::StudySpec::from_ron(text, "fuzz") {
        // Resolving reads only embedded presets (no directory is given).
        let _ = s.resolve(None);
    }
    if let Ok(s) = shoal::sweep::SweepSpec::from_ron(text, "fuzz") {
        let _ = s.resolve(None);
    }
});
