//! PVSM's counted work (`--count-work`): every pass that counts its texel reads counts the bytes
//! they fetched, each read its texture's texel size or its storage element's, so that the work
//! tables know its bytes read. Checked against formulas written from the formats on
//! parallel-square: the G-buffer's position and normal are Rgba32Float (16 bytes a texel), the
//! low-resolution map's levels and the tile maps R32Float (4), the tile pyramid Rgba32Float and its
//! near counts Rgba32Uint (16 each), a pixel's kernel record 48 bytes, its accumulated sums a
//! vec2<f32> (8) and its capped flag a u32 (4), a cell of the tile grid or of its pyramid 8.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_core::work::{FrameWork, PassWork};
use ssm_scene::builtin;
use ssm_testing::{gpu, render};

const SIZE: (u32, u32) = (160, 120);

/// One counted frame of `pvsm` with `settings` on parallel-square.
fn counted(settings: &[(&str, &str)]) -> FrameWork {
    let scene = builtin("parallel-square").unwrap().build();
    let mut rendered = render(&gpu(), &scene, &ssm_pvsm::INFO, settings, SIZE.0, SIZE.1).unwrap();
    let params = ssm_pvsm::INFO.params_from(settings.iter().copied()).unwrap();
    let work = rendered.renderer.count_work(&ssm_pvsm::INFO, &params).unwrap();
    println!("{}", work.passes_column());
    assert!(work.shader_counts, "pvsm counts in its shaders");
    work
}

fn pass<'a>(work: &'a FrameWork, name: &str) -> &'a PassWork {
    work.passes.iter().find(|p| p.name == name).unwrap_or_else(|| panic!("no {name} in {}", work.passes_column()))
}

fn diagnostic(work: &FrameWork, key: &str) -> u64 {
    let value = work.diagnostics.iter().find(|(k, _)| k == key).map(|(_, v)| *v).unwrap_or_else(|| panic!("no diagnostic {key}"));
    value.round() as u64
}

/// Every pass of pvsm that reads counts the bytes of its reads, so that its frame's bytes read are
/// known (ssm-bench's `Totals::read_bytes`: only where every reading pass counts them).
fn assert_every_reading_pass_counts_bytes(work: &FrameWork, expected: &[&str]) {
    for name in expected {
        let p = pass(work, name);
        assert!(p.texel_reads > 0 && p.read_bytes > 0, "{name}: {} reads, {} bytes", p.texel_reads, p.read_bytes);
    }
    for p in work.passes.iter().filter(|p| p.name.starts_with("pvsm_") && p.texel_reads > 0) {
        assert!(p.read_bytes > 0, "{} reads {} texels and counts no bytes", p.name, p.texel_reads);
    }
}

/// The per-texel walk (filter_walk = texels), whose every read is known: over P pixels (one
/// light), the mips read only R32Float texels (4 bytes), the grid's pyramid only 8-byte cells; the
/// kernel shape the G-buffer's two texels at every pixel and the rest from the low-resolution map,
/// 2·16·P + 4·(reads − 2P); the filter, per tile, every pixel's 48-byte kernel record, and per
/// filter evaluation (E) the G-buffer's two texels and the pixel's accumulated sums besides the
/// walk's W tile-map texels: 48·tiles·P + (2·16 + 8)·E + 4·W; the resolve every pixel's record
/// and a filtered pixel's (F) sums and capped flag: 48·P + (8 + 4)·F.
#[test]
fn each_pass_counts_the_bytes_of_what_it_reads() {
    let work = counted(&[("filter_walk", "texels")]);
    let pixels = u64::from(SIZE.0 * SIZE.1);
    assert_every_reading_pass_counts_bytes(
        &work,
        &["pvsm_low_res_mips", "pvsm_kernel_shape", "pvsm_smtg_pyramid", "pvsm_tile_filter", "pvsm_resolve"],
    );
    let mips = pass(&work, "pvsm_low_res_mips");
    assert_eq!(mips.read_bytes, 4 * mips.texel_reads, "the mips read R32Float texels");
    let grid = pass(&work, "pvsm_smtg_pyramid");
    assert_eq!(grid.read_bytes, 8 * grid.texel_reads, "the grid's pyramid reads 8-byte cells");

    let kernel = pass(&work, "pvsm_kernel_shape");
    assert_eq!(kernel.counted_invocations, pixels);
    assert_eq!(kernel.read_bytes, 2 * 16 * pixels + 4 * (kernel.texel_reads - 2 * pixels));

    let tiles = diagnostic(&work, "pvsm_tiles");
    let evaluations = diagnostic(&work, "pvsm_tile_filter_walk_pixels");
    let walked = diagnostic(&work, "pvsm_texels_filtered");
    assert!(tiles > 0 && evaluations > 0 && walked > 0, "{tiles} tiles, {evaluations} filter evaluations, {walked} texels filtered");
    let filter = pass(&work, "pvsm_tile_filter");
    assert_eq!(filter.counted_invocations, tiles * pixels);
    assert_eq!(filter.texel_reads, tiles * pixels + 3 * evaluations + walked);
    assert_eq!(filter.read_bytes, 48 * tiles * pixels + (2 * 16 + 8) * evaluations + 4 * walked);

    let filtered = diagnostic(&work, "pvsm_filtered_pixels");
    assert!(filtered > 0 && filtered < pixels, "{filtered} filtered pixels");
    let resolve = pass(&work, "pvsm_resolve");
    assert_eq!(resolve.texel_reads, pixels + 2 * filtered);
    assert_eq!(resolve.read_bytes, 48 * pixels + (8 + 4) * filtered);
}

/// The hierarchy (the default walk): the tile pyramid's level 1 reads each of the T texels the
/// tiles' maps hold (`pvsm_texels_rendered`) once from the map (R32Float, 4 bytes), and every other
/// read is a pyramid texel's depths or near counts (Rgba32Float, Rgba32Uint: 16 bytes):
/// 4·T + 16·(reads − T). The filter's walk reads map texels (4 bytes) and pyramid texels (16): its
/// bytes lie between those two sizes times the walk's W reads, beside 48·tiles·P + 40·E.
#[test]
fn the_tile_pyramid_counts_its_map_and_pyramid_texels_bytes() {
    let work = counted(&[]);
    let pixels = u64::from(SIZE.0 * SIZE.1);
    assert_every_reading_pass_counts_bytes(
        &work,
        &["pvsm_low_res_mips", "pvsm_kernel_shape", "pvsm_smtg_pyramid", "pvsm_tile_pyramid", "pvsm_tile_filter", "pvsm_resolve"],
    );
    let texels = diagnostic(&work, "pvsm_texels_rendered");
    let pyramid = pass(&work, "pvsm_tile_pyramid");
    assert!(pyramid.texel_reads > texels, "{} reads for {texels} map texels", pyramid.texel_reads);
    assert_eq!(pyramid.read_bytes, 4 * texels + 16 * (pyramid.texel_reads - texels));

    let (tiles, evaluations, walked) =
        (diagnostic(&work, "pvsm_tiles"), diagnostic(&work, "pvsm_tile_filter_walk_pixels"), diagnostic(&work, "pvsm_texels_filtered"));
    let filter = pass(&work, "pvsm_tile_filter");
    let fixed = 48 * tiles * pixels + 40 * evaluations;
    assert!(
        (fixed + 4 * walked..=fixed + 16 * walked).contains(&filter.read_bytes),
        "{} bytes against {fixed} + 4..16 × {walked}",
        filter.read_bytes
    );
}
