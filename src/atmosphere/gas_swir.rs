//! Gas transmittance from 1000 to 2500 nm: a table of 6SV's one-way transmittances against the
//! absorber's path amount, at every nanometre.
//!
//! The table (`assets/atmosphere/gas_transmittance_6sv.csv`) holds, per wavelength, the
//! sun-to-surface transmittance 6SV 1.1 computes with its band model (random exponential band
//! model on HITRAN lines, 10 cm⁻¹ resolution: Vermote et al. 1997; Kotchenova et al. 2006) for
//! - water vapour, against its slant column u = W/μ (g cm⁻²), 0.1–25 g cm⁻², and
//! - the uniformly mixed gases O₂, CO₂, CH₄, N₂O and CO together, against the air mass
//!   m = 1/μ at sea level (1–6).
//!
//! Between tabulated amounts the optical depth τ = −ln T is interpolated linearly in (ln u,
//! ln τ): the curve of growth is a power law τ ∝ u^k with k between 1 (weak lines) and ½
//! (strong lines, Goody & Yung 1989, §4.7), and a straight line in log–log space follows it
//! between nodes. Below the first amount τ ∝ u (weak-line limit), above the last τ ∝ u^½
//! (strong-line limit). A lower surface pressure P shortens the mixed gases' column in
//! proportion, m′ = m·P/1013.25 (the first-order scaling of Bird & Riordan 1986, eq. 2-11; the
//! narrower lines at low pressure are not modelled). Water vapour's column is the scene's
//! precipitable water, whatever the pressure.
//!
//! ## References
//! - Vermote, E. F. et al. (1997) Second Simulation of the Satellite Signal in the Solar Spectrum,
//!   6S: an overview. IEEE TGRS 35, 675–686.
//! - Kotchenova, S. Y. et al. (2006) Validation of a vector version of the 6S radiative transfer
//!   code for atmospheric correction of satellite data. Appl. Opt. 45, 6762–6774.
//! - Goody, R. M. & Yung, Y. L. (1989) Atmospheric Radiation: Theoretical Basis, 2nd ed., Oxford.
//! - Bird, R. E. & Riordan, C. (1986) Simple solar spectral model for direct and diffuse
//!   irradiance on horizontal and tilted planes at the Earth's surface for cloudless
//!   atmospheres. J. Clim. Appl. Meteorol. 25, 87–97.

use std::sync::OnceLock;

use super::AtmosphereError;
use crate::spectral::Table;

const ASSET: &str = "atmosphere/gas_transmittance_6sv.csv";

/// Where the table takes over from the WASI model, nm.
pub const FROM_NM: f64 = 1000.0;
/// Where the table ends, nm.
pub const TO_NM: f64 = 2500.0;

/// One gas group's optical depths: per wavelength, τ at each tabulated amount.
struct Group {
    /// The tabulated path amounts, increasing.
    amounts: Vec<f64>,
    /// ln of the amounts.
    ln_amounts: Vec<f64>,
    /// Per wavelength: τ at each amount.
    tau: Vec<Vec<f64>>,
}

/// The optical depth of a transmittance the table gives as 0: 6SV prints five decimals, so 0
/// means below 5·10⁻⁶ (τ above ln 2·10⁵ ≈ 12.2), found in the cores of the 1.38 and 1.88 µm
/// water bands, where no signal reaches the sensor either way.
const TAU_OPAQUE: f64 = 12.206_072_645_530_174;

/// The smallest optical depth kept (τ below it is treated as this, so its logarithm exists):
/// a transmittance of 1 − 10⁻⁹.
const TAU_FLOOR: f64 = 1e-9;

impl Group {
    /// τ at path amount `x` for wavelength row `i` (see the module's interpolation).
    fn tau(&self, i: usize, x: f64) -> f64 {
        if !(x > 0.0) {
            return 0.0;
        }
        let t = &self.tau[i];
        let n = self.amounts.len();
        if x <= self.amounts[0] {
            return t[0] * x / self.amounts[0];
        }
        if x >= self.amounts[n - 1] {
            return t[n - 1] * (x / self.amounts[n - 1]).sqrt();
        }
        let lx = x.ln();
        let j = self.ln_amounts.partition_point(|&a| a <= lx).clamp(1, n - 1);
        let w = (lx - self.ln_amounts[j - 1]) / (self.ln_amounts[j] - self.ln_amounts[j - 1]);
        let (a, b) = (t[j - 1].max(TAU_FLOOR).ln(), t[j].max(TAU_FLOOR).ln());
        let tau = (a + w * (b - a)).exp();
        if tau <= TAU_FLOOR * 1.000_001 { 0.0 } else { tau }
    }
}

struct SwirTable {
    /// Wavelengths, nm (1-nm steps).
    wavelengths_nm: Vec<f64>,
    water: Group,
    mixed: Group,
}

/// Columns named `prefix` + amount, in file order, as (amount, values).
fn columns(t: &Table, prefix: &str) -> Result<Vec<(f64, Vec<f64>)>, AtmosphereError> {
    let mut out = Vec::new();
    for name in &t.columns {
        if let Some(amount) = name.strip_prefix(prefix) {
            let a: f64 = amount
                .parse()
                .map_err(|_| AtmosphereError::Data(format!("{ASSET}: column `{name}` does not end in an amount")))?;
            out.push((a, t.column_f64(name)?));
        }
    }
    if out.len() < 2 || out.windows(2).any(|w| w[1].0 <= w[0].0) {
        return Err(AtmosphereError::Data(format!(
            "{ASSET}: `{prefix}` columns must be two or more increasing amounts"
        )));
    }
    Ok(out)
}

fn group(t: &Table, prefix: &str, rows: usize) -> Result<Group, AtmosphereError> {
    let cols = columns(t, prefix)?;
    let amounts: Vec<f64> = cols.iter().map(|c| c.0).collect();
    let mut tau = Vec::with_capacity(rows);
    for i in 0..rows {
        let row: Vec<f64> = cols
            .iter()
            .map(|c| {
                let v = c.1[i];
                if v.is_finite() && v > 0.0 && v <= 1.0 {
                    Ok(-v.ln())
                } else if v == 0.0 {
                    Ok(TAU_OPAQUE)
                } else {
                    Err(AtmosphereError::Data(format!("{ASSET}: transmittance {v} in row {} (allowed: 0 to 1)", i + 1)))
                }
            })
            .collect::<Result<_, _>>()?;
        tau.push(row);
    }
    Ok(Group { ln_amounts: amounts.iter().map(|a| a.ln()).collect(), amounts, tau })
}

fn table() -> Result<&'static SwirTable, AtmosphereError> {
    static T: OnceLock<Result<SwirTable, AtmosphereError>> = OnceLock::new();
    T.get_or_init(|| {
        let t = Table::from_asset(ASSET)?;
        let wavelengths_nm = t.column_f64("wavelength_nm")?;
        if wavelengths_nm.windows(2).any(|w| (w[1] - w[0] - 1.0).abs() > 1e-9)
            || wavelengths_nm.first() > Some(&FROM_NM)
            || wavelengths_nm.last() < Some(&TO_NM)
        {
            return Err(AtmosphereError::Data(format!(
                "{ASSET}: wavelengths must run every 1 nm over {FROM_NM}–{TO_NM} nm"
            )));
        }
        let rows = wavelengths_nm.len();
        Ok(SwirTable { water: group(&t, "t_h2o_u", rows)?, mixed: group(&t, "t_mixed_m", rows)?, wavelengths_nm })
    })
    .as_ref()
    .map_err(Clone::clone)
}

/// One-way transmittance of water vapour (slant column `water_g_cm2`, g cm⁻²) and the mixed
/// gases (air mass `mixed_air_mass`, pressure-scaled) at `wavelength_nm` in 1000–2500 nm:
/// the optical depths interpolated in amount at the two neighbouring table rows, then linearly
/// in wavelength.
pub fn transmittance(wavelength_nm: f64, water_g_cm2: f64, mixed_air_mass: f64) -> Result<f64, AtmosphereError> {
    let t = table()?;
    if !(FROM_NM..=TO_NM).contains(&wavelength_nm) {
        return Err(AtmosphereError::OutOfRange {
            field: "wavelength_nm (SWIR gas table)".into(),
            value: wavelength_nm,
            allowed: format!("{FROM_NM} to {TO_NM} nm"),
        });
    }
    let x = wavelength_nm - t.wavelengths_nm[0];
    let i = (x.floor() as usize).min(t.wavelengths_nm.len() - 2);
    let w = x - i as f64;
    let tau = |row: usize| t.water.tau(row, water_g_cm2) + t.mixed.tau(row, mixed_air_mass);
    Ok((-((1.0 - w) * tau(i) + w * tau(i + 1))).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_curve_of_growth_is_followed_between_and_beyond_the_nodes() {
        let g = Group { amounts: vec![1.0, 4.0], ln_amounts: vec![0.0, 4f64.ln()], tau: vec![vec![0.1, 0.2]] };
        // Between: a power law through both nodes, τ = 0.1·u^½.
        assert!((g.tau(0, 2.0) - 0.1 * 2f64.sqrt()).abs() < 1e-12);
        // Below: linear to zero; above: square root.
        assert!((g.tau(0, 0.5) - 0.05).abs() < 1e-12);
        assert!((g.tau(0, 16.0) - 0.4).abs() < 1e-12);
        assert_eq!(g.tau(0, 0.0), 0.0);
        assert!((TAU_OPAQUE - (2e5f64).ln()).abs() < 1e-12);
    }
}
