// The penumbra wedges of one silhouette buffer (Forest et al., Sec. 3.1 and
// 4.2-4.3): every silhouette half-edge's wedge is drawn as its convex
// polyhedron (the edge, the two tangent planes, the two side planes, the far
// plane), back faces only, so that each pixel whose view ray crosses it runs
// one fragment. The fragment takes the point p the stencil test judged (the
// G-buffer's point moved by the depth copy's bias along the view ray) and
//
// 1. finds its half-wedge by the split plane (the shadow-volume side through
//    the light's centre): inner, towards the umbra, or outer (Fig. 8), and
//    rejects p outside that half's three bounding planes, its tangent plane
//    and the two side planes (Lengyel 2005's quick test, Fig. 7);
// 2. clips the edge to the part between the light's plane and p (Lengyel's
//    local near plane, Fig. 9), in homogeneous light-plane coordinates so
//    that a point nearly level with p stays exact;
// 3. projects it from p onto the light, normalised to [-1, 1]^2 (the light's
//    left and bottom borders at -1, right and top at 1, Sec. 4.2), and, for
//    each of the four radial parts (the quadrants around the light's centre,
//    Fig. 6), clips it to the part and integrates from the centre the area
//    beyond it (Assarsson and Akenine-Möller 2003; Fig. 4): added by outer
//    half-wedges, subtracted by inner ones;
// 4. writes, per radial part, that area, the bounding rectangle of the
//    occluded region beyond an outer edge, and for inner edges the maximum X
//    and Y of the occluded region between the centre and the edge: the
//    paper's seven parameters per radial part (Sec. 4.3, Fig. 10, Fig. 11).
//
// Seven Rgba32Float targets: areas (added), four outer rectangles and two
// pairs of inner maxima (kept by maximum); and an R32Float target that counts
// the fragments shaded (added; a counter in a storage buffer would be a side
// effect, which turns off early depth testing). Back faces are depth-tested
// against the scene (GreaterEqual, not written): a surface behind the whole
// wedge is rejected before shading.

// #import common/light_frame.wgsl
// #import common/camera.wgsl
// #import wedges/wedges_common.wgsl
// #import wedges/wedges_counts.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
@group(1) @binding(0) var<uniform> camera: Camera;

@group(2) @binding(0) var<storage, read> half_edges: array<WedgeRecord>;
@group(2) @binding(1) var<uniform> settings: WedgesSettings;
@group(2) @binding(2) var<storage, read_write> read_counts: array<atomic<u32>>;

@group(3) @binding(0) var gbuffer_position: texture_2d<f32>;
@group(3) @binding(1) var gbuffer_normal: texture_2d<f32>;

// Fragment kind of a fallback pyramid: its four bounding planes are all tested. Every other
// wedge is kind 0: a proper wedge tests its half's three planes, and a fallback wedge drawn as a
// screen rectangle keeps NO_PLANE for all four, so the same tests reject nothing.
const KIND_PYRAMID: u32 = 4u;

struct WedgeVarying {
    @builtin(position) clip: vec4<f32>,
    // The half-edge.
    @location(0) @interpolate(flat) index: u32,
    // KIND_PYRAMID, or 0.
    @location(1) @interpolate(flat) kind: u32,
    // Bounding planes (unit normal, offset), inside where dot(normal, p) >= offset: the
    // inner and outer tangent planes, and the side planes at a' and b'.
    @location(2) @interpolate(flat) inner: vec4<f32>,
    @location(3) @interpolate(flat) outer: vec4<f32>,
    @location(4) @interpolate(flat) side0: vec4<f32>,
    @location(5) @interpolate(flat) side1: vec4<f32>,
};

// The plane through three points, oriented so that `inside` is on its positive side.
fn oriented_plane(p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>, inside: vec3<f32>) -> vec4<f32> {
    var normal = cross(p1 - p0, p2 - p0);
    let length_ = length(normal);
    if (length_ <= 0.0) {
        // Degenerate: a plane that rejects nothing.
        return vec4<f32>(0.0, 0.0, 0.0, -1e30);
    }
    normal = normal / length_;
    if (dot(normal, inside - p0) < 0.0) {
        normal = -normal;
    }
    return vec4<f32>(normal, dot(normal, p0));
}

// Corners (into a', b', Fi0, Fi1, Fo0, Fo1) of the eight triangles of a wedge.
const WEDGE_TRIANGLES = array<vec3<u32>, 8>(
    // The inner tangent plane: a', b', Fi1, Fi0.
    vec3<u32>(0u, 1u, 3u), vec3<u32>(0u, 3u, 2u),
    // The outer tangent plane: a', b', Fo1, Fo0.
    vec3<u32>(0u, 1u, 5u), vec3<u32>(0u, 5u, 4u),
    // The side planes.
    vec3<u32>(0u, 2u, 4u), vec3<u32>(1u, 3u, 5u),
    // The far plane: Fi0, Fi1, Fo1, Fo0.
    vec3<u32>(2u, 3u, 5u), vec3<u32>(2u, 5u, 4u),
);

const NO_PLANE = vec4<f32>(0.0, 0.0, 0.0, -1e30);

// Corners (into apex, R0, R1, R2, R3) of the six triangles of a fallback pyramid.
const PYRAMID_TRIANGLES = array<vec3<u32>, 6>(
    vec3<u32>(0u, 1u, 2u), vec3<u32>(0u, 2u, 3u), vec3<u32>(0u, 3u, 4u), vec3<u32>(0u, 4u, 1u),
    vec3<u32>(1u, 2u, 3u), vec3<u32>(1u, 3u, 4u),
);

@vertex
fn wedges_wedge_vertex(@builtin(vertex_index) vertex: u32) -> WedgeVarying {
    let index = vertex / WEDGE_VERTICES;
    let triangle = (vertex % WEDGE_VERTICES) / 3u;
    let corner = vertex % 3u;
    let record = half_edges[index];
    let flags = bitcast<u32>(record.outer1.w);
    var out: WedgeVarying;
    out.index = index;
    out.kind = 0u;
    out.inner = NO_PLANE;
    out.outer = NO_PLANE;
    out.side0 = NO_PLANE;
    out.side1 = NO_PLANE;
    // Outside the clip volume: no fragment.
    out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
    if ((flags & WEDGE_EMPTY) != 0u) {
        return out;
    }
    let a = record.a.xyz;
    let b = record.b.xyz;
    if ((flags & WEDGE_PYRAMID) != 0u) {
        // The pyramid from the apex to the far rectangle: its four side planes bound it.
        out.kind = KIND_PYRAMID;
        let apex = select(mix(a, b, record.a.w), mix(a, b, record.b.w), (flags & WEDGE_APEX_B) != 0u);
        let pyramid = array<vec3<f32>, 5>(apex, record.inner0.xyz, record.inner1.xyz, record.outer0.xyz, record.outer1.xyz);
        let centroid = (apex + pyramid[1] + pyramid[2] + pyramid[3] + pyramid[4]) * 0.2;
        if (triangle < 6u) {
            var corners = PYRAMID_TRIANGLES[triangle];
            let p0 = pyramid[corners.x];
            let p1 = pyramid[corners.y];
            let p2 = pyramid[corners.z];
            if (dot(cross(p1 - p0, p2 - p0), (p0 + p1 + p2) / 3.0 - centroid) < 0.0) {
                corners = corners.xzy;
            }
            out.clip = camera.view_proj * vec4<f32>(pyramid[corners[corner]], 1.0);
        }
        out.inner = oriented_plane(apex, pyramid[1], pyramid[2], centroid);
        out.outer = oriented_plane(apex, pyramid[2], pyramid[3], centroid);
        out.side0 = oriented_plane(apex, pyramid[3], pyramid[4], centroid);
        out.side1 = oriented_plane(apex, pyramid[4], pyramid[1], centroid);
        return out;
    }
    if ((flags & WEDGE_FALLBACK) != 0u) {
        // The screen-space bounding box of the fallback hull: the clipped edge and the far rectangle.
        if (triangle < 2u) {
            let hull = array<vec3<f32>, 6>(
                mix(a, b, record.a.w), mix(a, b, record.b.w), record.inner0.xyz, record.inner1.xyz, record.outer0.xyz, record.outer1.xyz,
            );
            var low = vec2<f32>(1.0);
            var high = vec2<f32>(-1.0);
            var behind = false;
            for (var k = 0u; k < 6u; k += 1u) {
                let clip = camera.view_proj * vec4<f32>(hull[k], 1.0);
                if (clip.w <= 1e-6 * max(abs(clip.x), abs(clip.y))) {
                    behind = true;
                } else {
                    low = min(low, clip.xy / clip.w);
                    high = max(high, clip.xy / clip.w);
                }
            }
            if (behind) {
                // Part of the hull is behind the camera: its projection is unbounded.
                low = vec2<f32>(-1.0);
                high = vec2<f32>(1.0);
            }
            low = clamp(low, vec2<f32>(-1.0), vec2<f32>(1.0));
            high = clamp(high, vec2<f32>(-1.0), vec2<f32>(1.0));
            // Two triangles wound as back faces (clockwise on screen), at the far depth.
            let rectangle = array<vec2<f32>, 6>(low, vec2<f32>(low.x, high.y), high, low, high, vec2<f32>(high.x, low.y));
            out.clip = vec4<f32>(rectangle[triangle * 3u + corner], 1.0, 1.0);
        }
        return out;
    }
    var points = array<vec3<f32>, 6>(
        mix(a, b, record.a.w), mix(a, b, record.b.w), record.inner0.xyz, record.inner1.xyz, record.outer0.xyz, record.outer1.xyz,
    );
    let centroid = (points[0] + points[1] + points[2] + points[3] + points[4] + points[5]) / 6.0;
    var corners = WEDGE_TRIANGLES[triangle];
    let p0 = points[corners.x];
    let p1 = points[corners.y];
    let p2 = points[corners.z];
    // Wind every face outwards, so that culling front faces keeps the back faces.
    if (dot(cross(p1 - p0, p2 - p0), (p0 + p1 + p2) / 3.0 - centroid) < 0.0) {
        corners = corners.xzy;
    }
    out.clip = camera.view_proj * vec4<f32>(points[corners[corner]], 1.0);
    out.inner = oriented_plane(points[0], points[1], points[2], centroid);
    out.outer = oriented_plane(points[0], points[1], points[4], centroid);
    out.side0 = oriented_plane(points[0], points[2], points[4], centroid);
    out.side1 = oriented_plane(points[1], points[3], points[5], centroid);
    return out;
}

// A segment in homogeneous light-plane coordinates (x, y, w), w > 0.
struct Segment {
    h0: vec3<f32>,
    h1: vec3<f32>,
    ok: bool,
};

// The part of a segment where an affine function, f0 at h0 and f1 at h1, is >= 0.
fn clip_segment(segment: Segment, f0: f32, f1: f32) -> Segment {
    if (!segment.ok || (f0 < 0.0 && f1 < 0.0)) {
        return Segment(segment.h0, segment.h1, false);
    }
    var out = segment;
    if (f0 < 0.0) {
        out.h0 = mix(segment.h0, segment.h1, f0 / (f0 - f1));
    } else if (f1 < 0.0) {
        out.h1 = mix(segment.h0, segment.h1, f0 / (f0 - f1));
    }
    return out;
}

// Position along the boundary of the unit quadrant [0, 1]^2 seen from the centre in
// direction d (d >= 0, not 0): 0 to 1 up the right side, 1 to 2 leftwards along the
// top. The area the direction sweeps from the centre is half the distance travelled.
fn perimeter(d: vec2<f32>) -> f32 {
    if (d.x >= d.y) {
        return d.y / d.x;
    }
    return 2.0 - d.x / d.y;
}

// Where the ray from the centre in direction d leaves the unit quadrant.
fn exit_point(d: vec2<f32>) -> vec2<f32> {
    return d / max(d.x, d.y);
}

// What one projected edge contributes to one radial part.
struct RadialPart {
    // Area of the part beyond the edge, seen from the centre (the part's own area is 1).
    area: f32,
    // Bounding rectangle of that area, as (1 - xmin, xmax, 1 - ymin, ymax) (zero: empty).
    rect: vec4<f32>,
    // Largest x and y of the part between the centre and the edge.
    inner_max: vec2<f32>,
};

// The radial part whose axes point along `mirror` (each ±1), in its own coordinates
// (both >= 0) where it is the unit square: Sec. 4.3's clip of the edge to the part,
// then Fig. 4's integration from the centre.
fn radial_part(segment: Segment, mirror: vec2<f32>) -> RadialPart {
    var part = RadialPart(0.0, vec4<f32>(0.0), vec2<f32>(0.0));
    var s = Segment(vec3<f32>(segment.h0.xy * mirror, segment.h0.z), vec3<f32>(segment.h1.xy * mirror, segment.h1.z), segment.ok);
    // Clip to the part's sector: x >= 0, y >= 0.
    s = clip_segment(s, s.h0.x, s.h1.x);
    s = clip_segment(s, s.h0.y, s.h1.y);
    if (!s.ok) {
        return part;
    }
    let d0 = s.h0.xy;
    let d1 = s.h1.xy;
    // An end at the centre itself: p lies on the split plane, where the sign is undecided.
    if (max(d0.x, d0.y) <= 1e-7 * s.h0.z || max(d1.x, d1.y) <= 1e-7 * s.h1.z) {
        return part;
    }
    // Clip to the light: x <= 1, y <= 1 (x <= w, y <= w in homogeneous coordinates).
    var k = clip_segment(s, s.h0.z - s.h0.x, s.h1.z - s.h1.x);
    k = clip_segment(k, k.h0.z - k.h0.y, k.h1.z - k.h1.y);
    var inner_max = vec2<f32>(0.0);
    if (k.ok) {
        let a = clamp(k.h0.xy / k.h0.z, vec2<f32>(0.0), vec2<f32>(1.0));
        let b = clamp(k.h1.xy / k.h1.z, vec2<f32>(0.0), vec2<f32>(1.0));
        if (max(a.x, a.y) > 0.0 && max(b.x, b.y) > 0.0) {
            // Fig. 4: the sector between the directions of a and b, minus the triangle (centre, a, b).
            let sector = 0.5 * abs(perimeter(b) - perimeter(a));
            let triangle = 0.5 * abs(a.x * b.y - a.y * b.x);
            part.area = max(sector - triangle, 0.0);
            let ea = exit_point(a);
            let eb = exit_point(b);
            let low = min(min(a, b), min(ea, eb));
            let high = max(max(a, b), max(ea, eb));
            if (part.area > 0.0) {
                part.rect = vec4<f32>(1.0 - low.x, high.x, 1.0 - low.y, high.y);
            }
            inner_max = max(a, b);
        }
    }
    // Where the edge runs outside the light, the region between centre and edge reaches the border.
    if (s.h0.x > s.h0.z || s.h0.y > s.h0.z) {
        inner_max = max(inner_max, exit_point(d0));
    }
    if (s.h1.x > s.h1.z || s.h1.y > s.h1.z) {
        inner_max = max(inner_max, exit_point(d1));
    }
    part.inner_max = inner_max;
    return part;
}

struct WedgeTargets {
    // Signed area beyond the edge, per radial part (added).
    @location(0) area: vec4<f32>,
    // Outer bounding rectangles of parts 0 to 3 (kept by maximum).
    @location(1) rect0: vec4<f32>,
    @location(2) rect1: vec4<f32>,
    @location(3) rect2: vec4<f32>,
    @location(4) rect3: vec4<f32>,
    // Inner maxima (x, y) of parts 0 and 1, and of parts 2 and 3 (kept by maximum).
    @location(5) inner01: vec4<f32>,
    @location(6) inner23: vec4<f32>,
    // One per fragment shaded (added): the diagnostics' count.
    @location(7) shaded: f32,
};

// The radial parts: their axes' directions in the light's normalised coordinates.
const RADIAL_MIRRORS = array<vec2<f32>, 4>(vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0), vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0));

fn outside(plane: vec4<f32>, p: vec3<f32>, tolerance: f32) -> bool {
    return dot(plane.xyz, p) - plane.w < -tolerance;
}

@fragment
fn wedges_wedge_fragment(in: WedgeVarying) -> WedgeTargets {
    return wedge_fragment(in);
}

// The fragment of a wedge (the entry points wedges_wedge_fragment and, when counting,
// wedges_wedges_counted.wgsl's).
fn wedge_fragment(in: WedgeVarying) -> WedgeTargets {
    let texel = vec2<i32>(in.clip.xy);
    let position = textureLoad(gbuffer_position, texel, 0);
    // The position, and the normal where a surface covers the pixel.
    let reads = select(1u, 2u, position.w >= 0.5);
    record_reads(COUNTER_WEDGE_READS, texel, reads, reads * GBUFFER_TEXEL_BYTES);
    if (position.w < 0.5) {
        discard;
    }
    // The point the stencil test judged the umbra at (the G-buffer's point moved by the depth
    // copy's bias along the view ray): the umbra, the half-wedge and the integration must all be
    // of one point. Otherwise, on a receiver within the bias of a shadow-volume side, the umbra
    // and the half-wedge disagree, and the sum is off by up to half the light.
    let offset = volume_depth_offset(frame, settings.depth_bias, position.xyz, textureLoad(gbuffer_normal, texel, 0).xyz);
    let p = volume_test_point(camera.view_proj, camera.position.xyz, position.xyz, offset);
    let record = half_edges[in.index];
    let a = record.a.xyz;
    let b = record.b.xyz;
    let c = frame.centre.xyz;
    // The half-wedge: p on the umbra's side of the shadow-volume side is in the inner half.
    let split = dot(cross(a - c, b - c), p - c);
    let inner = split < 0.0;
    if (split == 0.0) {
        discard;
    }
    // Lengyel's quick rejection: outside any of the half-wedge's three bounding planes.
    let tolerance = scene_length(frame, settings.plane_tolerance);
    let pyramid = in.kind == KIND_PYRAMID;
    let bound = select(in.outer, in.inner, inner);
    if (outside(bound, p, tolerance) || outside(in.side0, p, tolerance) || outside(in.side1, p, tolerance)
        || (pyramid && outside(select(in.inner, in.outer, inner), p, tolerance))) {
        discard;
    }
    let n = frame.normal.xyz;
    let depth_p = dot(p - c, n);
    if (depth_p <= 0.0) {
        discard;
    }
    // Homogeneous coordinates on the light of the projection of q from p: x = X / W, y = Y / W.
    let u = frame.u_axis.xyz;
    let v = frame.v_axis.xyz;
    let pu = dot(p - c, u);
    let pv = dot(p - c, v);
    let depth_a = dot(a - c, n);
    let depth_b = dot(b - c, n);
    let scale = vec2<f32>(1.0 / frame.u_axis.w, 1.0 / frame.v_axis.w);
    let ha = vec3<f32>(vec2<f32>(depth_p * dot(a - c, u) - depth_a * pu, depth_p * dot(a - c, v) - depth_a * pv) * scale, depth_p - depth_a);
    let hb = vec3<f32>(vec2<f32>(depth_p * dot(b - c, u) - depth_b * pu, depth_p * dot(b - c, v) - depth_b * pv) * scale, depth_p - depth_b);
    // Lengyel's local near plane: keep the part of the edge between the light's plane (the
    // geometric near plane) and p.
    let near = scene_length(frame, settings.near_fraction);
    let gap = depth_p * 1e-6;
    var segment = clip_segment(Segment(ha, hb, true), ha.z - gap, hb.z - gap);
    // The same affine clip on the depth: depth_a + t (depth_b - depth_a) >= near, along the segment
    // as clipped so far (W = depth_p - depth, so depth = depth_p - W).
    segment = clip_segment(segment, depth_p - segment.h0.z - near, depth_p - segment.h1.z - near);
    // Outside the wedge proper: the projected edge misses the light (both ends beyond one border).
    let h0 = segment.h0;
    let h1 = segment.h1;
    if (!segment.ok || (h0.x > h0.z && h1.x > h1.z) || (h0.x < -h0.z && h1.x < -h1.z) || (h0.y > h0.z && h1.y > h1.z)
        || (h0.y < -h0.z && h1.y < -h1.z)) {
        discard;
    }
    let sign = select(1.0, -1.0, inner);
    var out: WedgeTargets;
    var rects = array<vec4<f32>, 4>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    var maxima = array<vec2<f32>, 4>(vec2<f32>(0.0), vec2<f32>(0.0), vec2<f32>(0.0), vec2<f32>(0.0));
    var contributes = false;
    for (var i = 0u; i < 4u; i += 1u) {
        let part = radial_part(segment, RADIAL_MIRRORS[i]);
        out.area[i] = sign * part.area;
        if (inner) {
            maxima[i] = part.inner_max;
        } else {
            rects[i] = part.rect;
        }
        contributes = contributes || part.area > 0.0 || (inner && any(part.inner_max > vec2<f32>(0.0)));
    }
    if (!contributes) {
        discard;
    }
    out.rect0 = rects[0];
    out.rect1 = rects[1];
    out.rect2 = rects[2];
    out.rect3 = rects[3];
    out.inner01 = vec4<f32>(maxima[0], maxima[1]);
    out.inner23 = vec4<f32>(maxima[2], maxima[3]);
    out.shaded = 1.0;
    return out;
}
