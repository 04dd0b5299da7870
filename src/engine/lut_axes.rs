//! The atmosphere LUT's axes for a run: which wavelength, sun and view nodes it is built on.

use crate::atmosphere::LutAxes;
use crate::instrument::{Response, Viewing};

/// LUT axes: wavelength nodes on a fixed lattice covering the grids (so a change of bands rarely
/// rebuilds the table), one sun node, view nodes up to the swath edge. Only the lattice nodes
/// that bracket a stretch of simulated wavelengths are kept: a SWIR band adds the nodes around
/// it, not the 1000 nm between it and the visible (interpolation between two nodes uses only
/// those two, so leaving out the nodes of a gap changes nothing where wavelengths are simulated).
pub(super) fn lut_axes(response: &Response, viewing: &Viewing, sun_zenith_deg: f64, fid: &super::Fidelity) -> LutAxes {
    lut_axes_covering(response, (sun_zenith_deg, sun_zenith_deg), viewing.max_view_zenith_deg, fid)
}

/// LUT axes for `response`'s wavelengths, sun zeniths over `sun_zenith_deg` (lowest, highest) and
/// view zeniths to `max_view_zenith_deg`, at `fid`'s steps.
#[must_use]
pub fn lut_axes_covering(
    response: &Response,
    sun_zenith_deg: (f64, f64),
    max_view_zenith_deg: f64,
    fid: &super::Fidelity,
) -> LutAxes {
    use crate::ranges::{MAX_SIMULATED_NM, MIN_SIMULATED_NM};
    let step = fid.lut_wavelength_step_nm;
    let mut nodes: Vec<f64> = Vec::new();
    for g in &response.groups {
        let w = g.grid.wavelengths_nm();
        let mut start = 0;
        for i in 1..=w.len() {
            // A stretch ends where the next wavelength is more than a lattice step away.
            if i < w.len() && w[i] - w[i - 1] <= step {
                continue;
            }
            let (lo, hi) = (w[start], w[i - 1]);
            let first = ((lo / step).floor() * step).max(MIN_SIMULATED_NM);
            let last = ((hi / step).ceil() * step).min(MAX_SIMULATED_NM);
            nodes.push(first);
            let mut x = (first / step).floor() * step + step;
            while x < last {
                nodes.push(x);
                x += step;
            }
            nodes.push(last);
            start = i;
        }
    }
    nodes.sort_by(f64::total_cmp);
    nodes.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    let max_vza = ((max_view_zenith_deg / fid.lut_view_step_deg).ceil().max(1.0) * fid.lut_view_step_deg)
        .min(crate::ranges::GEOMETRY_VIEW_ZENITH_DEG.hi);
    LutAxes::covering(nodes, sun_zenith_deg, max_vza, (1.0, fid.lut_view_step_deg, 30.0))
}
