//! The retrievals the app offers, held as the specs the engine runs ([`AppState::retrievals`]):
//! aLMI and SAMBUCA always, then a study's own (a program, QAA). The app selects one by index,
//! edits its settings in place, and switches by the retrieval's name (`alm`, `sambuca`).

use super::model::AppState;
use crate::retrieval::{AlmiSettings, RetrievalSpec, SambucaSettings};

/// aLMI with the eight built-in SIOP sets and SAMBUCA with the scene's set and substrates.
#[must_use]
pub fn built_in(almi: AlmiSettings, sambuca: SambucaSettings) -> Vec<RetrievalSpec> {
    vec![
        RetrievalSpec::Almi { siop_sets: crate::retrieval::sets::default_almi_sets(), settings: almi },
        RetrievalSpec::Sambuca { siop: None, substrates: None, settings: sambuca },
    ]
}

impl AppState {
    /// The retrieval that runs, as the engine runs it (aLMI when none is held).
    #[must_use]
    pub fn retrieval_spec(&self) -> RetrievalSpec {
        self.retrievals
            .get(self.selected_retrieval)
            .or_else(|| self.retrievals.first())
            .cloned()
            .unwrap_or_else(|| built_in(AlmiSettings::default(), SambucaSettings::default()).remove(0))
    }

    /// The retrieval that runs, to edit its settings.
    pub fn retrieval_mut(&mut self) -> Option<&mut RetrievalSpec> {
        self.retrievals.get_mut(self.selected_retrieval)
    }

    /// Is the retrieval called `name` (`alm`, `sambuca`, `qaa`, a program's) the one that runs?
    #[must_use]
    pub fn runs(&self, name: &str) -> bool {
        self.retrievals.get(self.selected_retrieval).is_some_and(|r| r.name() == name)
    }

    /// Run the first retrieval called `name`; false when there is none.
    pub fn select_retrieval(&mut self, name: &str) -> bool {
        match self.retrievals.iter().position(|r| r.name() == name) {
            Some(i) => {
                self.selected_retrieval = i;
                true
            }
            None => false,
        }
    }

    /// Offer a study's retrievals: its aLMI and SAMBUCA (when it has them) in place of the
    /// built-in ones, its others after them; its first selected.
    pub fn offer_study_retrievals(&mut self, study: &[RetrievalSpec]) {
        let mut offered = built_in(AlmiSettings::default(), SambucaSettings::default());
        let (mut almi, mut sambuca) = (false, false);
        for r in study {
            match r {
                RetrievalSpec::Almi { .. } if !almi => (offered[0], almi) = (r.clone(), true),
                RetrievalSpec::Sambuca { .. } if !sambuca => (offered[1], sambuca) = (r.clone(), true),
                other => offered.push(other.clone()),
            }
        }
        self.selected_retrieval = study.first().and_then(|first| offered.iter().position(|r| r == first)).unwrap_or(0);
        self.retrievals = offered;
    }

    /// The retrievals' part of [`AppState::settle`]: a list without aLMI or SAMBUCA gets them
    /// back; the selection in range.
    pub(super) fn settle_retrievals(&mut self) {
        if !matches!(self.retrievals.first(), Some(RetrievalSpec::Almi { .. }))
            || !matches!(self.retrievals.get(1), Some(RetrievalSpec::Sambuca { .. }))
        {
            let study: Vec<RetrievalSpec> = std::mem::take(&mut self.retrievals);
            let selected = study.get(self.selected_retrieval).cloned();
            self.offer_study_retrievals(&study);
            if let Some(i) = selected.and_then(|s| self.retrievals.iter().position(|r| *r == s)) {
                self.selected_retrieval = i;
            }
        }
        if self.selected_retrieval >= self.retrievals.len() {
            self.selected_retrieval = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_study_s_retrievals_are_offered_beside_the_built_in_ones_its_first_selected() {
        let study = crate::study::StudySpec::preset("lake_hume_qaa").unwrap_or_else(|e| panic!("{e}"));
        let s = AppState::from_study(&study, None).unwrap_or_else(|e| panic!("{e}"));
        let names: Vec<&str> = s.retrievals.iter().map(RetrievalSpec::name).collect();
        assert_eq!(names, ["alm", "sambuca", "qaa"]);
        assert!(s.runs("alm"));
        let mut s = s;
        assert!(s.select_retrieval("qaa") && s.runs("qaa"));
        assert!(!s.select_retrieval("oc4"));
        // A list that lost its built-in ones gets them back, the selection kept on its spec.
        s.retrievals.remove(0);
        s.selected_retrieval = 1;
        s.settle();
        assert_eq!(s.retrievals.iter().map(RetrievalSpec::name).collect::<Vec<_>>(), ["alm", "sambuca", "qaa"]);
        assert!(s.runs("qaa"));
    }
}
