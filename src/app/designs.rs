//! The list of designs the app compares: their letters, and adding, removing and reordering them
//! so that every index the state keeps (the design edited, the reference of the parameter table,
//! the designs on the maps, the difference pair) still names the same design afterwards. Each
//! change returns where each old design went ([`Moved`]), so the engine link can move its results
//! with them instead of running them again.

use super::model::{AppState, Slot};

/// The designs the app holds at most: one colour each (`theme::DESIGN`), and a metrics table
/// that still fits a 1920-pixel window (the engine sizes its cache for them).
pub use crate::engine::worker::MAX_DESIGNS;

/// The designs on the maps when a study opens (the rest can be ticked on).
pub const MAPS_AT_OPEN: usize = 4;

/// Design `i`'s letter: A, B, C, …
#[must_use]
pub fn label(i: usize) -> String {
    u8::try_from(i).ok().filter(|k| *k < 26).map_or_else(|| format!("#{}", i + 1), |k| char::from(b'A' + k).to_string())
}

/// Where each design went: `Moved[old] = Some(new)`, or `None` if it was removed.
pub type Moved = Vec<Option<usize>>;

impl AppState {
    /// Bring the state to its invariants (an older session's fields were moved in by
    /// `migrate`): at least one design and at most [`MAX_DESIGNS`]; every index in range, the maps' list without repeats, the pair two different designs when there are two.
    pub fn settle(&mut self) {
        self.settle_retrievals();
        if self.designs.is_empty() {
            self.designs = AppState::default().designs;
        }
        self.designs.truncate(MAX_DESIGNS);
        let last = self.designs.len() - 1;
        self.editing = self.editing.min(last);
        self.reference = self.reference.min(last);
        let mut seen = Vec::new();
        self.on_maps.retain(|&i| {
            i <= last && !seen.contains(&i) && {
                seen.push(i);
                true
            }
        });
        if self.on_maps.is_empty() {
            self.on_maps = (0..=last.min(1)).collect();
        }
        self.pair = self.pair.map(|i| i.min(last));
        if self.pair[0] == self.pair[1] && last > 0 {
            self.pair[1] = usize::from(self.pair[0] == 0);
        }
        // A retrieval's own product that no variable is (a damaged session).
        if !self.product.exists() {
            self.product = super::model::ProductKind::Chl;
        }
    }

    /// Add `slot` as the last design, on the maps and in the editor; `None` at [`MAX_DESIGNS`].
    pub fn add_design(&mut self, slot: Slot) -> Option<Moved> {
        if self.designs.len() >= MAX_DESIGNS {
            return None;
        }
        let moved = (0..self.designs.len()).map(Some).collect();
        self.designs.push(slot);
        let new = self.designs.len() - 1;
        self.on_maps.push(new);
        self.editing = new;
        Some(moved)
    }

    /// Remove design `i`; `None` for the last design left, or no such design.
    pub fn remove_design(&mut self, i: usize) -> Option<Moved> {
        if self.designs.len() <= 1 || i >= self.designs.len() {
            return None;
        }
        let moved: Moved = (0..self.designs.len())
            .map(|k| match k.cmp(&i) {
                std::cmp::Ordering::Less => Some(k),
                std::cmp::Ordering::Equal => None,
                std::cmp::Ordering::Greater => Some(k - 1),
            })
            .collect();
        self.designs.remove(i);
        let fallback = i.min(self.designs.len() - 1);
        let to = |k: usize| moved[k].unwrap_or(fallback);
        (self.editing, self.reference) = (to(self.editing), moved[self.reference].unwrap_or(0));
        self.on_maps = self.on_maps.iter().filter_map(|&k| moved.get(k).copied().flatten()).collect();
        let [p, q] = self.pair;
        self.pair = [moved[p], moved[q]].map(|m| m.unwrap_or(usize::MAX));
        if self.pair.contains(&usize::MAX) {
            let kept = self.pair.into_iter().find(|&k| k != usize::MAX).unwrap_or(0);
            self.pair = [kept, kept];
        }
        self.settle();
        Some(moved)
    }

    /// Swap design `i` with the one before it (`earlier`) or after it; `None` at either end.
    pub fn move_design(&mut self, i: usize, earlier: bool) -> Option<Moved> {
        let j = if earlier { i.checked_sub(1)? } else { i + 1 };
        if j >= self.designs.len() || i >= self.designs.len() {
            return None;
        }
        self.designs.swap(i, j);
        let moved: Moved = (0..self.designs.len())
            .map(|k| {
                Some(if k == i {
                    j
                } else if k == j {
                    i
                } else {
                    k
                })
            })
            .collect();
        let to = |k: usize| moved[k].unwrap_or(k);
        (self.editing, self.reference) = (to(self.editing), to(self.reference));
        self.on_maps = self.on_maps.iter().map(|&k| to(k)).collect();
        self.on_maps.sort_unstable();
        self.pair = self.pair.map(to);
        Some(moved)
    }

    /// Design `i`'s letter and preset ("C: hyperspectral").
    #[must_use]
    pub fn design_name(&self, i: usize) -> String {
        self.designs.get(i).map_or_else(|| label(i), |s| format!("{}: {}", label(i), s.preset))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::InstrumentSpec;

    fn four() -> AppState {
        let mut s = AppState::default();
        for name in ["nominal", "hyperspectral"] {
            let spec = InstrumentSpec::preset(name).unwrap_or_else(|e| panic!("{e}"));
            assert!(s.add_design(Slot::new(name, spec)).is_some());
        }
        s
    }

    #[test]
    fn letters_run_a_to_z_then_number() {
        assert_eq!([0, 1, 25].map(label), ["A", "B", "Z"]);
        assert_eq!(label(26), "#27");
    }

    #[test]
    fn adding_removing_and_moving_keep_every_index_on_its_design() {
        let mut s = four();
        assert_eq!(s.designs.len(), 4);
        assert_eq!((s.editing, s.on_maps.as_slice()), (3, &[0, 1, 2, 3][..]), "a new design is edited and mapped");
        s.reference = 2;
        s.pair = [1, 3];
        // Move C (nominal) first: it stays the reference, wherever it goes.
        assert_eq!(s.move_design(2, true), Some(vec![Some(0), Some(2), Some(1), Some(3)]));
        assert_eq!(s.move_design(1, true), Some(vec![Some(1), Some(0), Some(2), Some(3)]));
        assert_eq!(s.designs[0].preset, "nominal");
        assert_eq!((s.reference, s.pair, s.editing), (0, [2, 3], 3));
        assert_eq!(s.move_design(0, true), None, "nothing before the first");
        // Remove the smallsat (now at 2): the pair keeps the hyperspectral one with another.
        assert_eq!(s.remove_design(2), Some(vec![Some(0), Some(1), None, Some(2)]));
        assert_eq!(
            s.designs.iter().map(|d| d.preset.as_str()).collect::<Vec<_>>(),
            ["nominal", "cubesat", "hyperspectral"]
        );
        assert_eq!((s.editing, s.on_maps.as_slice()), (2, &[0, 1, 2][..]));
        assert!(s.pair.contains(&2) && s.pair[0] != s.pair[1], "{:?}", s.pair);
        while s.designs.len() > 1 {
            assert!(s.remove_design(0).is_some());
        }
        assert_eq!(s.remove_design(0), None, "the last design stays");
        assert_eq!((s.editing, s.reference, s.pair, s.on_maps.as_slice()), (0, 0, [0, 0], &[0][..]));
    }

    #[test]
    fn no_more_than_the_maximum_and_settle_repairs_any_index() {
        let mut s = four();
        while s.add_design(s.designs[0].clone()).is_some() {}
        assert_eq!(s.designs.len(), MAX_DESIGNS);
        s.editing = 40;
        s.on_maps = vec![9, 1, 1, 0];
        s.pair = [5, 5];
        s.designs.truncate(3);
        s.settle();
        assert_eq!((s.editing, s.on_maps.as_slice(), s.pair), (2, &[1, 0][..], [2, 0]));
    }
}
