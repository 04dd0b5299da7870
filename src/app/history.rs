//! Undo and redo of the designs under review (the list of instruments) and the scene.
//!
//! The history watches the state once a frame, after the panels have changed it, instead of
//! asking every widget to report its edits: whatever changed the design (a slider, a typed
//! value, a loaded preset, a loaded study) is one step. A step is taken when the design has
//! settled — no pointer button held — so a slider drag of a hundred frames undoes as one step.
//! Ctrl+Z / Ctrl+Shift+Z (and Ctrl+Y) reach it when no text field has the keyboard, which then
//! keeps its own text undo.

use super::model::{AppState, Slot, label};
use crate::scene::SceneSpec;

/// What undo restores.
#[derive(Debug, Clone, PartialEq)]
struct Design {
    designs: Vec<Slot>,
    scene: SceneSpec,
    scene_name: String,
    scene_seed: u64,
}

impl Design {
    fn of(state: &AppState) -> Self {
        Self {
            designs: state.designs.clone(),
            scene: state.scene.clone(),
            scene_name: state.scene_name.clone(),
            scene_seed: state.scene_seed,
        }
    }

    /// Is `state`'s design this one? (Compared in place: the history looks every frame, and
    /// should not copy the scene to do it.)
    fn matches(&self, state: &AppState) -> bool {
        self.designs == state.designs
            && self.scene == state.scene
            && self.scene_name == state.scene_name
            && self.scene_seed == state.scene_seed
    }

    fn restore(self, state: &mut AppState) {
        state.designs = self.designs;
        state.scene = self.scene;
        state.scene_name = self.scene_name;
        state.scene_seed = self.scene_seed;
        // The design edited, the maps' list and the pair may name a design no longer there.
        state.settle();
    }

    /// What differs from `other`, in words, for the Undo button's tooltip.
    fn describe_change(&self, other: &Self) -> String {
        let mut what = Vec::new();
        if self.designs.len() != other.designs.len() {
            what.push(format!("designs {} → {}", self.designs.len(), other.designs.len()));
        }
        for (i, (x, y)) in self.designs.iter().zip(&other.designs).enumerate() {
            let name = label(i);
            if x.preset != y.preset {
                what.push(format!("{name} → {}", y.preset));
            } else if x.spec != y.spec {
                what.push(format!("{name}'s parameters"));
            }
        }
        if self.scene_name != other.scene_name {
            what.push(format!("scene → {}", other.scene_name));
        } else if self.scene != other.scene || self.scene_seed != other.scene_seed {
            what.push("the scene".into());
        }
        what.join(", ")
    }
}

/// Designs to go back and forward to.
#[derive(Debug, Default)]
pub struct History {
    undo: Vec<Design>,
    redo: Vec<Design>,
    /// The design as last settled (`None` before the first frame).
    settled: Option<Design>,
}

impl History {
    /// Steps kept; the oldest go first.
    pub const DEPTH: usize = 100;

    /// Once a frame, after the panels: a settled design that differs from the last one becomes a
    /// step. `pointer_down`: a drag may still be going on, so wait.
    pub fn observe(&mut self, state: &AppState, pointer_down: bool) {
        let Some(settled) = &self.settled else {
            self.settled = Some(Design::of(state));
            return;
        };
        if pointer_down {
            return;
        }
        if !settled.matches(state) {
            let before = self.settled.replace(Design::of(state));
            self.undo.extend(before);
            if self.undo.len() > Self::DEPTH {
                self.undo.remove(0);
            }
            self.redo.clear();
        }
    }

    /// Go back one step; false when there is none.
    pub fn undo(&mut self, state: &mut AppState) -> bool {
        // An unsettled change (mid-drag) is a step of its own first.
        self.observe(state, false);
        let Some(previous) = self.undo.pop() else { return false };
        self.redo.push(Design::of(state));
        self.settled = Some(previous.clone());
        previous.restore(state);
        true
    }

    /// Go forward one step; false when there is none.
    pub fn redo(&mut self, state: &mut AppState) -> bool {
        self.observe(state, false);
        let Some(next) = self.redo.pop() else { return false };
        self.undo.push(Design::of(state));
        self.settled = Some(next.clone());
        next.restore(state);
        true
    }

    /// What undo would take back, if anything ("A's parameters").
    #[must_use]
    pub fn undo_text(&self) -> Option<String> {
        Some(self.undo.last()?.describe_change(self.settled.as_ref()?))
    }

    /// What redo would bring back, if anything.
    #[must_use]
    pub fn redo_text(&self) -> Option<String> {
        Some(self.settled.as_ref()?.describe_change(self.redo.last()?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drag_is_one_step_and_undo_redo_walk_it() {
        let mut state = AppState::default();
        let mut h = History::default();
        h.observe(&state, false);
        let start = state.designs[0].spec.aperture_mm;
        // A drag over three frames, pointer held: no step yet.
        for v in [70.0, 80.0, 90.0] {
            state.designs[0].spec.aperture_mm = v;
            h.observe(&state, true);
        }
        assert!(h.undo_text().is_none());
        h.observe(&state, false);
        assert_eq!(h.undo_text().as_deref(), Some("A's parameters"));
        state.designs[1].spec.read_noise_e += 5.0;
        h.observe(&state, false);

        assert!(h.undo(&mut state));
        assert_eq!(state.designs[0].spec.aperture_mm, 90.0, "the last step (B's read noise) went first");
        assert!(h.undo(&mut state));
        assert_eq!(state.designs[0].spec.aperture_mm, start, "the drag undoes as one step");
        assert!(!h.undo(&mut state), "nothing older");
        assert!(h.redo(&mut state));
        assert_eq!(state.designs[0].spec.aperture_mm, 90.0);
        // A new edit drops what could be redone.
        state.designs[0].spec.aperture_mm = 100.0;
        h.observe(&state, false);
        assert!(!h.redo(&mut state));
        assert_eq!(state.designs[0].spec.aperture_mm, 100.0);
    }

    #[test]
    fn an_edit_not_yet_settled_is_undone_too() {
        let mut state = AppState::default();
        let mut h = History::default();
        h.observe(&state, false);
        let start = state.designs[0].spec.exposure_s;
        state.designs[0].spec.exposure_s *= 2.0;
        h.observe(&state, true);
        assert!(h.undo(&mut state));
        assert_eq!(state.designs[0].spec.exposure_s, start);
    }
}
