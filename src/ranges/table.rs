//! The ranges as text: each end as written, and the whole table as Markdown.

use super::ALL;

/// A range end as written: plain up to 65 535, powers of ten from 10⁵ as `1e5`.
pub(super) fn number(v: f64) -> String {
    if v.abs() >= 1e5 { format!("{v:e}") } else { format!("{v}") }
}

/// The table as Markdown (`shoal ranges`; docs/MANUAL.md's "Ranges" section).
#[must_use]
pub fn markdown_table() -> String {
    let mut out = String::from("| field | allowed | what |\n|---|---|---|\n");
    for r in ALL {
        out.push_str(&format!("| `{}` | {} | {} |\n", r.path, r.allowed(), r.meaning));
    }
    out
}
