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

/// The real-time techniques that must run on lavapipe (it has every device feature they need) in
/// every cross-crate test: the workspace's and the plug-in. A test fails when one of them is not
/// registered or does not run, except where the test expects a refusal of it by name and
/// reason. A technique registered from elsewhere may refuse with a typed device refusal
/// ([`ssm_core::Error::MissingFeatures`] or [`ssm_core::Error::LimitTooLow`]), which
/// [`render_or_refusal`] prints.
pub const MUST_RUN_ON_LAVAPIPE: &[&str] = &["atty", "hard", "multi-sm", "pcss", "plugin-hard", "pvsm", "sssm", "vssm", "wedges"];

/// The names of [`MUST_RUN_ON_LAVAPIPE`] that are not registered.
#[must_use]
pub fn missing_must_run() -> Vec<&'static str> {
    MUST_RUN_ON_LAVAPIPE.iter().copied().filter(|name| registry().get(name).is_err()).collect()
}

/// `result` of rendering `technique` (in `context`, for messages), as a cross-crate test takes it:
/// `Ok(Some(_))` when it rendered; `Ok(None)` when a technique outside [`MUST_RUN_ON_LAVAPIPE`]
/// refused with a typed device refusal (printed, with its reason); `Err(message)` for every other
/// error, a must-run technique's refusal included.
///
/// # Errors
/// A message naming the technique, the context and the error.
pub fn render_or_refusal<T>(technique: &str, context: &str, result: ssm_core::Result<T>) -> Result<Option<T>, String> {
    match result {
        Ok(value) => Ok(Some(value)),
        Err(e @ (ssm_core::Error::MissingFeatures { .. } | ssm_core::Error::LimitTooLow { .. }))
            if !MUST_RUN_ON_LAVAPIPE.contains(&technique) =>
        {
            println!("{technique} / {context}: refused (not required to run here): {e}");
            Ok(None)
        }
        Err(e) => Err(format!("{technique} / {context}: {e}")),
    }
}
