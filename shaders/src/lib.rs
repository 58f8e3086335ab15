//! The WGSL of ssm, embedded in the binary, so that the crates that use it package and run from
//! anywhere: `common` (what several techniques import: the light frame, the screen pass, the
//! shadow-map lookups), `core` (the framework's own passes) and one module per technique, each
//! file a constant named after it (`ssm_shaders::hard::HARD` is `shaders/hard/hard.wgsl`).
//! [`FILES`] lists every file by the path an `// #import` line names it by
//! (`common/screen_pass.wgsl`). The modules are generated from the folders by `build.rs`: a
//! new folder of WGSL files needs no line here.
//!
//! # Example
//!
//! ```
//! let (_, source) = ssm_shaders::FILES.iter().find(|(path, _)| *path == "common/screen_pass.wgsl").expect("a common file");
//! assert!(source.contains("fn trivial_visibility"));
//! assert_eq!(ssm_shaders::hard::HARD, ssm_shaders::FILES.iter().find(|(p, _)| *p == "hard/hard.wgsl").map(|(_, s)| *s).unwrap_or(""));
//! ```

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));

/// The text of the file at `path` under `shaders/` (`common/screen_pass.wgsl`), if there is one.
#[must_use]
pub fn file(path: &str) -> Option<&'static str> {
    FILES.iter().find(|(name, _)| *name == path).map(|(_, text)| *text)
}

#[cfg(test)]
mod tests {
    /// Every `.wgsl` file under `shaders/` is embedded, under the path imports name it by.
    #[test]
    fn every_wgsl_file_is_embedded_by_its_path() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut on_disk = Vec::new();
        for folder in std::fs::read_dir(root).into_iter().flatten().flatten().map(|entry| entry.path()).filter(|path| path.is_dir()) {
            for file in std::fs::read_dir(&folder).into_iter().flatten().flatten().map(|entry| entry.path()) {
                if file.extension().is_some_and(|e| e == "wgsl") {
                    let relative = file.strip_prefix(root).map(|p| p.to_string_lossy().replace('\\', "/")).unwrap_or_default();
                    let text = std::fs::read_to_string(&file).unwrap_or_default();
                    assert_eq!(super::file(&relative), Some(text.as_str()), "{relative}");
                    on_disk.push(relative);
                }
            }
        }
        assert_eq!(on_disk.len(), super::FILES.len(), "{on_disk:?}");
        assert_eq!(super::hard::HARD, super::file("hard/hard.wgsl").unwrap_or_default());
        assert!(super::common::FILES.iter().all(|(path, _)| path.starts_with("common/")));
    }
}
