// Silhouettes from the light's centre, every frame, on the GPU (Forest et
// al., Sec. 4.1, with the half-edge connectivity replaced by compute passes):
//
// 0. find, for each closed component, whether the light's centre is inside it
//    (its winding number around the centre);
// 1. classify each face: whether it bounds the shadow volume (turned towards
//    the light's centre, or away from it in a closed component around it);
// 2. label silhouette regions: connected sets of faces turned to the light,
//    joined across the edges whose shadow-volume sides cancel (hook and
//    pointer-jumping rounds until nothing changes; each region is bounded by
//    its silhouette loops, Sec. 3);
// 3. rank the regions by their smallest face (a deterministic scan) and give
//    region r to silhouette buffer r mod K;
// 4. emit, per buffer, the silhouette half-edges (each with its penumbra
//    wedge, Sec. 4.2) and the cap faces of the z-fail volumes, by counting
//    sort, and write the indirect draw arguments.

// #import common/light_frame.wgsl
// #import wedges/wedges_common.wgsl
// #import wedges/wedges_counts.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;

@group(1) @binding(0) var<uniform> settings: WedgesSettings;
@group(1) @binding(1) var<uniform> mesh: WedgesMesh;
@group(1) @binding(2) var<storage, read> positions: array<vec4<f32>>;
@group(1) @binding(3) var<storage, read> faces: array<Face>;
@group(1) @binding(4) var<storage, read> records: array<EdgeRecord>;
@group(1) @binding(5) var<storage, read_write> face_state: array<u32>;
@group(1) @binding(6) var<storage, read_write> labels: array<atomic<u32>>;
@group(1) @binding(7) var<storage, read_write> ranks: array<u32>;
@group(1) @binding(8) var<storage, read_write> block_sums: array<u32>;
@group(1) @binding(9) var<storage, read_write> counters: Counters;
@group(1) @binding(10) var<storage, read_write> half_edges: array<WedgeRecord>;
@group(1) @binding(11) var<storage, read_write> caps: array<u32>;
// Per closed component, its winding number around the light's centre in units of WINDING_TURN
// (cleared before the pass).
@group(1) @binding(12) var<storage, read_write> winding: array<atomic<i32>>;
// Per closed component, 1 when every edge of it is convex (CastingMesh::closed_convex).
@group(1) @binding(13) var<storage, read> component_convex: array<u32>;
@group(1) @binding(14) var<storage, read_write> read_counts: array<atomic<u32>>;

// Atomics this invocation did and bytes it stored, for the counts (wedges_counts.wgsl): every
// entry point below is a wrapper that runs its step and records them, for every thread it runs.
var<private> atomics: u32;
var<private> stored: u32;

fn record_silhouette_work(thread: u32) {
    let texel = vec2<i32>(i32(thread), 0);
    record_count(COUNTER_SILHOUETTE_ATOMICS, texel, atomics);
    record_count(COUNTER_SILHOUETTE_STORAGE_BYTES, texel, stored);
}

// The indirect arguments: two dispatches (hook over records, jump over faces), then per group
// four draws. Bound only in the passes that write them.
@group(2) @binding(0) var<storage, read_write> indirect: array<u32>;

fn workgroups(count: u32) -> u32 {
    return (count + WORKGROUP - 1u) / WORKGROUP;
}

// Zeroes the counters, and lets the first label-propagation round run over everything.
@compute @workgroup_size(1)
fn wedges_reset() {
    step_reset();
    record_silhouette_work(0u);
}

fn step_reset() {
    atomicStore(&counters.changed, 0u);
    atomicStore(&counters.rounds, 0u);
    counters.regions = 0u;
    counters.half_edges = 0u;
    counters.caps = 0u;
    atomicStore(&counters.fallback_wedges, 0u);
    counters.groups_used = 0u;
    // Three atomic stores and four u32s above, eight u32s of indirect arguments below.
    atomics = 3u;
    stored = 4u * 4u + 8u * 4u;
    for (var g = 0u; g < MAX_SILHOUETTE_BUFFERS; g += 1u) {
        atomics += 5u;
        stored += 2u * 4u;
        atomicStore(&counters.edge_count[g], 0u);
        atomicStore(&counters.edge_cursor[g], 0u);
        atomicStore(&counters.cap_count[g], 0u);
        atomicStore(&counters.cap_cursor[g], 0u);
        counters.edge_offset[g] = 0u;
        counters.cap_offset[g] = 0u;
        atomicStore(&counters.stencil_levels[g], 0u);
    }
    indirect[0] = workgroups(mesh.record_count);
    indirect[1] = 1u;
    indirect[2] = 1u;
    indirect[3] = 0u;
    indirect[4] = workgroups(mesh.face_count);
    indirect[5] = 1u;
    indirect[6] = 1u;
    indirect[7] = 0u;
}

// Whether face `f` is turned towards the light's centre: its winding's normal points at it.
// A degenerate face (no normal) is not.
fn faces_light(f: u32) -> bool {
    let face = faces[f];
    let p0 = positions[face.v0].xyz;
    let p1 = positions[face.v1].xyz;
    let p2 = positions[face.v2].xyz;
    let normal = cross(p1 - p0, p2 - p0);
    return dot(normal, frame.centre.xyz - p0) > 0.0;
}

// Step 0: the solid angle face f of a closed component subtends at the light's
// centre, signed (positive when its winding faces away from the centre; Van
// Oosterom and Strackee 1983), added to its component's winding number. A
// closed, outward-wound component sums to one turn around a centre inside it
// and to zero around one outside (minus one turn if it is wound inwards).
@compute @workgroup_size(256)
fn wedges_winding(@builtin(global_invocation_id) id: vec3<u32>) {
    step_winding(id);
    record_silhouette_work(id.x);
}

fn step_winding(id: vec3<u32>) {
    let f = id.x;
    if (f >= mesh.face_count) {
        return;
    }
    let face = faces[f];
    if (face.component == TWO_SIDED_COMPONENT) {
        return;
    }
    let c = frame.centre.xyz;
    let a = positions[face.v0].xyz - c;
    let b = positions[face.v1].xyz - c;
    let d = positions[face.v2].xyz - c;
    let la = length(a);
    let lb = length(b);
    let ld = length(d);
    let numerator = dot(a, cross(b, d));
    let denominator = la * lb * ld + dot(a, b) * ld + dot(a, d) * lb + dot(b, d) * la;
    // A face seen edge-on subtends nothing (and atan2(0, 0) is not defined).
    let solid_angle = select(2.0 * atan2(numerator, denominator), 0.0, numerator == 0.0);
    // 4 pi steradians are WINDING_TURN units: a face's share is below half a turn, and
    // rounding errs by half a unit per face, far from the half turn the test below draws the line at.
    atomicAdd(&winding[face.component], i32(round(solid_angle * (WINDING_TURN / (4.0 * 3.14159265358979)))));
    atomics = 1u;
}

// Step 1. A ray from the light's centre first crosses a closed component where
// it enters it, through a face turned towards the centre, when the centre is
// outside it, but where it leaves it, through a face turned away, when the
// centre is inside it (a closed room, a light sealed in a box). The faces of
// that first crossing take part: their prisms (each face as the near cap, its
// projection to infinity as the far cap, the silhouette edges as the sides)
// hold every point whose segment to the centre crosses the component, so the
// volume is closed even where no face is turned towards the light and there is
// no silhouette (Sec. 3, 4.1; the classic volume of the lit faces when the
// light is outside). Faces turned away take part turned to face the light
// (STATE_REVERSED), which keeps every silhouette half-edge's orientation and
// the caps' winding. Faces of open or non-manifold components are two-sided:
// every face takes part, turned to face the light, so the volume is the union
// of every face's prism, whatever the mesh.
@compute @workgroup_size(256)
fn wedges_classify_faces(@builtin(global_invocation_id) id: vec3<u32>) {
    step_classify_faces(id);
    record_silhouette_work(id.x);
}

fn step_classify_faces(id: vec3<u32>) {
    let f = id.x;
    if (f >= mesh.face_count) {
        return;
    }
    let lit = faces_light(f);
    let component = faces[f].component;
    var state = 0u;
    if (component == TWO_SIDED_COMPONENT) {
        state = STATE_PARTICIPATES | select(STATE_REVERSED, 0u, lit);
    } else {
        // Half a turn separates the winding numbers 0 (outside) and 1 (inside).
        let centre_inside = f32(atomicLoad(&winding[component])) > 0.5 * WINDING_TURN;
        atomics += 1u;
        if (lit != centre_inside) {
            state = STATE_PARTICIPATES | select(0u, STATE_REVERSED, centre_inside);
        }
    }
    face_state[f] = state;
    atomicStore(&labels[f], select(NO_FACE, f, (state & STATE_PARTICIPATES) != 0u));
    atomics += 1u;
    stored += 4u;
}

fn participates(state: u32) -> bool {
    return (state & STATE_PARTICIPATES) != 0u;
}

// True when both faces of a paired record take part and their volume sides on
// the edge cancel (turned to the light, they run the edge in opposite
// directions): the edge is inside a region.
fn joins(record: EdgeRecord) -> bool {
    if (record.face_b == NO_FACE) {
        return false;
    }
    let a = face_state[record.face_a];
    let b = face_state[record.face_b];
    let a_runs_backwards = (a & STATE_REVERSED) != 0u;
    let b_runs_backwards = face_b_runs_backwards(record, (b & STATE_REVERSED) != 0u);
    return participates(a) && participates(b) && (a_runs_backwards != b_runs_backwards);
}

// Step 2, hook: across every joining edge, link the larger label to the smaller.
// Labels only decrease and always name a face of the same region, so the
// final labels are each region's smallest face whatever the order of threads.
@compute @workgroup_size(256)
fn wedges_hook(@builtin(global_invocation_id) id: vec3<u32>) {
    step_hook(id);
    record_silhouette_work(id.x);
}

fn step_hook(id: vec3<u32>) {
    let r = id.x;
    if (r >= mesh.record_count) {
        return;
    }
    let record = records[r];
    if (!joins(record)) {
        return;
    }
    let la = atomicLoad(&labels[record.face_a]);
    let lb = atomicLoad(&labels[record.face_b]);
    atomics = 2u;
    if (la != lb) {
        atomicMin(&labels[max(la, lb)], min(la, lb));
        atomicStore(&counters.changed, 1u);
        atomics += 2u;
    }
}

// Step 2, jump: every label points at its root.
@compute @workgroup_size(256)
fn wedges_jump(@builtin(global_invocation_id) id: vec3<u32>) {
    step_jump(id);
    record_silhouette_work(id.x);
}

fn step_jump(id: vec3<u32>) {
    let f = id.x;
    if (f >= mesh.face_count) {
        return;
    }
    var label = atomicLoad(&labels[f]);
    atomics = 1u;
    if (label == NO_FACE) {
        return;
    }
    for (var step = 0u; step < 1048576u; step += 1u) {
        let parent = atomicLoad(&labels[label]);
        atomics += 1u;
        if (parent == label) {
            break;
        }
        label = parent;
    }
    atomicStore(&labels[f], label);
    atomics += 1u;
}

// Step 2, control: the next round runs only if this one linked anything.
@compute @workgroup_size(1)
fn wedges_control() {
    step_control();
    record_silhouette_work(0u);
}

fn step_control() {
    let changed = atomicLoad(&counters.changed);
    atomicStore(&counters.changed, 0u);
    // Two atomics, and two u32s of indirect arguments either way.
    atomics = 2u;
    stored = 2u * 4u;
    if (changed != 0u) {
        atomicAdd(&counters.rounds, 1u);
        atomics += 1u;
        indirect[0] = workgroups(mesh.record_count);
        indirect[4] = workgroups(mesh.face_count);
    } else {
        indirect[0] = 0u;
        indirect[4] = 0u;
    }
}

var<workgroup> scan_values: array<u32, 256>;
var<workgroup> scan_carry: u32;

// Inclusive prefix sum of `value` over the workgroup (Hillis and Steele).
fn workgroup_inclusive_scan(local: u32, value: u32) -> u32 {
    scan_values[local] = value;
    workgroupBarrier();
    for (var offset = 1u; offset < WORKGROUP; offset *= 2u) {
        var add = 0u;
        if (local >= offset) {
            add = scan_values[local - offset];
        }
        workgroupBarrier();
        scan_values[local] += add;
        workgroupBarrier();
    }
    let result = scan_values[local];
    workgroupBarrier();
    return result;
}

// A region's root: a face that takes part and is its own label.
fn is_root(f: u32) -> u32 {
    if (f >= mesh.face_count) {
        return 0u;
    }
    atomics += 1u;
    return select(0u, 1u, atomicLoad(&labels[f]) == f);
}

// Step 3a: roots per block of 256 faces.
@compute @workgroup_size(256)
fn wedges_rank_blocks(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32, @builtin(workgroup_id) group: vec3<u32>) {
    step_rank_blocks(id, local, group);
    record_silhouette_work(id.x);
}

fn step_rank_blocks(id: vec3<u32>, local: u32, group: vec3<u32>) {
    let total = workgroup_inclusive_scan(local, is_root(id.x));
    if (local == WORKGROUP - 1u) {
        block_sums[group.x] = total;
        stored += 4u;
    }
}

// Step 3b: exclusive prefix sum of the block counts, in one workgroup, 256 blocks at a time.
@compute @workgroup_size(256)
fn wedges_rank_scan(@builtin(local_invocation_index) local: u32) {
    step_rank_scan(local);
    record_silhouette_work(local);
}

fn step_rank_scan(local: u32) {
    if (local == 0u) {
        scan_carry = 0u;
    }
    workgroupBarrier();
    let chunks = (mesh.rank_blocks + WORKGROUP - 1u) / WORKGROUP;
    for (var chunk = 0u; chunk < chunks; chunk += 1u) {
        let i = chunk * WORKGROUP + local;
        var value = 0u;
        if (i < mesh.rank_blocks) {
            value = block_sums[i];
        }
        let carry = scan_carry;
        let inclusive = workgroup_inclusive_scan(local, value);
        if (i < mesh.rank_blocks) {
            block_sums[i] = carry + inclusive - value;
            stored += 4u;
        }
        workgroupBarrier();
        if (local == WORKGROUP - 1u) {
            scan_carry = carry + inclusive;
        }
        workgroupBarrier();
    }
    if (local == 0u) {
        counters.regions = scan_carry;
        stored += 4u;
    }
}

// Step 3c: each root's rank among the roots, in face order.
@compute @workgroup_size(256)
fn wedges_rank_faces(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32, @builtin(workgroup_id) group: vec3<u32>) {
    step_rank_faces(id, local, group);
    record_silhouette_work(id.x);
}

fn step_rank_faces(id: vec3<u32>, local: u32, group: vec3<u32>) {
    let root = is_root(id.x);
    let inclusive = workgroup_inclusive_scan(local, root);
    if (root != 0u) {
        ranks[id.x] = block_sums[group.x] + inclusive - root;
        stored += 4u;
    }
}

// The silhouette buffer of the region face `f` belongs to.
fn group_of(f: u32) -> u32 {
    let root = atomicLoad(&labels[f]);
    atomics += 1u;
    return ranks[root] % settings.silhouette_buffers;
}

// One silhouette half-edge: the edge `v_from -> v_to` of `face`, oriented.
struct Emission {
    face: u32,
    a: u32,
    b: u32,
};

// The silhouette half-edges of record `r` (at most two). An edge between two
// faces of one region whose sides cancel emits nothing; otherwise every face
// that takes part emits its side, oriented as its light-facing winding runs
// (face_b winds the edge backwards unless `face_b_winds_forward`). Regions split by an unfinished labelling
// still get closed volumes: the joining edge is emitted on both sides.
fn emissions(r: u32, out: ptr<function, array<Emission, 2>>) -> u32 {
    let record = records[r];
    let state_a = face_state[record.face_a];
    var count = 0u;
    if (record.face_b == NO_FACE) {
        if (participates(state_a)) {
            let reversed = (state_a & STATE_REVERSED) != 0u;
            (*out)[0] = Emission(record.face_a, select(record.v0, record.v1, reversed), select(record.v1, record.v0, reversed));
            count = 1u;
        }
        return count;
    }
    if (joins(record)) {
        atomics += 2u;
        if (atomicLoad(&labels[record.face_a]) == atomicLoad(&labels[record.face_b])) {
            return 0u;
        }
    }
    if (participates(state_a)) {
        let reversed = (state_a & STATE_REVERSED) != 0u;
        (*out)[count] = Emission(record.face_a, select(record.v0, record.v1, reversed), select(record.v1, record.v0, reversed));
        count += 1u;
    }
    let state_b = face_state[record.face_b];
    if (participates(state_b)) {
        let backwards = face_b_runs_backwards(record, (state_b & STATE_REVERSED) != 0u);
        (*out)[count] = Emission(record.face_b, select(record.v0, record.v1, backwards), select(record.v1, record.v0, backwards));
        count += 1u;
    }
    return count;
}

// Step 4a: count the half-edges of each silhouette buffer.
@compute @workgroup_size(256)
fn wedges_count_edges(@builtin(global_invocation_id) id: vec3<u32>) {
    step_count_edges(id);
    record_silhouette_work(id.x);
}

fn step_count_edges(id: vec3<u32>) {
    if (id.x >= mesh.record_count) {
        return;
    }
    var out: array<Emission, 2>;
    let count = emissions(id.x, &out);
    for (var i = 0u; i < count; i += 1u) {
        atomicAdd(&counters.edge_count[group_of(out[i].face)], 1u);
        atomics += 1u;
    }
}

// Step 4a: count the cap faces of each silhouette buffer, and bound its stencil count: a point's
// count is the number of the buffer's face prisms holding it, but a convex closed component's
// prisms (one region) hold a point at most once.
@compute @workgroup_size(256)
fn wedges_count_caps(@builtin(global_invocation_id) id: vec3<u32>) {
    step_count_caps(id);
    record_silhouette_work(id.x);
}

fn step_count_caps(id: vec3<u32>) {
    let f = id.x;
    if (f >= mesh.face_count || !participates(face_state[f])) {
        return;
    }
    let g = group_of(f);
    atomicAdd(&counters.cap_count[g], 1u);
    atomics += 1u;
    let component = faces[f].component;
    let convex = component != TWO_SIDED_COMPONENT && component_convex[component] != 0u;
    // The label is loaded only for a convex component (`||` does not evaluate its right side otherwise).
    atomics += select(0u, 1u, convex);
    if (!convex || atomicLoad(&labels[f]) == f) {
        atomicAdd(&counters.stencil_levels[g], 1u);
        atomics += 1u;
    }
}

// Step 4b: each buffer's place in the lists, and its draws' arguments.
@compute @workgroup_size(1)
fn wedges_offsets() {
    step_offsets();
    record_silhouette_work(0u);
}

fn step_offsets() {
    var edges = 0u;
    var caps_total = 0u;
    var used = 0u;
    for (var g = 0u; g < MAX_SILHOUETTE_BUFFERS; g += 1u) {
        let edge_count = atomicLoad(&counters.edge_count[g]);
        let cap_count = atomicLoad(&counters.cap_count[g]);
        counters.edge_offset[g] = edges;
        counters.cap_offset[g] = caps_total;
        // Two offsets and sixteen u32s of draw arguments.
        atomics += 2u;
        stored += 18u * 4u;
        let base = DRAW_ARGUMENTS + g * GROUP_ARGUMENTS;
        // Shadow-volume sides.
        indirect[base + 0u] = SIDE_VERTICES * edge_count;
        indirect[base + 1u] = 1u;
        indirect[base + 2u] = SIDE_VERTICES * edges;
        indirect[base + 3u] = 0u;
        // Caps.
        indirect[base + 4u] = CAP_VERTICES * cap_count;
        indirect[base + 5u] = 1u;
        indirect[base + 6u] = CAP_VERTICES * caps_total;
        indirect[base + 7u] = 0u;
        // Wedges.
        indirect[base + 8u] = WEDGE_VERTICES * edge_count;
        indirect[base + 9u] = 1u;
        indirect[base + 10u] = WEDGE_VERTICES * edges;
        indirect[base + 11u] = 0u;
        // Blend: a dispatch over the view (16 x 16 pixels per workgroup) when the buffer holds anything.
        let occupied = edge_count + cap_count > 0u;
        indirect[base + 12u] = select(0u, (mesh.width + 15u) / 16u, occupied);
        indirect[base + 13u] = select(0u, (mesh.height + 15u) / 16u, occupied);
        indirect[base + 14u] = 1u;
        indirect[base + 15u] = 0u;
        used += select(0u, 1u, occupied);
        edges += edge_count;
        caps_total += cap_count;
    }
    counters.half_edges = edges;
    counters.caps = caps_total;
    counters.groups_used = used;
    stored += 3u * 4u;
}

// A plane (unit normal, offset: dot(normal, x) = offset).
struct Plane {
    normal: vec3<f32>,
    offset: f32,
};

fn plane_through(normal: vec3<f32>, point: vec3<f32>) -> Plane {
    let unit = normalize(normal);
    return Plane(unit, dot(unit, point));
}

// The point where three planes meet; `ok` false when they are (nearly) parallel.
struct Meet {
    point: vec3<f32>,
    ok: bool,
};

fn meet(p1: Plane, p2: Plane, p3: Plane) -> Meet {
    let c23 = cross(p2.normal, p3.normal);
    let det = dot(p1.normal, c23);
    if (abs(det) < 1e-6) {
        return Meet(vec3<f32>(0.0), false);
    }
    let point = (p1.offset * c23 + p2.offset * cross(p3.normal, p1.normal) + p3.offset * cross(p1.normal, p2.normal)) / det;
    return Meet(point, all(abs(point) < vec3<f32>(1e30)));
}

fn side_of(plane: Plane, point: vec3<f32>) -> f32 {
    return dot(plane.normal, point) - plane.offset;
}

fn flag_record(record: ptr<function, WedgeRecord>, flags: u32) {
    (*record).outer1.w = bitcast<f32>(flags);
}

// The fallback bound of a wedge whose planes degenerate: the convex hull of
// the clipped edge a1 b1 and the rectangle R (along the light's axes, on the
// far plane) that bounds the far sections of the cones of rays from the
// light's corners through a1 and through b1. Every ray from the light through
// the edge lies in that hull. When the end farther from the light lies inside
// the pyramid from the nearer end (the apex) to R, as it does whenever the
// edge's line crosses the light (the edge continues a ray from the light), the
// hull is that pyramid: drawn with its four side planes as the bounding
// planes. Otherwise the vertex stage draws the hull's screen-space bounding
// box, and the fragments decide exactly.
fn fallback_wedge(record: ptr<function, WedgeRecord>, a1: vec3<f32>, b1: vec3<f32>, corners: array<vec3<f32>, 4>, far_depth: f32) {
    let c = frame.centre.xyz;
    let n = frame.normal.xyz;
    let u = frame.u_axis.xyz;
    let v = frame.v_axis.xyz;
    let depth_a = max(dot(a1 - c, n), 1e-30);
    let depth_b = max(dot(b1 - c, n), 1e-30);
    var low = vec2<f32>(3.4e38);
    var high = vec2<f32>(-3.4e38);
    for (var k = 0u; k < 4u; k += 1u) {
        // Depth grows linearly from 0 at the corner: the ray reaches far_depth at this multiple.
        let through_a = corners[k] + (a1 - corners[k]) * (far_depth / depth_a) - c;
        let through_b = corners[k] + (b1 - corners[k]) * (far_depth / depth_b) - c;
        low = min(low, min(vec2<f32>(dot(through_a, u), dot(through_a, v)), vec2<f32>(dot(through_b, u), dot(through_b, v))));
        high = max(high, max(vec2<f32>(dot(through_a, u), dot(through_a, v)), vec2<f32>(dot(through_b, u), dot(through_b, v))));
    }
    // A little slack, so that the other end on the pyramid's surface counts as inside.
    let slack = scene_length(frame, 1e-5);
    low -= vec2<f32>(slack);
    high += vec2<f32>(slack);
    let base = c + n * far_depth;
    let rectangle = array<vec3<f32>, 4>(
        base + low.x * u + low.y * v, base + high.x * u + low.y * v, base + high.x * u + high.y * v, base + low.x * u + high.y * v,
    );
    (*record).inner0 = vec4<f32>(rectangle[0], 0.0);
    (*record).inner1 = vec4<f32>(rectangle[1], 0.0);
    (*record).outer0 = vec4<f32>(rectangle[2], 0.0);
    (*record).outer1 = vec4<f32>(rectangle[3], 0.0);
    let apex_is_b = depth_b < depth_a;
    let apex = select(a1, b1, apex_is_b);
    let other = select(b1, a1, apex_is_b);
    let inside = (rectangle[0] + rectangle[1] + rectangle[2] + rectangle[3]) * 0.25;
    var in_pyramid = true;
    for (var k = 0u; k < 4u; k += 1u) {
        var normal = cross(rectangle[k] - apex, rectangle[(k + 1u) % 4u] - apex);
        if (dot(normal, inside - apex) < 0.0) {
            normal = -normal;
        }
        if (dot(normal, other - apex) < -1e-6 * length(normal) * length(other - apex)) {
            in_pyramid = false;
        }
    }
    flag_record(record, WEDGE_FALLBACK | select(0u, WEDGE_PYRAMID, in_pyramid) | select(0u, WEDGE_APEX_B, apex_is_b));
    atomicAdd(&counters.fallback_wedges, 1u);
    atomics += 1u;
}

// The plane that closes a wedge far from the light. Every receiver lies in the
// scene's bounding box, so any of its face planes cuts the wedge without
// losing a receiver: the face that the wedge's central ray leaves the box by,
// when all four of the wedge's lateral edges run towards it (the far section
// is then a quadrilateral), else the plane past the frame's far depth. With a
// tilted light over a wide ground, this stops the wedges at the ground instead
// of far below it, where every ground pixel above them would run a fragment.
fn truncation(a1: vec3<f32>, b1: vec3<f32>, planes: array<Plane, 4>, far_depth: f32) -> Plane {
    let c = frame.centre.xyz;
    let n = frame.normal.xyz;
    // The lateral edges: tangent plane x side plane, pointed away from the light.
    var lateral = array<vec3<f32>, 4>(
        cross(planes[0].normal, planes[2].normal), cross(planes[0].normal, planes[3].normal),
        cross(planes[1].normal, planes[2].normal), cross(planes[1].normal, planes[3].normal),
    );
    for (var k = 0u; k < 4u; k += 1u) {
        if (dot(lateral[k], n) < 0.0) {
            lateral[k] = -lateral[k];
        }
    }
    let middle = (a1 + b1) * 0.5;
    let direction = middle - c;
    var best = Plane(n, dot(n, c) + far_depth);
    var best_t = 3.4e38;
    for (var axis = 0u; axis < 3u; axis += 1u) {
        for (var side = 0u; side < 2u; side += 1u) {
            var normal = vec3<f32>(0.0);
            normal[axis] = select(-1.0, 1.0, side == 1u);
            let offset = select(-mesh.bounds_min[axis], mesh.bounds_max[axis], side == 1u);
            var towards = dot(normal, direction) > 0.0;
            for (var k = 0u; k < 4u; k += 1u) {
                towards = towards && dot(normal, lateral[k]) > 1e-6 * length(lateral[k]);
            }
            if (towards) {
                // Where the central ray from the light's centre leaves the box by this face.
                let t = (offset - dot(normal, c)) / dot(normal, direction);
                if (t > 1.0 && t < best_t) {
                    best_t = t;
                    best = Plane(normal, offset);
                }
            }
        }
    }
    return best;
}

// The penumbra wedge of silhouette edge a -> b (Akenine-Möller and Assarsson
// 2002, Sec. 4; Lengyel 2005's bounding planes): the edge is clipped to the
// geometric near plane (depth `near` in front of the light); its front and
// back planes contain the edge and are tangent to the light rectangle (the
// whole light behind them); its side planes pass through the edge's ends and
// keep every ray from the light through that end on their inner side; the
// split plane is the shadow-volume side through the light's centre. Far
// points lie on the plane past the frame's far depth. Where the construction
// degenerates (the edge's line crosses the light, so no plane through it is
// tangent; side planes that cross before the far plane), the wedge is bounded
// by `fallback_wedge` instead.
fn build_wedge(a: vec3<f32>, b: vec3<f32>) -> WedgeRecord {
    var record: WedgeRecord;
    record.a = vec4<f32>(a, 0.0);
    record.b = vec4<f32>(b, 1.0);
    let c = frame.centre.xyz;
    let n = frame.normal.xyz;
    let near = scene_length(frame, settings.near_fraction);
    let tolerance = scene_length(frame, 1e-5);
    let depth_a = dot(a - c, n);
    let depth_b = dot(b - c, n);
    if ((depth_a < near && depth_b < near) || (frame.u_axis.w <= 0.0 && frame.v_axis.w <= 0.0) || distance(a, b) <= tolerance) {
        flag_record(&record, WEDGE_EMPTY);
        return record;
    }
    var t0 = 0.0;
    var t1 = 1.0;
    if (depth_a < near) {
        t0 = (near - depth_a) / (depth_b - depth_a);
    }
    if (depth_b < near) {
        t1 = (near - depth_a) / (depth_b - depth_a);
    }
    record.a.w = t0;
    record.b.w = t1;
    let a1 = mix(a, b, t0);
    let b1 = mix(a, b, t1);
    let edge = b1 - a1;
    let half_u = frame.u_axis.xyz * frame.u_axis.w;
    let half_v = frame.v_axis.xyz * frame.v_axis.w;
    let corners = array<vec3<f32>, 4>(c + half_u + half_v, c - half_u + half_v, c - half_u - half_v, c + half_u - half_v);
    let far_depth = max(frame.projection.w, max(depth_a, depth_b)) * 1.01 + near;
    let split_normal = cross(a - c, b - c);
    if (length(split_normal) <= 1e-12 * max(dot(a - c, a - c), 1e-30)) {
        fallback_wedge(&record, a1, b1, corners, far_depth);
        return record;
    }
    let split = plane_through(split_normal, c);

    // Tangent planes: through the edge and a corner, with every corner behind.
    var inner_found = false;
    var outer_found = false;
    var inner_plane: Plane;
    var outer_plane: Plane;
    for (var k = 0u; k < 4u; k += 1u) {
        var normal = cross(edge, corners[k] - a1);
        if (length(normal) <= 1e-12) {
            continue;
        }
        normal = normalize(normal);
        if (dot(normal, c - a1) > 0.0) {
            normal = -normal;
        }
        var tangent = true;
        for (var j = 0u; j < 4u; j += 1u) {
            if (dot(normal, corners[j] - a1) > tolerance) {
                tangent = false;
            }
        }
        if (!tangent) {
            continue;
        }
        // The light lies on the plane's negative side; past the edge, the wedge on its positive side.
        let plane = Plane(normal, dot(normal, a1));
        // Past the edge, the tangent plane through a corner on the split plane's positive
        // side bounds the half on its negative side: the inner half.
        let corner_side = side_of(split, corners[k]);
        if (corner_side > 0.0) {
            inner_plane = plane;
            inner_found = true;
        } else if (corner_side < 0.0) {
            outer_plane = plane;
            outer_found = true;
        }
    }

    // Side planes through a1 and b1, containing the direction across the wedge.
    let along = normalize(edge);
    let away = (a1 - c) - dot(a1 - c, along) * along;
    var ok = inner_found && outer_found && length(away) > tolerance;
    let g = normalize(away);
    var lambda0 = 0.0;
    var lambda1 = 0.0;
    for (var k = 0u; k < 4u; k += 1u) {
        let beta0 = dot(g, a1 - corners[k]);
        let beta1 = dot(g, b1 - corners[k]);
        if (beta0 > 1e-9) {
            lambda0 = max(lambda0, -dot(along, a1 - corners[k]) / beta0);
        }
        if (beta1 > 1e-9) {
            lambda1 = max(lambda1, dot(along, b1 - corners[k]) / beta1);
        }
    }
    let side0 = plane_through(along + lambda0 * g, a1);
    let side1 = plane_through(-along + lambda1 * g, b1);
    for (var k = 0u; k < 4u; k += 1u) {
        // Every ray from the light through a1 (b1) stays inside its side plane.
        if (dot(side0.normal, a1 - corners[k]) < -1e-5 * length(a1 - corners[k])
            || dot(side1.normal, b1 - corners[k]) < -1e-5 * length(b1 - corners[k])) {
            ok = false;
        }
    }
    let far = truncation(a1, b1, array<Plane, 4>(inner_plane, outer_plane, side0, side1), far_depth);
    let m0 = meet(inner_plane, side0, far);
    let m1 = meet(inner_plane, side1, far);
    let m2 = meet(split, side0, far);
    let m3 = meet(split, side1, far);
    let m4 = meet(outer_plane, side0, far);
    let m5 = meet(outer_plane, side1, far);
    ok = ok && m0.ok && m1.ok && m2.ok && m3.ok && m4.ok && m5.ok;
    if (ok) {
        let slack = scene_length(frame, 1e-4);
        // The side planes do not cross before the far plane; the far section is a proper quadrilateral split in two.
        ok = side_of(side1, m0.point) > -slack && side_of(side1, m2.point) > -slack && side_of(side1, m4.point) > -slack
            && side_of(side0, m1.point) > -slack && side_of(side0, m3.point) > -slack && side_of(side0, m5.point) > -slack
            && side_of(split, m0.point) < slack && side_of(split, m1.point) < slack
            && side_of(split, m4.point) > -slack && side_of(split, m5.point) > -slack
            && side_of(outer_plane, m0.point) > -slack && side_of(inner_plane, m4.point) > -slack;
    }
    if (!ok) {
        fallback_wedge(&record, a1, b1, corners, far_depth);
        return record;
    }
    record.inner0 = vec4<f32>(m0.point, 0.0);
    record.inner1 = vec4<f32>(m1.point, 0.0);
    record.outer0 = vec4<f32>(m4.point, 0.0);
    record.outer1 = vec4<f32>(m5.point, 0.0);
    flag_record(&record, 0u);
    return record;
}

// Step 4c: write each half-edge, with its wedge, into its buffer's list.
@compute @workgroup_size(256)
fn wedges_scatter_edges(@builtin(global_invocation_id) id: vec3<u32>) {
    step_scatter_edges(id);
    record_silhouette_work(id.x);
}

fn step_scatter_edges(id: vec3<u32>) {
    if (id.x >= mesh.record_count) {
        return;
    }
    var out: array<Emission, 2>;
    let count = emissions(id.x, &out);
    for (var i = 0u; i < count; i += 1u) {
        let g = group_of(out[i].face);
        let slot = counters.edge_offset[g] + atomicAdd(&counters.edge_cursor[g], 1u);
        atomics += 1u;
        if (slot < mesh.half_edge_capacity) {
            half_edges[slot] = build_wedge(positions[out[i].a].xyz, positions[out[i].b].xyz);
            stored += 96u;
        }
    }
}

// Step 4c: write each cap face into its buffer's list.
@compute @workgroup_size(256)
fn wedges_scatter_caps(@builtin(global_invocation_id) id: vec3<u32>) {
    step_scatter_caps(id);
    record_silhouette_work(id.x);
}

fn step_scatter_caps(id: vec3<u32>) {
    let f = id.x;
    if (f >= mesh.face_count || !participates(face_state[f])) {
        return;
    }
    let g = group_of(f);
    let slot = counters.cap_offset[g] + atomicAdd(&counters.cap_cursor[g], 1u);
    caps[slot] = f;
    atomics += 1u;
    stored += 4u;
}
