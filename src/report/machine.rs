//! The machine results were made on, the build and the time, for the review pack's provenance
//! (timings mean little without them). Read from Linux's /proc and /etc/os-release; "unknown"
//! elsewhere.

use serde::{Deserialize, Serialize};

/// What the machine is.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// CPU model name.
    pub cpu: String,
    /// Logical cores available to this process.
    pub cores: usize,
    /// Memory, GiB.
    pub memory_gib: f64,
    /// Operating system and kernel.
    pub os: String,
}

fn field<'a>(text: &'a str, key: &str, sep: char) -> Option<&'a str> {
    text.lines().find_map(|l| l.split_once(sep).filter(|(k, _)| k.trim() == key).map(|(_, v)| v.trim()))
}

impl Machine {
    /// This machine.
    #[must_use]
    pub fn this() -> Self {
        let read = |p: &str| std::fs::read_to_string(p).unwrap_or_default();
        let cpuinfo = read("/proc/cpuinfo");
        let meminfo = read("/proc/meminfo");
        let os_release = read("/etc/os-release");
        let kib: f64 = field(&meminfo, "MemTotal", ':')
            .and_then(|v| v.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or(0.0);
        let os = field(&os_release, "PRETTY_NAME", '=')
            .map_or_else(|| std::env::consts::OS.to_string(), |v| v.trim_matches('"').to_string());
        let kernel = read("/proc/sys/kernel/osrelease");
        Self {
            cpu: field(&cpuinfo, "model name", ':').unwrap_or("unknown").to_string(),
            cores: std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get),
            memory_gib: kib / (1024.0 * 1024.0),
            os: if kernel.trim().is_empty() { os } else { format!("{os}, Linux {}", kernel.trim()) },
        }
    }

    /// One line: "AMD EPYC 7B13, 2 cores, 23.5 GiB, Debian GNU/Linux 12 (bookworm), Linux 6.1".
    #[must_use]
    pub fn line(&self) -> String {
        format!("{}, {} logical cores, {:.1} GiB, {}", self.cpu, self.cores, self.memory_gib, self.os)
    }
}

/// The git commit this binary was built from (`src/build.rs`), or "unknown".
#[must_use]
pub fn commit() -> &'static str {
    option_env!("SHOAL_GIT_COMMIT").unwrap_or("unknown")
}

/// Now, UTC, as `YYYY-MM-DDTHH:MM:SSZ` (civil-from-days: Hinnant, "chrono-Compatible Low-Level
/// Date Algorithms").
#[must_use]
pub fn now_utc() -> String {
    utc_text(std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs()))
}

/// `secs` after the Unix epoch as `YYYY-MM-DDTHH:MM:SSZ`.
pub(super) fn utc_text(secs: u64) -> String {
    let (days, rem) = ((secs / 86_400) as i64, secs % 86_400);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z", rem / 3600, rem % 3600 / 60, rem % 60)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_read_from_proc_style_text() {
        let text = "processor\t: 0\nmodel name\t: AMD EPYC 7B13\n";
        assert_eq!(field(text, "model name", ':'), Some("AMD EPYC 7B13"));
        assert_eq!(field("PRETTY_NAME=\"Debian 12\"\n", "PRETTY_NAME", '='), Some("\"Debian 12\""));
        let m = Machine::this();
        assert!(m.cores >= 1 && !m.line().is_empty());
    }
}
