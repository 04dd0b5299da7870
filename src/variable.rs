//! The product variables — what a retrieval returns and the truth holds — named once: the key
//! every file, table, requirement and metric uses, and how people, CF and GeoTIFF units call it.
//! A new product variable is a row of [`PRODUCTS`] (and a map in the truth and the product).

/// The keys, usable as `match` patterns.
pub mod key {
    /// Chlorophyll-a concentration, mg m⁻³.
    pub const CHL: &str = "chl_mg_m3";
    /// Non-algal particles (suspended matter), g m⁻³.
    pub const NAP: &str = "nap_g_m3";
    /// CDOM absorption at the SIOP set's reference wavelength, m⁻¹.
    pub const CDOM: &str = "cdom_per_m";
    /// Water depth, m.
    pub const DEPTH: &str = "depth_m";
}

/// One product variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Variable {
    /// The key (`chl_mg_m3`): file names, metrics, requirements, NetCDF variables.
    pub key: &'static str,
    /// Short name for tables and axes (`chl-a`).
    pub name: &'static str,
    /// What it is, in words (NetCDF `long_name`, the review pack).
    pub long_name: &'static str,
    /// Unit for people (`mg m⁻³`).
    pub unit: &'static str,
    /// Unit as UDUNITS and GeoTIFF files write it (`mg m-3`).
    pub udunits: &'static str,
    /// CF standard name, where CF has one.
    pub standard_name: Option<&'static str>,
}

/// Every product variable, in table order.
pub const PRODUCTS: [Variable; 4] = [
    Variable {
        key: key::CHL,
        name: "chl-a",
        long_name: "chlorophyll-a concentration",
        unit: "mg m⁻³",
        udunits: "mg m-3",
        standard_name: Some("mass_concentration_of_chlorophyll_a_in_sea_water"),
    },
    Variable {
        key: key::NAP,
        name: "NAP",
        long_name: "non-algal particle (suspended matter) concentration",
        unit: "g m⁻³",
        udunits: "g m-3",
        standard_name: Some("mass_concentration_of_suspended_matter_in_sea_water"),
    },
    Variable {
        key: key::CDOM,
        name: "CDOM",
        long_name: "CDOM absorption coefficient at the SIOP set's reference wavelength",
        unit: "m⁻¹",
        udunits: "m-1",
        standard_name: None,
    },
    Variable {
        key: key::DEPTH,
        name: "depth",
        long_name: "water depth",
        unit: "m",
        udunits: "m",
        standard_name: Some("sea_floor_depth_below_sea_surface"),
    },
];

/// Variables a retrieval may return beside [`PRODUCTS`] (`Product::extras`): mapped and written,
/// and scored where the retrieval says what their truth is (`Algorithm::extra_truths`: QAA's
/// IOPs from the true concentrations and the scene's SIOP set).
pub const EXTRAS: [Variable; 3] = [
    Variable {
        key: "adg443_per_m",
        name: "a_dg(443)",
        long_name: "absorption coefficient of detritus and CDOM at 443 nm",
        unit: "m⁻¹",
        udunits: "m-1",
        standard_name: None,
    },
    Variable {
        key: "aph443_per_m",
        name: "a_ph(443)",
        long_name: "absorption coefficient of phytoplankton at 443 nm",
        unit: "m⁻¹",
        udunits: "m-1",
        standard_name: None,
    },
    Variable {
        key: "bbp555_per_m",
        name: "b_bp(555)",
        long_name: "particulate backscattering coefficient at the band nearest 555 nm",
        unit: "m⁻¹",
        udunits: "m-1",
        standard_name: None,
    },
];

/// The keys of [`PRODUCTS`], in order.
pub const KEYS: [&str; 4] = [key::CHL, key::NAP, key::CDOM, key::DEPTH];

/// The variable called `key`, if it is one (of [`PRODUCTS`] or [`EXTRAS`]).
#[must_use]
pub fn of(key: &str) -> Option<&'static Variable> {
    PRODUCTS.iter().chain(&EXTRAS).find(|v| v.key == key)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_is_one_variable_in_table_order() {
        assert_eq!(PRODUCTS.map(|v| v.key), KEYS);
        assert_eq!(of("nap_g_m3").map(|v| v.unit), Some("g m⁻³"));
        assert!(of("chlorophyll").is_none());
        for (i, v) in PRODUCTS.iter().enumerate() {
            assert!(PRODUCTS[..i].iter().all(|w| w.key != v.key && w.name != v.name), "{v:?} twice");
            assert!(!v.unit.is_empty() && !v.udunits.is_empty() && !v.long_name.is_empty(), "{v:?}");
        }
    }
}
