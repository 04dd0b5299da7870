//! What the maps show: the product and the arrangement of the panels (saved with the session).

use serde::{Deserialize, Serialize};

/// Which product the maps show.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ProductKind {
    /// Chlorophyll-a.
    Chl,
    /// Non-algal particles.
    Nap,
    /// CDOM absorption.
    Cdom,
    /// Depth (SAMBUCA).
    Depth,
    /// Dominant substrate (SAMBUCA).
    Substrate,
    /// Chosen SIOP set (aLMI).
    SiopSet,
    /// Rrs of the selected band.
    Rrs,
    /// Level-1 radiance of the selected band.
    Level1,
    /// Per-pixel SNR of the selected band (analytic, at the pixel's radiance).
    Snr,
    /// A retrieval's own product: [`crate::variable::EXTRAS`]`[i]` (QAA's IOPs, or what a user's
    /// program returns of them); saved by its key, so a session outlives a reordered table.
    Extra(#[serde(with = "extra_key")] u8),
}

impl ProductKind {
    /// Every product every run may have, in menu order (then [`Self::extras`]).
    pub const ALL: [Self; 9] = [
        Self::Chl,
        Self::Nap,
        Self::Cdom,
        Self::Depth,
        Self::Substrate,
        Self::SiopSet,
        Self::Rrs,
        Self::Level1,
        Self::Snr,
    ];

    /// The retrievals' own products among `variables` (a retrieval's
    /// [`crate::retrieval::Algorithm::variables`]), in [`crate::variable::EXTRAS`] order.
    pub fn extras(variables: &[String]) -> impl Iterator<Item = Self> + '_ {
        crate::variable::EXTRAS
            .iter()
            .enumerate()
            .filter(|(_, v)| variables.iter().any(|k| k == v.key))
            .filter_map(|(i, _)| u8::try_from(i).ok().map(Self::Extra))
    }

    /// Menu text: the name, then the unit in brackets.
    #[must_use]
    pub fn label(self) -> String {
        match self {
            Self::Chl => "chl-a (mg m⁻³)",
            Self::Nap => "NAP (g m⁻³)",
            Self::Cdom => "a_CDOM(440) (m⁻¹)",
            Self::Depth => "depth (m)",
            Self::Substrate => "dominant substrate",
            Self::SiopSet => "chosen SIOP set",
            Self::Rrs => "Rrs (sr⁻¹)",
            Self::Level1 => "Level-1 radiance (W m⁻² sr⁻¹ nm⁻¹)",
            Self::Snr => "SNR",
            Self::Extra(i) => {
                return crate::variable::EXTRAS
                    .get(usize::from(i))
                    .map_or_else(|| "(no such product)".into(), |v| format!("{} ({})", v.name, v.unit));
            }
        }
        .to_string()
    }

    /// The map of the variable called `key` (of [`crate::variable::PRODUCTS`] or
    /// [`crate::variable::EXTRAS`]).
    #[must_use]
    pub fn of_variable(key: &str) -> Option<Self> {
        use crate::variable::{EXTRAS, key as k};
        match key {
            k::CHL => Some(Self::Chl),
            k::NAP => Some(Self::Nap),
            k::CDOM => Some(Self::Cdom),
            k::DEPTH => Some(Self::Depth),
            other => EXTRAS.iter().position(|v| v.key == other).and_then(|i| u8::try_from(i).ok()).map(Self::Extra),
        }
    }

    /// It names a product (an [`Self::Extra`] index within [`crate::variable::EXTRAS`]).
    #[must_use]
    pub fn exists(self) -> bool {
        match self {
            Self::Extra(i) => usize::from(i) < crate::variable::EXTRAS.len(),
            _ => true,
        }
    }

    /// Does it need a band?
    #[must_use]
    pub fn per_band(self) -> bool {
        matches!(self, Self::Rrs | Self::Level1 | Self::Snr)
    }

    /// Is it a class map (no colour scale)?
    #[must_use]
    pub fn categorical(self) -> bool {
        matches!(self, Self::Substrate | Self::SiopSet)
    }

    /// The metrics variable it corresponds to.
    #[must_use]
    pub fn variable(self) -> Option<&'static str> {
        use crate::variable::key;
        match self {
            Self::Chl => Some(key::CHL),
            Self::Nap => Some(key::NAP),
            Self::Cdom => Some(key::CDOM),
            Self::Depth => Some(key::DEPTH),
            Self::Extra(i) => crate::variable::EXTRAS.get(usize::from(i)).map(|v| v.key),
            _ => None,
        }
    }
}

/// [`ProductKind::Extra`]'s index saved as the variable's key; a key this Shoal does not know
/// reads as an index past the table ([`ProductKind::exists`] false: the session's repair shows
/// chl-a instead).
mod extra_key {
    use serde::{Deserialize, Deserializer, Serializer};

    use crate::variable::EXTRAS;

    pub fn serialize<S: Serializer>(i: &u8, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(EXTRAS.get(usize::from(*i)).map_or("", |v| v.key))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<u8, D::Error> {
        let key = String::deserialize(d)?;
        Ok(EXTRAS.iter().position(|v| v.key == key).and_then(|i| u8::try_from(i).ok()).unwrap_or(u8::MAX))
    }
}

#[cfg(test)]
mod tests {
    use super::ProductKind;

    #[test]
    fn a_retrieval_s_own_product_is_saved_by_its_key() {
        let text = ron::to_string(&ProductKind::Extra(1)).unwrap_or_default();
        assert_eq!(text, "Extra(\"aph443_per_m\")");
        assert_eq!(ron::from_str::<ProductKind>(&text).ok(), Some(ProductKind::Extra(1)));
        let unknown = ron::from_str::<ProductKind>("Extra(\"gone\")").ok();
        assert!(unknown.is_some_and(|k| !k.exists()), "{unknown:?}");
    }
}

/// How the three maps are arranged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Layout {
    /// The truth beside the designs on the maps (truth | A | B by default; `AppState::on_maps`).
    TruthAB,
    /// A pair of designs and their difference (A | B | A − B by default; `AppState::pair`).
    AbDifference,
}
