//! The water model against SAMBUCA's forward model (`tests/data/sambuca_forward`).
//!
//! Tolerance: 1e-6 relative on every column of every case. Both codes evaluate the same closed
//! formulas in f64 from the same inputs, so the only differences are rounding (≈1e-15) and the
//! inputs' own precision; 1e-6 is the acceptance figure and leaves nine orders of margin
//! for rounding while catching any wrong constant, exponent or angle (those move results by
//! ≥1e-4).

use shoal::spectral::{SpectrumSource, Table, WavelengthGrid};
use shoal::water::{Bottom, SiopSpec, WaterColumn, WaterGeometry, WaterModel};

use crate::data;

struct Case {
    id: String,
    values: std::collections::HashMap<String, String>,
}

impl Case {
    fn f(&self, key: &str) -> f64 {
        self.values[key].parse().unwrap_or_else(|_| panic!("{}: {key} = {}", self.id, self.values[key]))
    }
    fn s(&self, key: &str) -> &str {
        self.values[key].as_str()
    }
}

fn cases() -> Vec<Case> {
    // cases.csv has a quoted `note` column with commas; parse the fields we need by position.
    let text = std::fs::read_to_string(data("sambuca_forward/cases.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|line| {
            let mut cells = Vec::new();
            let (mut cur, mut quoted) = (String::new(), false);
            for ch in line.chars() {
                match ch {
                    '"' => quoted = !quoted,
                    ',' if !quoted => cells.push(std::mem::take(&mut cur)),
                    c => cur.push(c),
                }
            }
            cells.push(cur);
            assert_eq!(cells.len(), header.len(), "{line}");
            let values: std::collections::HashMap<_, _> = header.iter().map(|h| (*h).to_string()).zip(cells).collect();
            Case { id: values["case_id"].clone(), values }
        })
        .collect()
}

fn siop_for(case: &Case, inputs: &Table) -> SiopSpec {
    let wl = inputs.column_f64("wavelength_nm").unwrap();
    let table = |col: &str| SpectrumSource::Table {
        wavelength_nm: wl.clone(),
        values: inputs.column_f64(col).unwrap(),
        outside: Default::default(),
    };
    let y_ph = case.f("bb_ph_slope");
    let y_nap = if case.s("bb_nap_slope").is_empty() { y_ph } else { case.f("bb_nap_slope") };
    SiopSpec {
        name: format!("sambuca case {}", case.id),
        description: String::new(),
        water_absorption: table("a_water"),
        water_backscatter: SpectrumSource::PowerLaw {
            coefficient: 0.00194 / 2.0,
            reference_nm: case.f("bb_lambda_ref"),
            exponent: 4.32,
        },
        phytoplankton_absorption: table("a_ph_star"),
        phytoplankton_backscatter: SpectrumSource::PowerLaw {
            coefficient: case.f("x_ph_lambda0x"),
            reference_nm: case.f("lambda0x"),
            exponent: y_ph,
        },
        cdom_absorption: SpectrumSource::Exponential {
            coefficient: case.f("a_cdom_lambda0cdom"),
            reference_nm: case.f("lambda0cdom"),
            slope_per_nm: case.f("a_cdom_slope"),
        },
        nap_absorption: SpectrumSource::Exponential {
            coefficient: case.f("a_nap_lambda0nap"),
            reference_nm: case.f("lambda0nap"),
            slope_per_nm: case.f("a_nap_slope"),
        },
        nap_backscatter: SpectrumSource::PowerLaw {
            coefficient: case.f("x_nap_lambda0x"),
            reference_nm: case.f("lambda0x"),
            exponent: y_nap,
        },
        water_refractive_index: case.f("water_refractive_index"),
    }
}

fn substrate(case: &Case, inputs: &Table) -> Vec<f64> {
    let col = |name: &str| inputs.column_f64(&format!("R_{name}")).unwrap();
    let r1 = col(case.s("substrate1"));
    if case.s("substrate2").is_empty() {
        return r1; // SAMBUCA: substrate2=None uses substrate1 alone
    }
    let r2 = col(case.s("substrate2"));
    let f = case.f("substrate_fraction");
    r1.iter().zip(&r2).map(|(a, b)| f * a + (1.0 - f) * b).collect()
}

fn assert_close(case: &str, column: &str, wl: &[f64], got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{case}/{column}: length");
    for ((l, g), w) in wl.iter().zip(got).zip(want) {
        let ok = if *w == 0.0 { g.abs() < 1e-300 } else { ((g - w) / w).abs() <= 1e-6 };
        assert!(ok, "{case}/{column} at {l} nm: shoal {g:e} vs SAMBUCA {w:e} (rel {:e})", (g - w) / w);
    }
}

#[test]
fn matches_sambuca_forward_model_on_every_case_and_column() {
    let inputs = Table::from_file(&data("sambuca_forward/inputs_1nm.csv")).unwrap();
    let spectra = Table::from_file(&data("sambuca_forward/spectra_1nm.csv")).unwrap();
    let wl = inputs.column_f64("wavelength_nm").unwrap();
    let grid = WavelengthGrid::from_wavelengths(wl.clone()).unwrap();
    let case_col = spectra.column_index("case_id").unwrap();
    let all = cases();
    assert_eq!(all.len(), 11);
    for case in &all {
        let reference = spectra.filter_eq(case_col, &case.id);
        assert_eq!(reference.column_f64("wavelength_nm").unwrap(), wl, "{}: grid", case.id);
        let model = WaterModel::new(siop_for(case, &inputs).resolve(&grid, None).unwrap());
        let rb = substrate(case, &inputs);
        let column = WaterColumn {
            chl_mg_m3: case.f("chl"),
            cdom_per_m: case.f("cdom"),
            nap_g_m3: case.f("nap"),
            bottom: Bottom::Shallow { depth_m: case.f("depth"), reflectance: &rb },
        };
        let geometry = WaterGeometry::from_degrees(case.f("theta_air"), case.f("off_nadir"));
        let r = model.evaluate(&column, &geometry).unwrap();
        let q = case.f("q_factor");
        let s = model.siop();
        let rdp_0_minus: Vec<f64> = r.rrs_deep.iter().map(|x| q * x).collect();
        let checks: Vec<(&str, Vec<f64>)> = vec![
            ("r_substratum", r.r_substratum.clone()),
            ("rrs", r.rrs.clone()),
            ("rrsdp", r.rrs_deep.clone()),
            ("r_0_minus", r.r_0_minus(q)),
            ("rdp_0_minus", rdp_0_minus),
            ("kd", r.kd.clone()),
            ("kub", r.kub.clone()),
            ("kuc", r.kuc.clone()),
            ("a", r.a.clone()),
            ("a_cdom_star", s.a_cdom_star.clone()),
            ("a_nap_star", s.a_nap_star.clone()),
            ("a_ph", r.a_ph.clone()),
            ("a_cdom", r.a_cdom.clone()),
            ("a_nap", r.a_nap.clone()),
            ("bb", r.bb.clone()),
            ("bb_ph_star", s.bb_ph_star.clone()),
            ("bb_nap_star", s.bb_nap_star.clone()),
            ("bb_ph", r.bb_ph.clone()),
            ("bb_nap", r.bb_nap.clone()),
            ("bb_water", r.bb_w.clone()),
            ("Rrs_above_lee2002_OURS", r.rrs_above.clone()),
        ];
        assert_eq!(checks.len() + 2, reference.columns.len(), "every reference column is checked");
        for (name, got) in &checks {
            assert_close(&case.id, name, &wl, got, &reference.column_f64(name).unwrap());
        }
        // The per-pixel fast path (vectorised exp) must agree as well.
        let mut fast = vec![0.0; wl.len()];
        model.rrs_above_into(&column, &geometry, &mut fast).unwrap();
        assert_close(&case.id, "fast Rrs", &wl, &fast, &reference.column_f64("Rrs_above_lee2002_OURS").unwrap());
    }
}
