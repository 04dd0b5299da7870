//! The machine results were made on, for the review pack's provenance (timings mean little
//! without it). Read from Linux's /proc and /etc/os-release; "unknown" elsewhere.

use serde::{Deserialize, Serialize};

/// What the machine is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
