// Shared by the three passes of Buades et al. 2015, Separable Soft Shadow Mapping.

// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl
// #import common/camera.wgsl
// #import common/read_counts.wgsl

// The settings, declared once in Rust (`SssmSettingsUniform`, ssm-techniques/sssm/src/lib.rs),
// whose derive writes this struct.
// #import rust/SssmSettings

// The settings' blur_axes.
const BLUR_ALONG_SCREEN: u32 = 0u;
const BLUR_ALONG_LIGHT: u32 = 1u;
const BLUR_AXES_AUTO: u32 = 2u;

// With BLUR_AXES_AUTO, a light whose long side is this many times its short one or more is
// blurred along its sides: the paper's screen-aligned Gaussian emulates a round light (Sec. 4.4),
// which a tube is not, and whose penumbra it would blur across the tube wherever the tube does
// not run along a screen axis.
const ELONGATED_LIGHT_RATIO: f32 = 2.0;

// Whether the blurs of this light run along its sides (the settings' blur_axes).
fn blur_along_light() -> bool {
    let long_side = max(frame.u_axis.w, frame.v_axis.w);
    let short_side = min(frame.u_axis.w, frame.v_axis.w);
    return settings.blur_axes == BLUR_ALONG_LIGHT
        || (settings.blur_axes == BLUR_AXES_AUTO && long_side >= ELONGATED_LIGHT_RATIO * short_side);
}

@group(2) @binding(0) var<uniform> camera: Camera;
@group(2) @binding(1) var<uniform> settings: SssmSettings;
@group(2) @binding(2) var shadow_map: texture_2d<f32>;
// Per pass (0 horizontal blocker, 1 blocker and horizontal blur, 2 vertical blur): (pixels,
// reads) per bucket (common/read_counts.wgsl); then the failed rows' counters
// (FAILED_ROW_COUNTERS) and each pass's (pixels, bytes read) (READ_BYTES_COUNTERS).
@group(2) @binding(3) var<storage, read_write> read_counts: array<atomic<u32>>;

// Texel reads of this invocation so far, each a textureLoad of one texel (nearest, no sampler):
// the G-buffer's two at every pixel of the screen, trivial ones (background, trivially lit or
// dark) included, and in steps 2 and 3 the pixel's own texel of the previous step's target, also
// at every pixel; then a computed pixel's shadow-map taps (one each; a tap past the map's border
// counts as one, though shadow_map_depth fetches nothing there), the previous steps' texels its
// rows and blur taps read, and in the compute passes the texels of the shared segment this
// invocation loaded (a tap that reads workgroup memory is not a texel read).
var<private> reads: u32 = 0u;

// The bytes those reads fetched, each texel its format's size: a G-buffer texel (position or
// normal: Rgba32Float, ssm-core's GBuffer::POSITION_FORMAT, NORMAL_FORMAT) 16, a texel of the
// passes' own screen targets (horizontal_blocker, blur_source, horizontal_blur,
// vertical_tap_source: Rgba32Float, sssm's SCREEN_TARGET_FORMAT) 16, a shadow-map depth
// (R32Float, LightDepthMap::FORMAT; a tap past the border, counted as a read, counts a texel's
// bytes too) 4. A tap read from a shared segment's workgroup memory is no read and no bytes.
var<private> read_bytes: u32 = 0u;
const GBUFFER_TEXEL_BYTES: u32 = 16u;
const SCREEN_TARGET_TEXEL_BYTES: u32 = 16u;
const SHADOW_MAP_TEXEL_BYTES: u32 = 4u;

// A pixel's own G-buffer texels (position and normal) and, in steps 2 and 3, its own texel of the
// previous step's target: the reads at every pixel of the screen.
fn count_own_texels(previous_step: bool) {
    reads = 2u + select(0u, 1u, previous_step);
    read_bytes = 2u * GBUFFER_TEXEL_BYTES + select(0u, SCREEN_TARGET_TEXEL_BYTES, previous_step);
}

// One texel read of a shadow map, and one of a screen target, counted with their bytes.
fn count_shadow_map_read() {
    reads += 1u;
    read_bytes += SHADOW_MAP_TEXEL_BYTES;
}

fn count_screen_target_read() {
    reads += 1u;
    read_bytes += SCREEN_TARGET_TEXEL_BYTES;
}

// Rows of this invocation's kernel that failed their reuse test (α in step 2, β in step 3), by
// cause, when counting: the row's pixel lies off the screen (with CLAMP_EDGE_ROWS, only a
// blocker row behind the eye: the others are read from the edge and fail, if at all, by the
// next two causes); it holds nothing the test can use (step 1 computed nothing there: no
// surface, or trivially lit or dark; in step 3, no surface); or it holds a value whose depth
// differs by the threshold or more. Only the last depends on α and β: the first two are rows the
// screen cannot supply at any threshold.
var<private> failed_rows_off_screen: u32;
var<private> failed_rows_no_data: u32;
var<private> failed_rows_depth: u32;

// The counters after the three passes' read counts (sssm's COUNTED): the causes of step 2's
// failed blocker rows at 3-5, of step 3's failed blur rows at 6-8.
const FAILED_ROW_COUNTERS: u32 = 3u;
// The first pass's bytes-read counter, after the failed rows' (sssm's COUNTED): pass k's at 9 + k.
const READ_BYTES_COUNTERS: u32 = 9u;

// Counts a kernel row that failed its reuse test, by cause (see failed_rows_off_screen), when counting.
fn count_failed_row(off_screen: bool, no_data: bool) {
    if (COUNT_READS) {
        failed_rows_off_screen += select(0u, 1u, off_screen);
        failed_rows_no_data += select(0u, 1u, !off_screen && no_data);
        failed_rows_depth += select(0u, 1u, !off_screen && !no_data);
    }
}

// Adds this invocation's pixel and its reads to pass `pass_index`'s counts, when counting
// (COUNT_READS): at every pixel of the screen, computed or not.
fn record_reads(pass_index: u32, texel: vec2<i32>) {
    record_reads_of(pass_index, texel, 1u);
}

// Adds `pixels` (0 or 1) and this invocation's reads and their bytes to pass `pass_index`'s counts, when counting:
// 0 for a compute invocation past the screen's edge, which only loaded its share of a workgroup's
// shared segment, so that the invocations counted are the screen's pixels in every variant.
fn record_reads_of(pass_index: u32, texel: vec2<i32>, pixels: u32) {
    if (COUNT_READS && (pixels != 0u || reads != 0u)) {
        let word = read_count_word(pass_index, texel);
        atomicAdd(&read_counts[word], pixels);
        atomicAdd(&read_counts[word + 1u], reads);
        let bytes_word = read_count_word(READ_BYTES_COUNTERS + pass_index, texel);
        atomicAdd(&read_counts[bytes_word], pixels);
        atomicAdd(&read_counts[bytes_word + 1u], read_bytes);
    }
}

// Adds a computed pixel's failed rows of step 2 (`pass_index` 1) or step 3 (2), by cause, to
// their counters (diagnostics per computed pixel, not work: ReadCounts::work leaves their unit,
// rows, out), when counting.
fn record_failed_rows(pass_index: u32, texel: vec2<i32>) {
    if (COUNT_READS) {
        let first = 3u + (pass_index - 1u) * FAILED_ROW_COUNTERS;
        let causes = array<u32, 3>(failed_rows_off_screen, failed_rows_no_data, failed_rows_depth);
        for (var cause = 0u; cause < FAILED_ROW_COUNTERS; cause++) {
            let word = read_count_word(first + cause, texel);
            atomicAdd(&read_counts[word], 1u);
            atomicAdd(&read_counts[word + 1u], causes[cause]);
        }
    }
}

// The shadow map's depth at `uv`: one texel read (a textureLoad; counted by the caller).
fn tap_depth(uv: vec2<f32>) -> f32 {
    return shadow_map_depth(shadow_map, uv);
}

// The partial blocker sum and count (Sec. 4.1) of the n taps of the shadow-map row through
// `row_uv`, `half_width` either side along u: partial_blocker_sum = Σ dm(x, t) over the taps
// nearer the light than `receiver` (the receiver's depth, or its tangent plane along each tap's
// ray), and partial_blocker_count their number. Step 1's row, and a row step 2 reads because its
// reuse test failed (Table 1: "for each (x point) get data from DepthMap"). n texel reads.
fn blocker_row(row_uv: vec2<f32>, half_width: f32, receiver: TapPlane, n: u32) -> vec2<f32> {
    var sum = 0.0;
    var count = 0.0;
    for (var i = 0u; i < n; i++) {
        let tap = row_uv + vec2<f32>(grid_offset(i, n) * half_width, 0.0);
        let depth = tap_depth(tap);
        count_shadow_map_read();
        if (depth < tap_plane_depth(receiver, tap)) {
            sum += depth;
            count += 1.0;
        }
    }
    return vec2<f32>(sum, count);
}

// The weight of a blur tap at offset `offset` in [-1, 1] of the kernel's half-width (Sec. 4.4:
// a Gaussian of σ half-widths, the paper's N(0, 0.5), or 1 for the mean filter).
fn blur_weight(offset: f32) -> f32 {
    // With filter = auto, the box along the light's sides: it is the uniform light's own profile
    // (PCSS's filter), and the Gaussian's reason, hiding the screen alignment of a box (Sec. 4.4),
    // does not arise there.
    let exponent = select(settings.blur_weight_exponent, 0.0, settings.box_along_light != 0u && blur_along_light());
    return exp(-exponent * offset * offset);
}

// The world point at shadow-map coordinates `uv` and linear light depth `depth` (inverse of light_uv_depth).
fn light_point(uv: vec2<f32>, depth: f32) -> vec3<f32> {
    let xy = (uv * 2.0 - 1.0) * depth * frame.projection.xy;
    return frame.centre.xyz + xy.x * frame.u_axis.xyz + xy.y * frame.v_axis.xyz + depth * frame.normal.xyz;
}

// Camera rays, unnormalised, as an affine function of the pixel position: for a perspective
// camera the far-plane points' homogeneous w is the same at every pixel, so the ray through pixel
// (x, y) is base + x·per_x + y·per_y exactly. Built once per pixel, each tap then costs a few
// multiply-adds instead of a matrix product and a normalisation.
struct CameraRays {
    base: vec3<f32>,
    per_x: vec3<f32>,
    per_y: vec3<f32>,
};

fn far_point(pixel: vec2<f32>) -> vec3<f32> {
    let ndc = vec2<f32>(pixel.x / camera.viewport.x * 2.0 - 1.0, 1.0 - pixel.y / camera.viewport.y * 2.0);
    let far = camera.inverse_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    return far.xyz / far.w;
}

fn camera_rays() -> CameraRays {
    let origin = far_point(vec2<f32>(0.0)) - camera.position.xyz;
    let at_x = far_point(vec2<f32>(1.0, 0.0)) - camera.position.xyz;
    let at_y = far_point(vec2<f32>(0.0, 1.0)) - camera.position.xyz;
    return CameraRays(origin, at_x - origin, at_y - origin);
}

// The camera ray through pixel position `pixel` (xyz, unnormalised) and the parameter t (w) at
// which it meets the plane through `point` with normal `normal`; t = -1 where the ray runs along
// the plane or meets it behind the eye.
fn tangent_plane_hit(rays: CameraRays, point: vec3<f32>, normal: vec3<f32>, pixel: vec2<f32>) -> vec4<f32> {
    let direction = rays.base + pixel.x * rays.per_x + pixel.y * rays.per_y;
    let denominator = dot(direction, normal);
    if (abs(denominator) < 1e-12) {
        return vec4<f32>(direction, -1.0);
    }
    let t = dot(point - camera.position.xyz, normal) / denominator;
    return vec4<f32>(direction, select(-1.0, t, t > 0.0));
}

// Where the camera ray through pixel position `pixel` meets the plane through `point` with
// normal `normal`; w = 0 when the ray runs along the plane or meets it behind the eye.
fn tangent_plane_point(rays: CameraRays, point: vec3<f32>, normal: vec3<f32>, pixel: vec2<f32>) -> vec4<f32> {
    let hit = tangent_plane_hit(rays, point, normal, pixel);
    return vec4<f32>(camera.position.xyz + hit.xyz * max(hit.w, 0.0), select(0.0, 1.0, hit.w > 0.0));
}

// The eye's distance to the tangent plane through `point` (normal `normal`) along the camera ray
// through pixel position `pixel`: what the bilateral weight and step 3's β test compare a tap
// pixel's own distance with. -1 where the ray runs along the plane or meets it behind the eye.
fn plane_distance(rays: CameraRays, point: vec3<f32>, normal: vec3<f32>, pixel: vec2<f32>) -> f32 {
    let hit = tangent_plane_hit(rays, point, normal, pixel);
    return select(-1.0, hit.w * length(hit.xyz), hit.w > 0.0);
}

// Hard visibility of a world point seen with normal `normal` (the shadow test of Step 1).
fn hard_visibility(world: vec3<f32>, normal: vec3<f32>) -> f32 {
    return tap_visibility(world, lookup_offset(world, normal));
}

// The normal offset of a pixel's lookups, computed once: every tap on its tangent plane shares it.
fn lookup_offset(point: vec3<f32>, normal: vec3<f32>) -> vec3<f32> {
    return normal_offset_position(frame, shadow_map, point, normal, settings.normal_offset) - point;
}

// Hard visibility of a tap on a pixel's tangent plane, with that pixel's lookup offset: one
// texel read, none behind the light's plane.
fn tap_visibility(world: vec3<f32>, offset: vec3<f32>) -> f32 {
    if (!in_front_of_light(frame, world)) {
        return 0.0;
    }
    let uvd = light_uv_depth(frame, world + offset);
    count_shadow_map_read();
    return select(0.0, 1.0, uvd.z <= tap_depth(uvd.xy));
}

// Whether a pixel position lies on the screen.
fn on_screen(pixel: vec2<f32>) -> bool {
    return all(pixel >= vec2<f32>(0.0)) && all(pixel < camera.viewport.xy);
}

// Whether steps 2 and 3 read a blocker row or a blur row that falls past the screen's edges from
// the nearest pixel on the screen, and reuse it when it passes the reuse test (α, β), as a
// screen-space pass reading through a clamp-to-edge sampler would (the settings' edge_rows =
// clamp). The paper only says that filtering there is "not possible" (Sec. 4.2: "in the upper
// and bottom borders of the screen, which would need information that falls out of the
// screen"), not how its passes read there. Otherwise (recompute) such a row is read from the
// depth map, as a failed test's is. A row costs n or m taps, so these rows are a large share of the
// work near the borders; the horizontal blur's single taps past the edges are shadow-tested either
// way. A constant of the pipeline.
override CLAMP_EDGE_ROWS: bool = false;

// Whether a row at pixel position `pixel` is read from the screen (at clamped_texel): on the
// screen, or anywhere with CLAMP_EDGE_ROWS.
fn row_read_from_screen(pixel: vec2<f32>) -> bool {
    return CLAMP_EDGE_ROWS || on_screen(pixel);
}

// The pixel on the screen nearest pixel position `pixel` (the pixel itself when on the screen).
fn clamped_texel(pixel: vec2<f32>) -> vec2<i32> {
    return clamp(vec2<i32>(floor(pixel)), vec2<i32>(0), vec2<i32>(camera.viewport.xy) - 1);
}

// Half-width in pixels of a blur `half_width` world units wide on a surface at `world` facing the
// camera: the fallback where the kernel's footprint on the tangent plane cannot be found.
fn facing_radius(world: vec3<f32>, half_width: f32) -> f32 {
    let centre = camera.viewport.xy * 0.5;
    let eye = camera.position.xyz;
    let forward = normalize(far_point(centre) - eye);
    // World size of one pixel per unit of distance along the view direction.
    let far = far_point(centre);
    let pixel_scale = distance(far, far_point(centre + vec2<f32>(0.0, 1.0))) / dot(far - eye, forward);
    return half_width / max(dot(world - eye, forward) * pixel_scale, 1e-9);
}

// What shadow-map taps compare with, prepared once per point (the receiver model shared with pcss):
// read at a tap with tap_plane_depth.
fn compared_plane(position: vec3<f32>, normal: vec3<f32>, receiver_depth: f32) -> TapPlane {
    return receiver_tap_plane(frame, position, normal, receiver_depth, settings.receiver_plane != 0u);
}

// Pixel position of a world point, w = 0 behind the eye.
fn screen_position(world: vec3<f32>) -> vec3<f32> {
    let clip = camera.view_proj * vec4<f32>(world, 1.0);
    if (clip.w <= 0.0) {
        return vec3<f32>(0.0);
    }
    let ndc = clip.xy / clip.w;
    return vec3<f32>((ndc.x * 0.5 + 0.5) * camera.viewport.x, (0.5 - ndc.y * 0.5) * camera.viewport.y, 1.0);
}

// Pixel position of the point of the tangent plane through `point` (normal `normal`) seen from the
// light's centre at shadow-map coordinates `uv`; w = 0 where the ray misses the plane.
fn plane_screen_position(point: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>) -> vec3<f32> {
    let depth = receiver_plane_depth(frame, point, normal, uv, -1.0);
    if (depth <= 0.0) {
        return vec3<f32>(0.0);
    }
    return screen_position(light_point(uv, depth));
}

// The PCF kernel of shadow-map half-extent `extent` around `uv` laid on the receiver's tangent
// plane through `point` (normal `normal`) and projected onto the screen: its two half-axes, the
// light's two sides, as screen vectors a (along u) and b (along v), in pixels (the paper projects
// the penumbra into screen space, Sec. 4.2). `found` is false where the plane runs along the
// light's rays or behind the eye.
struct KernelAxes {
    a: vec2<f32>,
    b: vec2<f32>,
    found: bool,
};

fn kernel_screen_axes(point: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, extent: vec2<f32>) -> KernelAxes {
    let right = plane_screen_position(point, normal, uv + vec2<f32>(extent.x, 0.0));
    let left = plane_screen_position(point, normal, uv - vec2<f32>(extent.x, 0.0));
    let down = plane_screen_position(point, normal, uv + vec2<f32>(0.0, extent.y));
    let up = plane_screen_position(point, normal, uv - vec2<f32>(0.0, extent.y));
    if (right.z * left.z * down.z * up.z == 0.0) {
        return KernelAxes(vec2<f32>(0.0), vec2<f32>(0.0), false);
    }
    return KernelAxes(0.5 * (right.xy - left.xy), 0.5 * (down.xy - up.xy), true);
}

// The blur's two half-axes in pixels: step 2 blurs along `first`, step 3 along `second`.
struct BlurAxes {
    first: vec2<f32>,
    second: vec2<f32>,
};

// `axis` no longer than a few screens: a plane at a grazing angle to the light stretches the
// kernel without bound.
fn screen_capped(axis: vec2<f32>) -> vec2<f32> {
    let cap = 4.0 * max(camera.viewport.x, camera.viewport.y);
    return axis * min(1.0, cap / max(length(axis), 1e-12));
}

// The blur that stands for PCSS's filter at a pixel at `point` whose blocker average is `blocker`
// at light depth `d` (Eq. 1; blocker > 0), computed alike by steps 2 and 3. Along the screen (the
// paper's rows and columns): each pass takes the root-sum-square of the projected kernel's axes'
// components along its axis, the box with the projected parallelogram's second moments (on a
// surface seen at an angle the vertical width shrinks with the foreshortening, as it must).
// Along the light: the passes run along the projected axes themselves, so the blur is the
// projected kernel's parallelogram, which follows a tube light's two sides at any angle to the
// screen (a separable filter along any two directions is still the product of two 1-D ones).
fn blur_axes(point: ScreenPoint, blocker: f32, d: f32) -> BlurAxes {
    let extent = light_half_extent_uv(frame, blocker, d);
    let kernel = kernel_screen_axes(point.position, point.normal, light_uv_depth(frame, point.position).xy, extent);
    if (!kernel.found) {
        // The plane runs along the light's rays: the width on a surface facing the camera, the
        // mean of the rectangle's half-sides, a single width.
        let light_half_size = 0.5 * (frame.u_axis.w + frame.v_axis.w);
        let radius = facing_radius(point.position, light_half_size * max(d - blocker, 0.0) / max(blocker, 1e-6));
        return BlurAxes(vec2<f32>(radius, 0.0), vec2<f32>(0.0, radius));
    }
    if (blur_along_light()) {
        return BlurAxes(screen_capped(kernel.a), screen_capped(kernel.b));
    }
    let radii = min(sqrt(kernel.a * kernel.a + kernel.b * kernel.b), 4.0 * camera.viewport.xy);
    return BlurAxes(vec2<f32>(radii.x, 0.0), vec2<f32>(0.0, radii.y));
}

// Whether a blur is narrower than half a pixel along both axes (the hard value stands).
fn under_half_a_pixel(axes: BlurAxes) -> bool {
    return max(length(axes.first), length(axes.second)) < 0.5;
}

// What a blur tap needs of the pixel it lands on: the value blurred there, and what the bilateral
// weight and the vertical pass's β test compare with this pixel's tangent plane.
struct BlurSource {
    value: f32,
    // Distance from the eye to the surface seen there; -1 where nothing covers the pixel.
    eye_distance: f32,
    // Its unit normal (zero where nothing covers the pixel).
    normal: vec3<f32>,
};

// What step 1 writes per pixel for the blurs (the `blur_source` target), so that a blur tap
// reads one texel instead of the hard value's and the G-buffer's two: the unit normal in xyz, and
// in w the distance from the eye, negated where the hard shadow test failed (the hard value is 0
// or 1, and a covered pixel lies beyond the near plane, so the distance is never 0); w = 0 where
// nothing covers the pixel.
fn packed_blur_source(hard: f32, point: ScreenPoint) -> vec4<f32> {
    if (!point.covered) {
        return vec4<f32>(0.0);
    }
    let eye_distance = distance(point.position, camera.position.xyz);
    return vec4<f32>(point.normal, select(-eye_distance, eye_distance, hard >= 0.5));
}

// The hard value of a `blur_source` texel (1 where nothing covers the pixel).
fn packed_hard_value(packed: vec4<f32>) -> f32 {
    return select(1.0, 0.0, packed.w < 0.0);
}

// The BlurSource of a `blur_source` texel, blurring `value`.
fn unpack_blur_source(value: f32, packed: vec4<f32>) -> BlurSource {
    if (packed.w == 0.0) {
        return BlurSource(value, -1.0, vec3<f32>(0.0));
    }
    return BlurSource(value, abs(packed.w), packed.xyz);
}

// What step 2 writes per pixel for the vertical blur's taps (the `vertical_tap_source` target),
// so that a tap reads one texel instead of step 2's result and step 1's blur source: the
// horizontally blurred `value` in x, the distance from the eye in y (0 where nothing covers the
// pixel), its sign the sign of the normal's z, and the normal's x and y in z and w (its z follows
// from them: a unit vector).
fn packed_vertical_tap_source(value: f32, point: ScreenPoint) -> vec4<f32> {
    if (!point.covered) {
        return vec4<f32>(value, 0.0, 0.0, 0.0);
    }
    let eye_distance = distance(point.position, camera.position.xyz);
    return vec4<f32>(value, select(-eye_distance, eye_distance, point.normal.z >= 0.0), point.normal.xy);
}

// The BlurSource of a `vertical_tap_source` texel.
fn unpack_vertical_tap_source(packed: vec4<f32>) -> BlurSource {
    if (packed.y == 0.0) {
        return BlurSource(packed.x, -1.0, vec3<f32>(0.0));
    }
    let normal_z = sqrt(max(1.0 - dot(packed.zw, packed.zw), 0.0));
    return BlurSource(packed.x, abs(packed.y), vec3<f32>(packed.zw, select(-normal_z, normal_z, packed.y > 0.0)));
}

// Bilateral weight of a blur tap landing on `source`, for a pixel of normal `normal`, where
// `expected_distance` is the eye's distance to this pixel's tangent plane along the tap pixel's
// ray (plane_distance): how much the surface seen there looks like this pixel's tangent plane, by
// the difference of camera distances (the distance of the vertical pass's β test) and of
// normals. Taps on another object across a silhouette get no weight, so shadow does not leak over
// edges. 1 with bilateral_depth = 0 (the paper's plain blur).
fn bilateral_weight_of(normal: vec3<f32>, source: BlurSource, expected_distance: f32) -> f32 {
    if (settings.bilateral_depth <= 0.0) {
        return 1.0;
    }
    if (source.eye_distance < 0.0 || expected_distance < 0.0) {
        return 0.0;
    }
    let gap = (source.eye_distance - expected_distance) / scene_length(frame, settings.bilateral_depth);
    let turn = max(dot(normal, source.normal), 0.0);
    // turn⁸: the normal term falls to 1/2 at about 23°.
    let turn_2 = turn * turn;
    let turn_4 = turn_2 * turn_2;
    return exp(-gap * gap) * turn_4 * turn_4;
}

// Whether the tap pixel seen as `source` lies within β of this pixel's tangent plane along its ray
// (`expected_distance` from the eye; the vertical pass's reuse test, Sec. 4.2: "the distance is
// modified taking into account the normal").
fn within_beta(source: BlurSource, expected_distance: f32) -> bool {
    return source.eye_distance >= 0.0 && expected_distance >= 0.0
        && abs(source.eye_distance - expected_distance) < scene_length(frame, settings.beta);
}
