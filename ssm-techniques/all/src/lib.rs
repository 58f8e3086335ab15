//! Every technique crate of the workspace in one dependency.
//!
//! `ssm-bench` (the `ssm` tool and the benches) and the cross-crate tests
//! depend on this crate and call [`link_all`], so that every technique's
//! registration is in the binary: the linker keeps a crate only when
//! something calls into it. The list is this crate's `Cargo.toml`: adding a
//! technique is one line there.
//!
//! # Example
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let names = ssm_techniques::link_all();
//! assert!(names.contains(&"pvsm") && names.contains(&"reference"));
//! let pcss = ssm_techniques::registry()?.get("pcss")?;
//! println!("{}: {} parameters", pcss.name, pcss.params.len());
//! # Ok(())
//! # }
//! ```

include!(concat!(env!("OUT_DIR"), "/link_all.rs"));

/// The registry, with every technique linked.
///
/// # Errors
/// Two techniques registered under one name.
pub fn registry() -> ssm_core::Result<&'static ssm_core::Registry> {
    let _linked = link_all();
    ssm_core::Registry::global()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_dependency_is_linked_and_registered() {
        let names = link_all();
        // The ground truth plus one registration per technique crate.
        assert_eq!(names.len(), CRATES.len() + 1, "{names:?} for {CRATES:?}");
        let registry = registry().unwrap_or_else(|e| panic!("{e}"));
        for name in names {
            assert!(registry.get(name).is_ok(), "{name} is linked but not registered");
        }
    }

    /// Every crate folder beside this one is in the list: a technique whose line was forgotten
    /// would be missing from `ssm list`, the benches and the extremes matrix without a word.
    #[test]
    fn every_technique_folder_is_a_dependency() {
        let techniques = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut folders: Vec<String> = std::fs::read_dir(&techniques)
            .unwrap_or_else(|e| panic!("{e}"))
            .filter_map(|entry| entry.ok().map(|e| e.path()))
            .filter(|path| path.join("Cargo.toml").is_file() && !path.ends_with("all"))
            .filter_map(|path| std::fs::read_to_string(path.join("Cargo.toml")).ok())
            .filter_map(|manifest| {
                manifest
                    .lines()
                    .find_map(|line| line.strip_prefix("name = \"").and_then(|rest| rest.strip_suffix('"')).map(|n| n.replace('-', "_")))
            })
            .collect();
        folders.sort();
        let mut linked: Vec<String> = CRATES.iter().map(|c| (*c).to_owned()).collect();
        linked.sort();
        assert_eq!(folders, linked, "add each technique crate to ssm-techniques/all/Cargo.toml");
    }
}
