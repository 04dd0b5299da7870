//! Sessions saved by an older Shoal, brought up to date in typed steps ([`crate::schema`]'s
//! `RESHAPES`). A session is read twice from the same text: as today's [`AppState`] (which
//! ignores fields it no longer has) and as [`Legacy`], the fields older formats wrote and today's
//! never does; each step then moves what it finds into the state. `AppState` itself carries no
//! legacy field, and a session saved again is today's format.

use serde::Deserialize;

use super::model::{AppState, Slot};
use super::retrievals::built_in;
use crate::retrieval::{AlmiSettings, RetrievalSpec, SambucaSettings};

/// Sessions saved before the app held a list of designs named the instrument being edited
/// `editing_instrument: A` or `B`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
enum LegacyAb {
    /// Instrument A (design 0).
    A,
    /// Instrument B (design 1).
    B,
}

/// The retrieval a session saved before [`AppState::retrievals`] ran (`retrieval: Almi`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
enum LegacyRetrieval {
    /// aLMI.
    Almi,
    /// SAMBUCA.
    Sambuca,
    /// The study's external program.
    External,
}

/// `Some` of a value stored bare (`a: (preset: …)`, not `a: Some((…))`).
fn bare_some<'de, D: serde::Deserializer<'de>, T: Deserialize<'de>>(d: D) -> Result<Option<T>, D::Error> {
    T::deserialize(d).map(Some)
}

/// The fields of older session formats (every other field of the text is skipped).
#[derive(Default, Deserialize)]
#[serde(rename = "AppState", default)]
pub(super) struct Legacy {
    /// Version 3 made `designs` a list: instrument A was the field `a`.
    #[serde(deserialize_with = "bare_some")]
    a: Option<Slot>,
    /// Instrument B.
    #[serde(deserialize_with = "bare_some")]
    b: Option<Slot>,
    /// The instrument being edited.
    #[serde(deserialize_with = "bare_some")]
    editing_instrument: Option<LegacyAb>,
    /// Version 4 made the retrievals a list: the one that ran was `retrieval`, with its settings
    /// in `almi` and `sambuca` and the study's program in `external`.
    #[serde(deserialize_with = "bare_some")]
    retrieval: Option<LegacyRetrieval>,
    /// aLMI's settings.
    #[serde(deserialize_with = "bare_some")]
    almi: Option<AlmiSettings>,
    /// SAMBUCA's settings.
    #[serde(deserialize_with = "bare_some")]
    sambuca: Option<SambucaSettings>,
    /// The study's program.
    external: Option<crate::retrieval::external::ExternalSpec>,
}

impl AppState {
    /// A session's text, as any Shoal saved it, as today's state: the fields renamed since
    /// ([`crate::schema::migrate`]), then the steps below.
    ///
    /// # Errors
    /// A session from a newer Shoal, or a text that is not a session (with line and column).
    pub fn from_session_text(text: &str) -> Result<Self, String> {
        crate::schema::migrate(text).and_then(|t| read_session(&t))
    }
}

/// A session's text (already through [`crate::schema::migrate`]'s renames) as today's state.
fn read_session(text: &str) -> Result<AppState, String> {
    let mut state = ron::from_str::<AppState>(text).map_err(|e| crate::parse::describe(text, &e))?;
    let legacy = ron::from_str::<Legacy>(text).map_err(|e| crate::parse::describe(text, &e))?;
    legacy.bring_up_to_date(&mut state);
    state.schema_version = crate::schema::VERSION;
    Ok(state)
}

impl Legacy {
    /// Each step in the order the formats changed.
    fn bring_up_to_date(self, state: &mut AppState) {
        let Self { a, b, editing_instrument, retrieval, almi, sambuca, external } = self;
        // Version 3: A and B became the first two designs.
        if let Some(a) = a {
            let b = b.unwrap_or_else(|| a.clone());
            state.designs = vec![a, b];
            state.editing = usize::from(editing_instrument == Some(LegacyAb::B));
            (state.reference, state.on_maps, state.pair) = (0, vec![0, 1], [0, 1]);
        }
        // Version 4: aLMI's and SAMBUCA's settings and the study's program became specs, the one
        // that ran the selection.
        if retrieval.is_some() || almi.is_some() || sambuca.is_some() || external.is_some() {
            state.retrievals = built_in(almi.unwrap_or_default(), sambuca.unwrap_or_default());
            state.retrievals.extend(external.map(RetrievalSpec::External));
            state.selected_retrieval = match retrieval {
                Some(LegacyRetrieval::Sambuca) => 1,
                Some(LegacyRetrieval::External) if state.retrievals.len() > 2 => 2,
                _ => 0,
            };
        }
        state.settle();
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_session_from_before_the_list_reads_as_a_and_b() {
        // The session as the app saved it with fields `a`, `b` and `editing_instrument`.
        let mut old = AppState::default();
        old.designs[1].spec.aperture_mm = 123.0;
        let text = ron::to_string(&old).unwrap();
        let designs = text.find("designs:").unwrap();
        let a = ron::to_string(&old.designs[0]).unwrap();
        let b = ron::to_string(&old.designs[1]).unwrap();
        let end = designs + text[designs..].find("],linked").unwrap() + 2;
        let legacy = format!("{}a:{a},b:{b},editing_instrument:B,{}", &text[..designs], &text[end..]);
        let read = read_session(&legacy).unwrap();
        assert_eq!(read.designs.len(), 2);
        assert_eq!(read.designs[1].spec.aperture_mm, 123.0);
        assert_eq!(read.editing, 1);
        assert!(!ron::to_string(&read).unwrap().contains("editing_instrument"));
    }

    #[test]
    fn a_session_from_before_the_retrieval_list_selects_what_it_ran() {
        let text = ron::to_string(&AppState::default()).unwrap();
        let at = text.find("retrievals:").unwrap();
        let legacy = format!("{}retrieval:Sambuca,sambuca:(max_iterations:7),{}", &text[..at], &text[at..]);
        let read = read_session(&legacy).unwrap();
        assert_eq!(read.retrieval_spec().name(), "sambuca");
        let RetrievalSpec::Sambuca { settings, .. } = read.retrieval_spec() else { panic!("not SAMBUCA") };
        assert_eq!(settings.max_iterations, 7);
        assert!(!ron::to_string(&read).unwrap().contains(",retrieval:"));
        let today = read_session(&text).unwrap();
        assert_eq!(today.retrievals, AppState::default().retrievals, "today's session is read as it is");
    }
}
