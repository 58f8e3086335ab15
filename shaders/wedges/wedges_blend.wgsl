// Blending one silhouette buffer into the final one (Forest et al., Sec. 3.2
// and 4.3), and resolving the final buffer into visibility.
//
// Per pixel and per radial part, the silhouette buffer's occluded area A_s is
// the umbra (1 where the stencil count is non-zero, the light's centre is
// hidden: the umbra mask the volume pass wrote through the stencil test)
// plus the wedges' signed areas, clamped to the part; its bounding rectangle
// B_s is the union of the outer edges' rectangles and, in the umbra, of
// [0, max X] x [0, max Y] of the inner edges (the whole part when no inner
// edge crosses it). With blending=forest the overlap of the two occluded regions is
// estimated as eps = (A_f / B_f) (A_s / B_s) beta, beta the area of the
// rectangles' intersection, and A_f <- A_f + A_s - eps, B_f <- B_f u B_s.
// With blending=none the areas are summed (Akenine-Möller and Assarsson).
// The final buffer is in storage buffers of full-precision floats, one vec4
// per pixel each: the four areas, and one buffer per radial part's rectangle
// (so that each binding stays under the storage binding limit at 3840 x 2160:
// AllocationPlan in ssm-techniques/wedges/src/plan.rs).

// #import common/screen_pass.wgsl
// #import wedges/wedges_common.wgsl
// #import wedges/wedges_counts.wgsl

@group(2) @binding(0) var silhouette_area: texture_2d<f32>;
@group(2) @binding(1) var silhouette_rect0: texture_2d<f32>;
@group(2) @binding(2) var silhouette_rect1: texture_2d<f32>;
@group(2) @binding(3) var silhouette_rect2: texture_2d<f32>;
@group(2) @binding(4) var silhouette_rect3: texture_2d<f32>;
@group(2) @binding(5) var silhouette_inner01: texture_2d<f32>;
@group(2) @binding(6) var silhouette_inner23: texture_2d<f32>;
@group(2) @binding(7) var silhouette_shaded: texture_2d<f32>;
@group(2) @binding(8) var<storage, read_write> final_areas: array<vec4<f32>>;
@group(2) @binding(9) var<uniform> settings: WedgesSettings;
@group(2) @binding(10) var umbra_mask: texture_2d<f32>;
@group(2) @binding(11) var<storage, read_write> fragment_counts: array<u32>;
@group(2) @binding(12) var<storage, read_write> final_rectangles0: array<vec4<f32>>;
@group(2) @binding(13) var<storage, read_write> final_rectangles1: array<vec4<f32>>;
@group(2) @binding(14) var<storage, read_write> final_rectangles2: array<vec4<f32>>;
@group(2) @binding(15) var<storage, read_write> final_rectangles3: array<vec4<f32>>;
@group(2) @binding(16) var<storage, read_write> read_counts: array<atomic<u32>>;
// Blending modes.
const BLENDING_NONE: u32 = 0u;

// Texels this invocation read, the bytes they fetched and the bytes it stored, for the counts
// (wedges_counts.wgsl).
var<private> reads: u32;
var<private> read_bytes: u32;
var<private> stored: u32;

// A rectangle (xmin, xmax, ymin, ymax) from its stored form (1 - xmin, xmax, 1 - ymin, ymax);
// the stored zero is the empty rectangle (1, 0, 1, 0), neutral for the union.
fn decode(stored: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(1.0 - stored.x, stored.y, 1.0 - stored.z, stored.w);
}

fn encode(rect: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(1.0 - rect.x, rect.y, 1.0 - rect.z, rect.w);
}

fn rect_area(rect: vec4<f32>) -> f32 {
    return max(rect.y - rect.x, 0.0) * max(rect.w - rect.z, 0.0);
}

fn rect_union(r: vec4<f32>, s: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(min(r.x, s.x), max(r.y, s.y), min(r.z, s.z), max(r.w, s.w));
}

fn rect_intersection(r: vec4<f32>, s: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(max(r.x, s.x), min(r.y, s.y), max(r.z, s.z), min(r.w, s.w));
}

// The share of a rectangle that its region occupies (1 when the rectangle is degenerate).
fn fill(area: f32, rect: vec4<f32>) -> f32 {
    let bound = rect_area(rect);
    if (bound <= 1e-12) {
        return 1.0;
    }
    return min(area / bound, 1.0);
}

// Radial part `part`'s stored rectangle at `pixel` in the final buffer.
fn final_rectangle(part: u32, pixel: u32) -> vec4<f32> {
    reads += 1u;
    read_bytes += FINAL_ELEMENT_BYTES;
    switch (part) {
        case 0u: {
            return final_rectangles0[pixel];
        }
        case 1u: {
            return final_rectangles1[pixel];
        }
        case 2u: {
            return final_rectangles2[pixel];
        }
        default: {
            return final_rectangles3[pixel];
        }
    }
}

fn store_final_rectangle(part: u32, pixel: u32, rectangle: vec4<f32>) {
    stored += 16u;
    switch (part) {
        case 0u: {
            final_rectangles0[pixel] = rectangle;
        }
        case 1u: {
            final_rectangles1[pixel] = rectangle;
        }
        case 2u: {
            final_rectangles2[pixel] = rectangle;
        }
        default: {
            final_rectangles3[pixel] = rectangle;
        }
    }
}

fn blend(texel: vec2<i32>, umbra: bool) {
    let area = textureLoad(silhouette_area, texel, 0);
    let inner01 = textureLoad(silhouette_inner01, texel, 0);
    let inner23 = textureLoad(silhouette_inner23, texel, 0);
    reads += 3u;
    read_bytes += 3u * SILHOUETTE_TEXEL_BYTES;
    if (!umbra && max(max(area.x, area.y), max(area.z, area.w)) <= 0.0) {
        return;
    }
    // The four rectangles and the final areas.
    reads += 5u;
    read_bytes += 4u * SILHOUETTE_TEXEL_BYTES + FINAL_ELEMENT_BYTES;
    var rects = array<vec4<f32>, 4>(
        textureLoad(silhouette_rect0, texel, 0),
        textureLoad(silhouette_rect1, texel, 0),
        textureLoad(silhouette_rect2, texel, 0),
        textureLoad(silhouette_rect3, texel, 0),
    );
    var maxima = array<vec2<f32>, 4>(inner01.xy, inner01.zw, inner23.xy, inner23.zw);
    let pixel = u32(texel.y) * u32(textureDimensions(silhouette_area).x) + u32(texel.x);
    var final_area = final_areas[pixel];
    let umbra_area = select(0.0, 1.0, umbra);
    for (var i = 0u; i < 4u; i += 1u) {
        let silhouette = clamp(umbra_area + area[i], 0.0, 1.0);
        if (silhouette <= 0.0) {
            continue;
        }
        if (settings.blending == BLENDING_NONE) {
            final_area[i] += silhouette;
            continue;
        }
        var bound = decode(rects[i]);
        if (umbra) {
            // Fig. 10: the umbra's region, trimmed by the inner edges to their maximum X and Y.
            let crossed = any(maxima[i] > vec2<f32>(0.0));
            let reach = select(vec2<f32>(1.0), maxima[i], crossed);
            bound = rect_union(bound, vec4<f32>(0.0, reach.x, 0.0, reach.y));
        }
        if (rect_area(bound) <= 0.0) {
            // No rectangle was recorded for occlusion that exists: assume the whole part.
            bound = vec4<f32>(0.0, 1.0, 0.0, 1.0);
        }
        let final_bound = decode(final_rectangle(i, pixel));
        if (final_area[i] <= 0.0) {
            final_area[i] = silhouette;
            store_final_rectangle(i, pixel, encode(bound));
            continue;
        }
        // Sec. 3.2: the overlap, weighted by how much of each rectangle is occluded.
        let beta = rect_area(rect_intersection(final_bound, bound));
        let epsilon = fill(final_area[i], final_bound) * fill(silhouette, bound) * beta;
        final_area[i] = clamp(final_area[i] + silhouette - epsilon, 0.0, 1.0);
        store_final_rectangle(i, pixel, encode(rect_union(final_bound, bound)));
    }
    final_areas[pixel] = final_area;
    stored += 16u;
}

// One thread per pixel (dispatched only for buffers that hold anything).
@compute @workgroup_size(16, 16)
fn wedges_blend(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(silhouette_area);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let texel = vec2<i32>(id.xy);
    let shaded = u32(textureLoad(silhouette_shaded, texel, 0).x + 0.5);
    if (shaded > 0u) {
        fragment_counts[id.y * size.x + id.x] += shaded;
        reads += 1u;
        read_bytes += FRAGMENT_COUNT_BYTES;
        stored += 4u;
    }
    blend(texel, textureLoad(umbra_mask, texel, 0).x > 0.5);
    // The shaded count and the umbra mask, besides what the blend read.
    record_reads(COUNTER_BLEND_READS, texel, reads + 2u, read_bytes + SHADED_COUNT_TEXEL_BYTES + UMBRA_MASK_TEXEL_BYTES);
    record_count(COUNTER_BLEND_STORAGE_BYTES, texel, stored);
}

// The umbra mask: drawn over the whole view through the stencil test (non-zero count).
@fragment
fn wedges_umbra_mask(in: FullscreenVertex) -> @location(0) vec4<f32> {
    return vec4<f32>(1.0);
}

// Visibility: one minus the occluded share of the light (each radial part is a quarter of it).
@fragment
fn wedges_resolve(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    let trivial = trivial_visibility(point);
    // The G-buffer's two texels, and the final areas where the pixel needs them.
    let texels = select(3u, 2u, trivial >= 0.0);
    record_reads(COUNTER_RESOLVE_READS, point.texel, texels, 2u * GBUFFER_TEXEL_BYTES + (texels - 2u) * FINAL_ELEMENT_BYTES);
    if (trivial >= 0.0) {
        return trivial;
    }
    let occluded = final_areas[u32(point.texel.y) * u32(textureDimensions(silhouette_area).x) + u32(point.texel.x)];
    return 1.0 - clamp(dot(occluded, vec4<f32>(0.25)), 0.0, 1.0);
}
