//! Any bytes as a spectrum CSV (header row, wavelength column, value columns): parsed, each
//! column made a spectrum and resampled onto a grid. An error is fine, a panic is a bug.
#![no_main]

use libfuzzer_sys::fuzz_target;
use shoal::spectral::{Extrapolation, Spectrum, Table, WavelengthGrid};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(table) = Table::parse(text, "fuzz.csv") else { return };
    let Ok(grid) = WavelengthGrid::uniform(400.0, 700.0, 10.0) else { return };
    for column in table.columns.iter().skip(1) {
        if let Ok(s) = Spectrum::from_table(&table, column) {
            let _ = s.resample(&grid, Extrapolation::Error);
            let _ = s.resample(&grid, Extrapolation::Clamp);
        }
    }
});
