//! What a run may plan to use of this machine: memory and the atmosphere's time. Every run is
//! checked against it before it starts ([`crate::engine::resources`] says what a run will ask
//! for; the raster reader asks before it decodes), so a run that would not fit is refused with
//! one line naming the fields that drive it and what would fit — instead of an allocation failure
//! (an abort) minutes in, or a run that never ends.
//!
//! The budget is `SHOAL_MEMORY_BUDGET` (bytes, or with a suffix: `6G`, `500M`) when set, else a
//! share ([`MEMORY_SHARE`]) of the machine's memory — the smaller of its RAM and a cgroup's limit.
//! The atmosphere's budget is `SHOAL_TIME_BUDGET_S` seconds (default [`DEFAULT_ATMOSPHERE_S`]).

use crate::parse::FieldError;

/// Share of the machine's memory a run may plan to use when no budget is set.
pub const MEMORY_SHARE: f64 = 0.6;
/// Seconds the atmosphere's radiative transfer may be planned to take when no budget is set.
pub const DEFAULT_ATMOSPHERE_S: f64 = 900.0;
/// Bytes per sample of a raster read (f64 per band).
pub const BYTES_PER_RASTER_SAMPLE: f64 = 8.0;

/// One part of a run's demand.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// What it is ("cubes of cubesat (2000 × 1024 pixels × 19 bands)").
    pub what: String,
    /// Bytes.
    pub bytes: f64,
    /// The fields that set its size, as a user would change them.
    pub fields: &'static str,
    /// What makes it smaller.
    pub lever: Lever,
}

/// What makes a part of a run's demand smaller, for the refusal's advice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Lever {
    /// The scene's grid of `width` × `height` cells (bytes ∝ cells).
    SceneGrid {
        /// Cells along x.
        width: usize,
        /// Cells along y.
        height: usize,
    },
    /// The image of `rows` × `columns` pixels simulated at `decimation` (bytes ∝ pixels).
    Image {
        /// Output rows.
        rows: usize,
        /// Output columns.
        columns: usize,
        /// The decimation it is simulated at.
        decimation: usize,
    },
    /// The radiative transfer's layers (bytes ∝ 1 / max_layer_depth).
    Layers,
    /// Files read whole (bytes ∝ their size).
    Files,
}

impl Lever {
    /// The advice for shrinking the part to `share` (0–1) of its bytes.
    fn advice(self, share: f64) -> String {
        let side = share.max(0.0).sqrt();
        match self {
            Self::SceneGrid { width, height } => format!(
                "make the scene at most {} × {} cells (a coarser cell_m over the same area)",
                (width as f64 * side).floor().max(1.0),
                (height as f64 * side).floor().max(1.0)
            ),
            Self::Image { rows, columns, decimation } => format!(
                "simulate at most {} × {} pixels: fidelity.decimation {} or more, or fewer lines and detectors",
                (rows as f64 * side).floor().max(1.0),
                (columns as f64 * side).floor().max(1.0),
                ((decimation as f64) / side.max(1e-9)).ceil()
            ),
            Self::Layers => format!("raise max_layer_depth by {:.1}× or more", 1.0 / share.max(1e-9)),
            Self::Files => format!(
                "give files at most {:.0} % of their size (crop them), or raise SHOAL_MEMORY_BUDGET",
                100.0 * share.max(0.0)
            ),
        }
    }
}

/// What one run (or a study's runs together) will ask for.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Demand {
    /// Memory, by part.
    pub parts: Vec<Part>,
    /// Planned seconds of radiative transfer.
    pub atmosphere_s: f64,
}

impl Demand {
    /// Total bytes.
    #[must_use]
    pub fn bytes(&self) -> f64 {
        self.parts.iter().map(|p| p.bytes).sum()
    }
}

/// How much a run may plan to use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MachineBudget {
    /// Bytes of memory.
    pub memory_bytes: f64,
    /// Seconds of radiative transfer.
    pub atmosphere_s: f64,
}

/// `6G`, `500M`, `2048K` or plain bytes.
fn parse_bytes(text: &str) -> Option<f64> {
    let t = text.trim();
    let (num, scale) = match t.char_indices().last()? {
        (i, 'K' | 'k') => (&t[..i], 1024.0),
        (i, 'M' | 'm') => (&t[..i], 1024.0 * 1024.0),
        (i, 'G' | 'g') => (&t[..i], 1024.0 * 1024.0 * 1024.0),
        (i, 'T' | 't') => (&t[..i], 1024.0_f64.powi(4)),
        _ => (t, 1.0),
    };
    num.trim().parse::<f64>().ok().map(|v| v * scale).filter(|v| v.is_finite() && *v > 0.0)
}

/// The most memory this process has held resident so far, bytes (Linux's `VmHWM`; `None`
/// elsewhere): what a run reports beside its plan.
#[must_use]
pub fn peak_resident_bytes() -> Option<f64> {
    std::fs::read_to_string("/proc/self/status").ok().and_then(|t| {
        t.lines()
            .find_map(|l| l.strip_prefix("VmHWM:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
            .map(|kb| kb * 1024.0)
    })
}

/// The machine's memory, bytes: the smaller of its RAM and this process's cgroup limit (Linux);
/// `None` when neither can be read.
#[must_use]
pub fn machine_memory_bytes() -> Option<f64> {
    let ram = std::fs::read_to_string("/proc/meminfo").ok().and_then(|t| {
        t.lines()
            .find_map(|l| l.strip_prefix("MemTotal:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
            .map(|kb| kb * 1024.0)
    });
    let cgroup = ["/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"]
        .iter()
        .find_map(|p| std::fs::read_to_string(p).ok())
        .and_then(|t| t.trim().parse::<f64>().ok());
    match (ram, cgroup) {
        (Some(r), Some(c)) => Some(r.min(c)),
        (r, c) => r.or(c),
    }
}

impl MachineBudget {
    /// The budget from `SHOAL_MEMORY_BUDGET` and `SHOAL_TIME_BUDGET_S`, or the defaults; a value
    /// that does not read is an error naming the variable.
    pub fn from_env() -> Result<Self, String> {
        let memory_bytes = match std::env::var("SHOAL_MEMORY_BUDGET") {
            Ok(v) if !v.trim().is_empty() => parse_bytes(&v).ok_or_else(|| {
                format!("SHOAL_MEMORY_BUDGET=`{v}` is not a size (bytes, or a number with K, M, G or T)")
            })?,
            _ => machine_memory_bytes().map_or(8.0 * 1024.0_f64.powi(3), |m| m * MEMORY_SHARE),
        };
        let atmosphere_s = match std::env::var("SHOAL_TIME_BUDGET_S") {
            Ok(v) if !v.trim().is_empty() => v
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|s| s.is_finite() && *s > 0.0)
                .ok_or_else(|| format!("SHOAL_TIME_BUDGET_S=`{v}` is not a positive number of seconds"))?,
            _ => DEFAULT_ATMOSPHERE_S,
        };
        Ok(Self { memory_bytes, atmosphere_s })
    }

    /// Samples of one raster the reader may hold (a quarter of the memory budget, as f64).
    #[must_use]
    pub fn raster_limit_samples(&self) -> usize {
        (self.memory_bytes / 4.0 / BYTES_PER_RASTER_SAMPLE) as usize
    }

    /// `Ok` when `demand` fits; otherwise one message naming what is too large, the fields that
    /// set it and what would fit.
    pub fn check(&self, demand: &Demand) -> Result<(), FieldError> {
        let gb = |b: f64| b / 1024.0_f64.powi(3);
        let total = demand.bytes();
        if total > self.memory_bytes {
            let Some(big) = demand.parts.iter().max_by(|a, b| a.bytes.total_cmp(&b.bytes)) else {
                return Ok(());
            };
            // The share of the largest part that would fit beside the others.
            let share = (self.memory_bytes - (total - big.bytes)) / big.bytes;
            let advice = if share > 0.0 {
                big.lever.advice(share)
            } else {
                "the other parts alone exceed it; raise SHOAL_MEMORY_BUDGET".into()
            };
            return Err(FieldError {
                field: big.fields.into(),
                message: format!(
                    "this run needs about {:.1} GB ({} alone {:.1} GB) but may use {:.1} GB (SHOAL_MEMORY_BUDGET, default {:.0} % of this machine's memory); {advice}",
                    gb(total),
                    big.what,
                    gb(big.bytes),
                    gb(self.memory_bytes),
                    MEMORY_SHARE * 100.0
                ),
            });
        }
        if demand.atmosphere_s > self.atmosphere_s {
            return Err(FieldError {
                field: "scene.atmosphere.accuracy".into(),
                message: format!(
                    "the radiative transfer would take about {:.0} s (layers × streams² × orders × Fourier terms) but may take {:.0} s (SHOAL_TIME_BUDGET_S); lower streams, max_orders or fourier_terms, or raise max_layer_depth",
                    demand.atmosphere_s, self.atmosphere_s
                ),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_with_their_suffixes() {
        assert_eq!(parse_bytes("6G"), Some(6.0 * 1024.0_f64.powi(3)));
        assert_eq!(parse_bytes("500 M"), Some(500.0 * 1024.0 * 1024.0));
        assert_eq!(parse_bytes("1024"), Some(1024.0));
        assert_eq!(parse_bytes("lots"), None);
        assert_eq!(parse_bytes("-1G"), None);
    }
}
