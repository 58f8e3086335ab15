//! WGSL assembly: `// #import common/<file>.wgsl` lines pull in the shared
//! WGSL under `shaders/common/`, once each, before the importing file.
//!
//! WGSL has no include mechanism; a comment keeps every file valid to
//! editors, and the same resolution runs in the naga validation test.

use crate::context::GpuContext;
use crate::error::{Error, Result};

/// The shared WGSL files (`shaders/common/`), by the path an import names.
pub const COMMON_SHADERS: &[(&str, &str)] = ssm_shaders::common::FILES;

/// The prefix of an import line.
pub const IMPORT_PREFIX: &str = "// #import ";

/// Resolves the imports of `source` against `lookup`, each file once, imports first.
///
/// # Errors
/// The name of an import `lookup` does not know, or an import cycle.
pub fn compose_with(source: &str, lookup: &dyn Fn(&str) -> Option<String>) -> std::result::Result<String, String> {
    fn visit(
        source: &str,
        lookup: &dyn Fn(&str) -> Option<String>,
        done: &mut Vec<String>,
        stack: &mut Vec<String>,
        out: &mut String,
    ) -> std::result::Result<(), String> {
        for line in source.lines() {
            if let Some(path) = line.trim().strip_prefix(IMPORT_PREFIX.trim_start()) {
                let path = path.trim().to_owned();
                if done.contains(&path) {
                    continue;
                }
                if stack.contains(&path) {
                    return Err(format!("import cycle through `{path}`"));
                }
                let text = lookup(&path).ok_or_else(|| format!("unknown import `{path}`"))?;
                stack.push(path.clone());
                visit(&text, lookup, done, stack, out)?;
                out.push_str(&text);
                out.push('\n');
                stack.pop();
                done.push(path);
            }
        }
        Ok(())
    }
    let mut out = String::new();
    visit(source, lookup, &mut Vec::new(), &mut Vec::new(), &mut out)?;
    // Every import's body precedes the file that imports it.
    out.push_str(source);
    Ok(out)
}

/// Resolves the imports of `source` against [`COMMON_SHADERS`].
///
/// # Errors
/// [`Error::Shader`] naming `label` and the unknown import.
pub fn compose(label: &str, source: &str) -> Result<String> {
    compose_with(source, &|path| COMMON_SHADERS.iter().find(|(p, _)| *p == path).map(|(_, text)| (*text).to_owned()))
        .map_err(|problem| Error::Shader { shader: label.into(), problem })
}

/// Assembles and compiles a shader module labelled `label`.
///
/// # Errors
/// [`Error::Shader`] for a bad import, [`Error::Gpu`] when wgpu rejects the WGSL.
pub fn create_shader(gpu: &GpuContext, label: &str, source: &str) -> Result<wgpu::ShaderModule> {
    create_shader_with_imports(gpu, label, source, &[])
}

/// As [`create_shader`], with a technique's own importable files besides
/// [`COMMON_SHADERS`], as `(path under shaders/, text)`: `("mine/settings.wgsl", include_str!(...))`.
///
/// # Errors
/// [`Error::Shader`] for a bad import, [`Error::Gpu`] when wgpu rejects the WGSL.
pub fn create_shader_with_imports(gpu: &GpuContext, label: &str, source: &str, local: &[(&str, &str)]) -> Result<wgpu::ShaderModule> {
    let lookup = |path: &str| COMMON_SHADERS.iter().chain(local).find(|(p, _)| *p == path).map(|(_, text)| (*text).to_owned());
    let code = compose_with(source, &lookup).map_err(|problem| Error::Shader { shader: label.into(), problem })?;
    let module =
        gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(label), source: wgpu::ShaderSource::Wgsl(code.into()) });
    let messages = gpu.take_errors();
    if messages.is_empty() { Ok(module) } else { Err(Error::Gpu { during: format!("compiling shader `{label}`"), messages }) }
}
