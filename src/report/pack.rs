//! Writing the review pack (`index.html`, its figures as PNG, and `review.json`) and reading a
//! results directory back into one.

use std::path::{Path, PathBuf};

use super::ReviewData;
use super::html::{PageFigure, page};
use crate::study::{Figure, StudyError, write_bytes};

/// The file `shoal study` writes beside its tables so that `shoal report DIR` can rebuild the
/// page without rerunning.
pub const REVIEW_JSON: &str = "review.json";

fn io(e: impl std::fmt::Display) -> StudyError {
    StudyError::Io(e.to_string())
}

/// `review.json` text of `data`.
pub fn review_json(data: &ReviewData) -> Result<String, StudyError> {
    serde_json::to_string_pretty(data).map_err(|e| io(format!("review.json: {e}")))
}

/// Write the pack into `out`: `index.html` (self-contained), `figures/NAME.png` and
/// `review.json`. Returns the page's path.
pub fn write_pack(data: &ReviewData, figures: &[Figure], out: &Path) -> Result<PathBuf, StudyError> {
    let mut shown = Vec::with_capacity(figures.len());
    for f in figures {
        let png = !f.png.is_empty();
        if png {
            write_bytes(&out.join("figures").join(format!("{}.png", f.name)), &f.png)?;
        }
        shown.push(PageFigure { name: f.name.clone(), svg: f.svg.clone(), png });
    }
    write_bytes(&out.join(REVIEW_JSON), review_json(data)?.as_bytes())?;
    let index = out.join("index.html");
    write_bytes(&index, page(data, &shown).as_bytes())?;
    Ok(index)
}

/// Is `dir` a results directory `shoal report` can read (it has `review.json`)?
#[must_use]
pub fn is_results_dir(dir: &Path) -> bool {
    dir.join(REVIEW_JSON).is_file()
}

/// The review data and figures of a results directory written by `shoal study` (figures in
/// name order; a figure's PNG is read when it is there).
pub fn load_results(dir: &Path) -> Result<(ReviewData, Vec<Figure>), StudyError> {
    let path = dir.join(REVIEW_JSON);
    let text = std::fs::read_to_string(&path).map_err(|e| io(format!("cannot read {}: {e}", path.display())))?;
    let data: ReviewData = serde_json::from_str(&text).map_err(|e| {
        io(format!("{}: {e} (written by another version of Shoal? rerun `shoal study`)", path.display()))
    })?;
    let mut figures = Vec::new();
    let fig_dir = dir.join("figures");
    if let Ok(entries) = std::fs::read_dir(&fig_dir) {
        let mut svgs: Vec<PathBuf> = entries
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "svg"))
            .collect();
        svgs.sort();
        for svg_path in svgs {
            let name = svg_path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            let svg = std::fs::read_to_string(&svg_path)
                .map_err(|e| io(format!("cannot read {}: {e}", svg_path.display())))?;
            let png = std::fs::read(svg_path.with_extension("png")).unwrap_or_default();
            figures.push(Figure { name, png, svg });
        }
    }
    Ok((data, figures))
}
