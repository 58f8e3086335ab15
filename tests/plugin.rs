//! The plug-in test: a technique defined in a crate ssm-core does not know
//! (`tests/plugin-technique`) is registered, listed, created and rendered
//! through the same path as the built-in ones.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use glam::Vec3;
use ssm_integration_tests::registry;
use ssm_scene::{Manifest, builtin};
use ssm_testing::{at, gpu, pixel_of, render};

#[test]
fn outside_technique_is_registered_and_listed_in_order() {
    let registry = registry();
    let names = registry.names();
    assert!(names.contains(&"plugin-hard"), "{names:?}");
    // The workspace's techniques and the ground truth are there too.
    assert!(ssm_techniques::link_all().iter().all(|name| names.contains(name)), "{names:?}");
    let mut sorted = names.clone();
    sorted.sort_unstable();
    assert_eq!(names, sorted, "the listing is sorted by name");
    assert_eq!(registry.get("plugin-hard").unwrap().params.iter().map(|p| p.name).collect::<Vec<_>>(), ["map_size"]);
}

#[test]
fn outside_technique_renders() {
    let gpu = gpu();
    // parallel-square: the receiver's centre is in the occluder's hard shadow, a point 2.5 to the side is lit.
    let scene = builtin("parallel-square").unwrap().build();
    let rendered = render(&gpu, &scene, &ssm_plugin_technique::INFO, &[("map_size", "512")], 64, 48).unwrap();
    assert_eq!(at(&rendered, pixel_of(&scene, 64, 48, Vec3::ZERO)), 0.0);
    assert_eq!(at(&rendered, pixel_of(&scene, 64, 48, Vec3::new(2.5, 0.0, 0.0))), 1.0);
    assert!(rendered.visibility.iter().all(|v| *v == 0.0 || *v == 1.0), "a hard shadow");

    // Light facing up from below the ground: every surface is behind it.
    let text = r#"
[camera]
position = [0.0, 5.0, 6.0]
target = [0.0, 0.0, 0.0]

[[light]]
centre = [0.0, -1.0, 0.0]
normal = [0.0, -1.0, 0.0]
size = [1.0, 1.0]

[[object]]
primitive = "plane"
size = [8.0, 8.0]
role = "receiver"
"#;
    let scene = Manifest::parse(text, Path::new("inline.toml")).unwrap().build(Path::new("inline.toml"), Path::new(".")).unwrap();
    let rendered = render(&gpu, &scene, &ssm_plugin_technique::INFO, &[], 64, 48).unwrap();
    let covered = rendered.covered_visibility();
    assert!(covered.len() > 500, "the plane covers the view");
    assert!(covered.iter().all(|v| *v == 0.0), "everything is behind the light");
}
