// SSSM step 3 (Table 1): the vertical blur over m taps, reusing a tap pixel's horizontal result
// when its camera depth differs from this pixel's tangent plane by less than β (Sec. 4.2: "the
// distance is modified taking into account the normal"), else shadow-testing that row's points
// of this pixel's tangent plane directly (which also covers taps past the screen's edges).
// Also writes the share of reused rows of both steps (Fig. 10).

// #import sssm/sssm_common.wgsl

@group(2) @binding(4) var horizontal_blocker: texture_2d<f32>;
@group(2) @binding(5) var horizontal_blur: texture_2d<f32>;
@group(2) @binding(6) var reuse_share: texture_storage_2d<r32float, write>;

@fragment
fn sssm_vertical_blur(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    // (horizontal blur, half-width along x, along y, blocker rows reused or -1).
    let own = textureLoad(horizontal_blur, point.texel, 0);
    if (own.w < 0.0) {
        // Nothing computed here (background, behind the light): -1 keeps it out of the average.
        textureStore(reuse_share, point.texel, vec4<f32>(-1.0));
        return own.x;
    }
    reads = 3u;
    let result = vertical(in, point, own);
    record_reads(2u, point.texel);
    return result;
}

fn vertical(in: FullscreenVertex, point: ScreenPoint, own: vec4<f32>) -> f32 {
    let n = f32(max(settings.blocker_kernel, 1u));
    let radii = own.yz;
    if (max(radii.x, radii.y) < 0.5) {
        // No blur: only the blocker rows counted.
        textureStore(reuse_share, point.texel, vec4<f32>(own.w / n));
        return own.x;
    }
    let m = max(settings.blur_kernel, 1u);
    let eye = camera.position.xyz;
    let rays = camera_rays();
    let own_hard = textureLoad(horizontal_blocker, point.texel, 0).w;
    reads += 1u;
    let offset = lookup_offset(point.position, point.normal);
    var blurred = 0.0;
    var total = 0.0;
    var reused = 0.0;
    for (var j = 0u; j < m; j++) {
        let row = in.clip.xy + vec2<f32>(0.0, grid_offset(j, m) * radii.y);
        var value = 0.0;
        var weight = tap_weight(j, m);
        var reuse = false;
        if (on_screen(row)) {
            let texel = vec2<i32>(row);
            let other = textureLoad(gbuffer_position, texel, 0);
            reads += 1u;
            let expected = tangent_plane_point(rays, point.position, point.normal, row);
            if (other.w > 0.5 && expected.w > 0.0 && abs(distance(other.xyz, eye) - distance(expected.xyz, eye)) < scene_length(frame, settings.beta)) {
                value = textureLoad(horizontal_blur, texel, 0).x;
                reads += 1u;
                // The same position and tangent-plane point as the β test's: not read again.
                weight *= bilateral_weight_of(other, expected, point.normal, texel);
                reuse = true;
                reused += 1.0;
            }
        }
        if (!reuse) {
            // The row recomputed on this pixel's tangent plane, with this pixel's kernel.
            var row_sum = 0.0;
            var row_total = 0.0;
            for (var i = 0u; i < m; i++) {
                let tap = row + vec2<f32>(grid_offset(i, m) * radii.x, 0.0);
                let plane = tangent_plane_point(rays, point.position, point.normal, tap);
                let visible = select(own_hard, tap_visibility(plane.xyz, offset), plane.w > 0.0);
                let inner_weight = tap_weight(i, m);
                row_sum += inner_weight * visible;
                row_total += inner_weight;
            }
            value = row_sum / row_total;
        }
        blurred += weight * value;
        total += weight;
    }
    textureStore(reuse_share, point.texel, vec4<f32>((own.w + reused) / (n + f32(m))));
    return clamp(select(own.x, blurred / total, total > 1e-6), 0.0, 1.0);
}
