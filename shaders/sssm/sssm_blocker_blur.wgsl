// SSSM step 2 (Table 1): the blocker average over the n×n window, each of its n rows reused
// from the pixel whose shadow-map position lies on that row when |d - d_t| < α (Sec. 4.1),
// else read from the depth map; the penumbra size by Eq. 1; then the horizontal screen-space
// blur of the hard shadow over m taps (Sec. 4.2).

// #import sssm/sssm_common.wgsl

@group(2) @binding(4) var horizontal_blocker: texture_2d<f32>;

// (horizontally blurred visibility, blur half-width along x and along y in pixels, blocker rows
// reused); w = -1 where nothing was computed (background, behind the light).
@fragment
fn sssm_blocker_blur(in: FullscreenVertex) -> @location(0) vec4<f32> {
    let point = screen_point(in);
    let own = textureLoad(horizontal_blocker, point.texel, 0);
    if (own.x < 0.0) {
        return vec4<f32>(own.w, 0.0, 0.0, -1.0);
    }
    reads = 3u;
    let result = blocker_and_blur(in, point, own);
    record_reads(1u, point.texel);
    return result;
}

fn blocker_and_blur(in: FullscreenVertex, point: ScreenPoint, own: vec4<f32>) -> vec4<f32> {
    let d = own.x;
    let lookup = normal_offset_position(frame, shadow_map, point.position, point.normal, settings.normal_offset);
    let uvd = light_uv_depth(frame, lookup);
    let search = light_half_extent_uv(frame, frame.projection.z, d);
    let n = max(settings.blocker_kernel, 1u);
    var sum = 0.0;
    var count = 0.0;
    var reused = 0.0;
    // The rows' points at depth d lie on a line, and clip space is linear in them: project the two ends once.
    let first_clip = camera.view_proj * vec4<f32>(light_point(vec2<f32>(uvd.x, uvd.y - search.y), d), 1.0);
    let last_clip = camera.view_proj * vec4<f32>(light_point(vec2<f32>(uvd.x, uvd.y + search.y), d), 1.0);
    for (var t = 0u; t < n; t++) {
        let row_uv = vec2<f32>(uvd.x, uvd.y + grid_offset(t, n) * search.y);
        // The pixel that sees the point of this row at the same light depth d (Fig. 4).
        let clip = mix(first_clip, last_clip, grid_offset(t, n) * 0.5 + 0.5);
        let ndc = clip.xy / clip.w;
        let screen = vec3<f32>((ndc.x * 0.5 + 0.5) * camera.viewport.x, (0.5 - ndc.y * 0.5) * camera.viewport.y, clip.w);
        var reuse = false;
        if (screen.z > 0.0 && on_screen(screen.xy)) {
            let other = textureLoad(horizontal_blocker, vec2<i32>(screen.xy), 0);
            reads += 1u;
            if (other.x >= 0.0 && abs(d - other.x) < scene_length(frame, settings.alpha)) {
                sum += other.y;
                count += other.z;
                reused += 1.0;
                reuse = true;
            }
        }
        if (!reuse) {
            for (var i = 0u; i < n; i++) {
                let tap = row_uv + vec2<f32>(grid_offset(i, n) * search.x, 0.0);
                let depth = shadow_map_depth(shadow_map, tap);
                reads += 1u;
                if (depth < compared_depth(lookup, point.normal, tap, d)) {
                    sum += depth;
                    count += 1.0;
                }
            }
        }
    }
    // No blocker: fully lit (Sec. 4.2).
    if (count == 0.0) {
        return vec4<f32>(1.0, 0.0, 0.0, reused);
    }
    let blocker = sum / count;
    // Eq. 1: w_penumbra = w_light (z_receiver - z_avg) / z_avg, as the shadow-map half-extent of
    // PCSS's filter (the same kernel pcss filters over), then laid on the receiver's tangent plane
    // and measured along each screen axis.
    let extent = light_half_extent_uv(frame, blocker, d);
    var radii = kernel_screen_radii(point.position, point.normal, light_uv_depth(frame, point.position).xy, extent);
    if (radii.x < 0.0) {
        // The plane runs along the light's rays: the width on a surface facing the camera.
        // The mean of the rectangle's half-sides: a single width.
        let light_half_size = 0.5 * (frame.u_axis.w + frame.v_axis.w);
        radii = vec2<f32>(facing_radius(point.position, light_half_size * max(d - blocker, 0.0) / max(blocker, 1e-6)));
    }
    // A penumbra under half a pixel keeps the hard value.
    if (max(radii.x, radii.y) < 0.5) {
        return vec4<f32>(own.w, 0.0, 0.0, reused);
    }
    let m = max(settings.blur_kernel, 1u);
    let rays = camera_rays();
    var blurred = 0.0;
    var total = 0.0;
    let centre = in.clip.xy;
    for (var j = 0u; j < m; j++) {
        let tap = centre + vec2<f32>(grid_offset(j, m) * radii.x, 0.0);
        var value: f32;
        var weight = tap_weight(j, m);
        if (on_screen(tap)) {
            value = textureLoad(horizontal_blocker, vec2<i32>(tap), 0).w;
            reads += 1u;
            weight *= bilateral_weight(rays, point.position, point.normal, tap);
        } else {
            // Past the screen's edge: shadow-test the point of this pixel's tangent plane seen there.
            let plane = tangent_plane_point(rays, point.position, point.normal, tap);
            value = select(own.w, hard_visibility(plane.xyz, point.normal), plane.w > 0.0);
        }
        blurred += weight * value;
        total += weight;
    }
    // Every tap on other surfaces (an even m has no centre tap): keep the hard value.
    let horizontal = select(own.w, blurred / total, total > 1e-6);
    return vec4<f32>(horizontal, radii, reused);
}
