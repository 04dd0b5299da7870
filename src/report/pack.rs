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
/// `review.json` (listing the figures). Returns the page's path.
pub fn write_pack(data: &ReviewData, figures: &[Figure], out: &Path) -> Result<PathBuf, StudyError> {
    let mut shown = Vec::with_capacity(figures.len());
    for f in figures {
        let png = !f.png.is_empty();
        if png {
            write_bytes(&crate::parse::join_name(&out.join("figures"), "figure", &format!("{}.png", f.name))?, &f.png)?;
        }
        shown.push(PageFigure { name: f.name.clone(), svg: f.svg.clone(), png });
    }
    let mut data = data.clone();
    data.figures = figures.iter().map(|f| f.name.clone()).collect();
    write_bytes(&out.join(REVIEW_JSON), review_json(&data)?.as_bytes())?;
    let index = out.join("index.html");
    write_bytes(&index, page(&data, &shown).as_bytes())?;
    Ok(index)
}

/// The largest `review.json` read (a study of eight designs and many seeds writes well under 1 MB).
const REVIEW_JSON_MAX_BYTES: u64 = 64 << 20;
/// The largest figure PNG read (a 1920 × 1080 slide is a few MB).
const MAX_PNG_BYTES: u64 = 64 << 20;

/// Is `dir` a results directory `shoal report` can read (it has `review.json`)?
#[must_use]
pub fn is_results_dir(dir: &Path) -> bool {
    dir.join(REVIEW_JSON).is_file()
}

/// The review data and figures of a results directory written by `shoal study`: the figures
/// its `review.json` lists, each read from `figures/NAME.svg` (and its PNG when there), in that
/// order. The directory is never listed, so a file planted there is not read; what is read is
/// untrusted and passes [`super::svg::clean`] before it reaches a page. A `review.json` that does
/// not parse, or lists a figure that is missing or not a plain name, is refused naming it.
pub fn load_results(dir: &Path) -> Result<(ReviewData, Vec<Figure>), StudyError> {
    let path = dir.join(REVIEW_JSON);
    let bad =
        |message: String| StudyError::Invalid(crate::parse::FieldError { field: path.display().to_string(), message });
    let text = crate::infile::read_text(&path, REVIEW_JSON_MAX_BYTES)
        .map_err(|e| bad(format!("cannot be read: {}", e.message)))?;
    let data: ReviewData = serde_json::from_str(&text)
        .map_err(|e| bad(format!("{e} (written by another version of Shoal, or changed? rerun `shoal study`)")))?;
    let mut figures = Vec::with_capacity(data.figures.len());
    for name in &data.figures {
        let svg_path = crate::parse::join_name(&dir.join("figures"), "review.json figures", &format!("{name}.svg"))
            .map_err(|e| bad(e.to_string()))?;
        let svg = crate::infile::read_text(&svg_path, super::svg::MAX_SVG_BYTES as u64).map_err(|e| {
            bad(format!(
                "lists the figure `{name}`, but {} cannot be read ({}): an incomplete folder? rerun `shoal study`",
                svg_path.display(),
                e.message
            ))
        })?;
        // The PNG is optional (the page shows the SVG without it): anything but a regular file
        // within the limit is left out, never waited on.
        let png = crate::infile::read(&svg_path.with_extension("png"), MAX_PNG_BYTES).unwrap_or_default();
        figures.push(Figure { name: name.clone(), png, svg });
    }
    Ok((data, figures))
}
