//! Every technique crate of the workspace in one dependency.
//!
//! `ssm-bench` (the `ssm` tool and the benches) and the cross-crate tests
//! depend on this crate and call [`link_all`], so that every technique's
//! registration is in the binary: the linker keeps a crate only when
//! something calls into it. The list is this crate's `Cargo.toml`: adding a
//! technique is one line there.

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
}
