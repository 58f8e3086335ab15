//! What the cross-crate tests share beyond `ssm-testing`: the registry with
//! every technique linked, the workspace's and the plug-in test's.

use ssm_core::Registry;

/// Every registered technique: the workspace's (through the `ssm-techniques`
/// facade) and the plug-in defined outside it (`tests/plugin-technique`).
///
/// # Panics
/// If two techniques share a name.
#[must_use]
pub fn registry() -> &'static Registry {
    let _linked = ssm_plugin_technique::link();
    ssm_techniques::registry().unwrap_or_else(|e| panic!("{e}"))
}
