//! What tests and the bench read of the app, and the switches they set.

use super::{Library, ShoalApp, explore};

impl ShoalApp {
    /// Inject `fault` into A's runs (tests of the failure path); `None` removes it.
    pub fn inject_fault(&mut self, fault: Option<crate::engine::Fault>) {
        self.ui.fault = fault;
    }

    /// Use `library` for presets (tests).
    pub fn set_library(&mut self, library: Library) {
        self.listing.reread(&library);
        self.library = library;
    }

    /// The sweep and cost windows' state.
    #[must_use]
    pub fn explore(&self) -> &explore::Explore {
        &self.ui.explore
    }

    /// The inline message of a refused instrument value, if one is shown.
    #[must_use]
    pub fn refused_value(&self) -> Option<&str> {
        self.ui.param_error.as_ref().map(|(_, m)| m.as_str())
    }

    /// The last error shown to the user, if any.
    #[must_use]
    pub fn error(&self) -> Option<&str> {
        self.ui.error.as_deref()
    }

    /// Map panels on screen (truth, A, B, A − B).
    #[must_use]
    pub fn map_panels(&self) -> usize {
        self.images.panel_count()
    }

    /// The map panels' titles, in display order ("truth", "A", "C − A (A at C's ground points)").
    #[must_use]
    pub fn panel_titles(&self) -> Vec<String> {
        self.images.titles()
    }

    /// The histogram and scatter data on display.
    #[must_use]
    pub fn plot_data(&self) -> Option<&super::plot_data::PlotData> {
        self.images.plot()
    }

    /// Where the histogram, scatter and SNR plots were drawn in the last frame.
    #[must_use]
    pub fn plot_rects(&self) -> &[egui::Rect] {
        &self.ui.plot_rects
    }

    /// Is an export being written?
    #[must_use]
    pub fn exporting(&self) -> bool {
        self.ui.exports.running > 0
    }

    /// Where the maps and their colour bars were drawn in the last frame.
    #[must_use]
    pub fn map_rects(&self) -> &[egui::Rect] {
        &self.ui.map_rects
    }

    /// Median time the UI thread spent drawing each of the last frames, ms.
    #[must_use]
    pub fn median_frame_ms(&self) -> Option<f32> {
        let mut v = self.ui.frame_times_ms.clone();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f32::total_cmp);
        Some(v[v.len() / 2])
    }
}
