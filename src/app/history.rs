//! Undo and redo of the designs under review (the list of instruments) and the scene.
//!
//! The history watches the state once a frame, after the panels have changed it, instead of
//! asking every widget to report its edits: whatever changed the design (a slider, a typed
//! value, a loaded preset, a loaded study) is one step. A step is taken when the design has
//! settled — no pointer button held — so a slider drag of a hundred frames undoes as one step.
//! Ctrl+Z / Ctrl+Shift+Z (and Ctrl+Y) reach it when no text field has the keyboard, which then
//! keeps its own text undo.

use super::designs::Moved;
use super::model::{AppState, Slot, label};
use crate::scene::SceneSpec;

/// What undo restores.
#[derive(Debug, Clone, PartialEq)]
struct Design {
    designs: Vec<Slot>,
    scene: SceneSpec,
    scene_name: String,
    scene_seed: u64,
    /// How the designs were shown: on the maps, the pair, the reference, the one edited. Not a
    /// step of its own (a tick on "map" is not undone), but restored with the designs, so an
    /// undone removal brings its design back on the maps.
    view: (Vec<usize>, [usize; 2], usize, usize),
}

impl Design {
    fn of(state: &AppState) -> Self {
        Self {
            designs: state.designs.clone(),
            scene: state.scene.clone(),
            scene_name: state.scene_name.clone(),
            scene_seed: state.scene_seed,
            view: (state.on_maps.clone(), state.pair, state.reference, state.editing),
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

    /// Put this design back; its view too when the designs were added, removed or moved
    /// (`regrouped`), else the view stays as it is now (a map tick is not undone by undoing an
    /// aperture).
    fn restore(self, state: &mut AppState, regrouped: bool) {
        state.designs = self.designs;
        state.scene = self.scene;
        state.scene_name = self.scene_name;
        state.scene_seed = self.scene_seed;
        if regrouped {
            (state.on_maps, state.pair, state.reference, state.editing) = self.view;
        }
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
        if settled.matches(state) {
            // The view moves without making a step; the step remembers it as it was last.
            if let Some(s) = self.settled.as_mut()
                && (s.view.0 != state.on_maps
                    || (s.view.1, s.view.2, s.view.3) != (state.pair, state.reference, state.editing))
            {
                s.view = (state.on_maps.clone(), state.pair, state.reference, state.editing);
            }
        } else {
            let before = self.settled.replace(Design::of(state));
            self.undo.extend(before);
            if self.undo.len() > Self::DEPTH {
                self.undo.remove(0);
            }
            self.redo.clear();
        }
    }

    /// Go back one step: where each design went (for the engine link to move its results with
    /// it, [`moved`]), or `None` when there is no step.
    pub fn undo(&mut self, state: &mut AppState) -> Option<Moved> {
        // An unsettled change (mid-drag) is a step of its own first.
        self.observe(state, false);
        let previous = self.undo.pop()?;
        self.redo.push(Design::of(state));
        self.settled = Some(previous.clone());
        let moved = moved(&state.designs, &previous.designs);
        previous.restore(state, !identity(&moved));
        Some(moved)
    }

    /// Go forward one step, as [`Self::undo`].
    pub fn redo(&mut self, state: &mut AppState) -> Option<Moved> {
        self.observe(state, false);
        let next = self.redo.pop()?;
        self.undo.push(Design::of(state));
        self.settled = Some(next.clone());
        let moved = moved(&state.designs, &next.designs);
        next.restore(state, !identity(&moved));
        Some(moved)
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

/// Where each of the designs `before` is among `after`: the same design (equal slot) wherever it
/// went, else the same place if that holds a changed design; `None` for one that is gone. An
/// undone removal so moves the designs after it back without running them again.
#[must_use]
pub fn moved(before: &[Slot], after: &[Slot]) -> Moved {
    let mut taken = vec![false; after.len()];
    let mut out: Moved = before
        .iter()
        .map(|slot| {
            let k = (0..after.len()).find(|&k| !taken[k] && after[k] == *slot)?;
            taken[k] = true;
            Some(k)
        })
        .collect();
    for (i, m) in out.iter_mut().enumerate() {
        if m.is_none() && i < after.len() && !taken[i] && !after.iter().any(|s| *s == before[i]) {
            taken[i] = true;
            *m = Some(i);
        }
    }
    out
}

/// Did every design stay where it was (none added, removed or moved)?
fn identity(moved: &Moved) -> bool {
    moved.iter().enumerate().all(|(i, m)| *m == Some(i))
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

        assert!(h.undo(&mut state).is_some());
        assert_eq!(state.designs[0].spec.aperture_mm, 90.0, "the last step (B's read noise) went first");
        assert!(h.undo(&mut state).is_some());
        assert_eq!(state.designs[0].spec.aperture_mm, start, "the drag undoes as one step");
        assert!(h.undo(&mut state).is_none(), "nothing older");
        assert!(h.redo(&mut state).is_some());
        assert_eq!(state.designs[0].spec.aperture_mm, 90.0);
        // A new edit drops what could be redone.
        state.designs[0].spec.aperture_mm = 100.0;
        h.observe(&state, false);
        assert!(h.redo(&mut state).is_none());
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
        assert!(h.undo(&mut state).is_some());
        assert_eq!(state.designs[0].spec.exposure_s, start);
    }

    #[test]
    fn an_undone_removal_moves_the_others_back_and_restores_the_map_tick() {
        let mut state = AppState::default();
        for name in ["nominal", "hyperspectral"] {
            let spec = crate::instrument::InstrumentSpec::preset(name).unwrap_or_else(|e| panic!("{e}"));
            assert!(state.add_design(Slot::new(name, spec)).is_some());
        }
        state.on_maps = vec![0, 2, 3];
        let mut h = History::default();
        h.observe(&state, false);
        assert!(state.remove_design(1).is_some());
        h.observe(&state, false);
        assert_eq!(state.on_maps, [0, 1, 2]);
        // Back: B returns to its place, C and D move from 1 and 2 back to 2 and 3 (their results
        // with them), and the maps are as they were.
        assert_eq!(h.undo(&mut state), Some(vec![Some(0), Some(2), Some(3)]));
        assert_eq!(state.designs[1].preset, "smallsat");
        assert_eq!(state.on_maps, [0, 2, 3], "B was not on the maps; C and D were");
        assert_eq!(h.redo(&mut state), Some(vec![Some(0), None, Some(1), Some(2)]));
        // An edit undone leaves the view as it is now: a tick made since is not taken back.
        state.designs[0].spec.aperture_mm = 90.0;
        h.observe(&state, false);
        state.on_maps = vec![0];
        assert_eq!(h.undo(&mut state), Some(vec![Some(0), Some(1), Some(2)]));
        assert_eq!(state.on_maps, [0], "the map tick was undone with the aperture");
        // A changed design keeps its place (its result shown, greyed, until the new one).
        let before = state.designs.clone();
        state.designs[1].spec.aperture_mm *= 2.0;
        assert_eq!(moved(&before, &state.designs), vec![Some(0), Some(1), Some(2)]);
    }
}
