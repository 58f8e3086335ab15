//! The WGSL a `#[derive(UniformStruct)]` writes: one struct, its fields' doc comments as
//! comments, each Rust type's WGSL twin, and the import path shaders name it by.

use ssm_core::UniformStruct;

/// A uniform with every kind of field the derive maps.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, UniformStruct)]
struct EveryFieldUniform {
    /// World to clip.
    view_proj: [[f32; 4]; 4],
    /// Centre, intensity.
    ///
    /// (second paragraph)
    centre: [f32; 4],
    light_count: u32,
    offset: i32,
    scale: f32,
    _pad0: u32,
    size: [u32; 2],
    tile: [i32; 2],
}

/// A uniform whose WGSL name is set.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, UniformStruct)]
#[wgsl(name = "Named")]
struct OtherNameUniform {
    value: f32,
}

#[test]
fn the_wgsl_declaration_mirrors_the_rust_struct() {
    let expected = "struct EveryField {
    // World to clip.
    view_proj: mat4x4<f32>,
    // Centre, intensity.
    //
    // (second paragraph)
    centre: vec4<f32>,
    light_count: u32,
    offset: i32,
    scale: f32,
    _pad0: u32,
    size: vec2<u32>,
    tile: vec2<i32>,
}
";
    assert_eq!(EveryFieldUniform::WGSL, expected);
    assert_eq!(EveryFieldUniform::WGSL_NAME, "EveryField");
    assert_eq!(EveryFieldUniform::WGSL_IMPORT, "rust/EveryField");
    assert_eq!((OtherNameUniform::WGSL_NAME, OtherNameUniform::WGSL_IMPORT), ("Named", "rust/Named"));
    assert_eq!(OtherNameUniform::WGSL, "struct Named {\n    value: f32,\n}\n");
}
