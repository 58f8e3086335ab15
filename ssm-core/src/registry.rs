//! The technique registry: every [`TechniqueInfo`] submitted anywhere in the
//! binary, in one map sorted by name, built once. Never relies on
//! `inventory`'s iteration order; duplicate names are an error.

use std::collections::BTreeMap;
use std::sync::OnceLock;

use crate::error::{Error, Result};
use crate::technique::TechniqueInfo;

/// The registered techniques, by name.
#[derive(Debug)]
pub struct Registry {
    entries: BTreeMap<&'static str, &'static TechniqueInfo>,
}

impl Registry {
    /// Builds a registry from explicit entries.
    ///
    /// # Errors
    /// [`Error::DuplicateTechnique`] when two entries share a name.
    pub fn from_entries(entries: impl IntoIterator<Item = &'static TechniqueInfo>) -> Result<Self> {
        let mut map: BTreeMap<&'static str, &'static TechniqueInfo> = BTreeMap::new();
        for info in entries {
            if let Some(first) = map.insert(info.name, info) {
                return Err(Error::DuplicateTechnique { name: info.name.into(), first: first.summary.into(), second: info.summary.into() });
            }
        }
        Ok(Self { entries: map })
    }

    /// Every technique registered with [`register_technique!`](crate::register_technique) in this binary.
    ///
    /// # Errors
    /// [`Error::DuplicateTechnique`] when two crates register one name.
    pub fn global() -> Result<&'static Self> {
        static GLOBAL: OnceLock<std::result::Result<Registry, (String, String, String)>> = OnceLock::new();
        let built = GLOBAL.get_or_init(|| {
            Self::from_entries(inventory::iter::<TechniqueInfo>).map_err(|e| match e {
                Error::DuplicateTechnique { name, first, second } => (name, first, second),
                other => (String::new(), other.to_string(), String::new()),
            })
        });
        built.as_ref().map_err(|(name, first, second)| Error::DuplicateTechnique {
            name: name.clone(),
            first: first.clone(),
            second: second.clone(),
        })
    }

    /// The technique called `name`.
    ///
    /// # Errors
    /// [`Error::UnknownTechnique`] listing the registered names.
    pub fn get(&self, name: &str) -> Result<&'static TechniqueInfo> {
        self.entries.get(name).copied().ok_or_else(|| Error::UnknownTechnique { name: name.into(), known: self.names().join(", ") })
    }

    /// Every technique, sorted by name.
    pub fn iter(&self) -> impl Iterator<Item = &'static TechniqueInfo> + '_ {
        self.entries.values().copied()
    }

    /// Every name, sorted.
    #[must_use]
    pub fn names(&self) -> Vec<&'static str> {
        self.entries.keys().copied().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::technique::{Requirements, TechniqueKind};

    fn no_create(_: &crate::TechniqueSetup<'_>) -> Result<Box<dyn crate::ShadowTechnique>> {
        Err(Error::Technique { technique: "test".into(), message: "not creatable".into() })
    }

    static ALPHA: TechniqueInfo = TechniqueInfo {
        name: "alpha",
        summary: "first",
        paper: "",
        kind: TechniqueKind::Realtime,
        light_sampling: crate::LightSampling::Centre,
        light_view: crate::LightView::Frame,
        params: &[],
        requirements: |_| Ok(Requirements::NONE),
        create: no_create,
        presets: &[],
        trade: None,
        debug_outputs: &[],
        uniforms: &[],
        limits: &[],
        paper_configuration: crate::PaperConfiguration::DEFAULTS,
    };
    static ALPHA_AGAIN: TechniqueInfo = TechniqueInfo {
        name: "alpha",
        summary: "second",
        paper: "",
        kind: TechniqueKind::Realtime,
        light_sampling: crate::LightSampling::Centre,
        light_view: crate::LightView::Frame,
        params: &[],
        requirements: |_| Ok(Requirements::NONE),
        create: no_create,
        presets: &[],
        trade: None,
        debug_outputs: &[],
        uniforms: &[],
        limits: &[],
        paper_configuration: crate::PaperConfiguration::DEFAULTS,
    };
    static BETA: TechniqueInfo = TechniqueInfo {
        name: "beta",
        summary: "b",
        paper: "",
        kind: TechniqueKind::Realtime,
        light_sampling: crate::LightSampling::Centre,
        light_view: crate::LightView::Frame,
        params: &[],
        requirements: |_| Ok(Requirements::NONE),
        create: no_create,
        presets: &[],
        trade: None,
        debug_outputs: &[],
        uniforms: &[],
        limits: &[],
        paper_configuration: crate::PaperConfiguration::DEFAULTS,
    };

    #[test]
    fn listing_is_sorted_whatever_the_submission_order() {
        let registry = Registry::from_entries([&BETA, &ALPHA]).unwrap();
        assert_eq!(registry.names(), vec!["alpha", "beta"]);
        assert_eq!(registry.get("beta").unwrap().summary, "b");
        let err = registry.get("gamma").unwrap_err().to_string();
        assert!(err.contains("gamma") && err.contains("alpha, beta"), "{err}");
    }

    #[test]
    fn duplicate_names_are_an_error() {
        let err = Registry::from_entries([&ALPHA, &BETA, &ALPHA_AGAIN]).unwrap_err();
        assert!(matches!(err, Error::DuplicateTechnique { ref name, .. } if name == "alpha"), "{err}");
    }
}
