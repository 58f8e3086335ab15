// The screen segment that a workgroup of SSSM's compute blurs (steps 2 and 3) shares: its
// SEGMENT_PIXELS pixels of a row or a column, widened either side by the widest reach of the
// group's blurs, up to SEGMENT_CAPACITY texels, loaded once into workgroup memory.

// #import sssm/sssm_common.wgsl

// Pixels per workgroup, along its row or down its column.
const SEGMENT_PIXELS: u32 = 64u;
// Texels of the segment: the group's pixels and up to (768 - 64) / 2 = 352 either side, in
// 5 · 4 · 768 = 15,360 bytes (WebGPU guarantees 16,384).
const SEGMENT_CAPACITY: u32 = 768u;

var<workgroup> segment_value: array<f32, SEGMENT_CAPACITY>;
var<workgroup> segment_eye_distance: array<f32, SEGMENT_CAPACITY>;
var<workgroup> segment_normal_x: array<f32, SEGMENT_CAPACITY>;
var<workgroup> segment_normal_y: array<f32, SEGMENT_CAPACITY>;
var<workgroup> segment_normal_z: array<f32, SEGMENT_CAPACITY>;
// The widest reach of the group's blurs, whole pixels beyond the group's own.
var<workgroup> group_reach: atomic<u32>;

// The segment's first texel along its axis and its length (the same in every invocation; 0 when
// no pixel of the group blurs).
var<private> segment_start: i32;
var<private> segment_length: i32;
// The row (step 2) or column (step 3) the segment lies on: a tap elsewhere reads the texture.
var<private> segment_line: i32;

// Widens the group's reach for a blur of half-width `radius` pixels (before the first barrier).
// Taps lie within the radius of the pixel's centre: in its texel's column or row ± ceil(radius).
fn reach_for(radius: f32) {
    atomicMax(&group_reach, u32(ceil(min(radius, f32(SEGMENT_CAPACITY))) + 1.0));
}

// Places the segment of the group whose first pixel is at `first` along the axis (after the first
// barrier, when every reach is in).
fn place_segment(first: i32) {
    let reach = min(atomicLoad(&group_reach), (SEGMENT_CAPACITY - SEGMENT_PIXELS) / 2u);
    segment_start = first - i32(reach);
    segment_length = select(0, i32(SEGMENT_PIXELS + 2u * reach), reach > 0u);
}

fn store_segment(index: i32, source: BlurSource) {
    segment_value[index] = source.value;
    segment_eye_distance[index] = source.eye_distance;
    segment_normal_x[index] = source.normal.x;
    segment_normal_y[index] = source.normal.y;
    segment_normal_z[index] = source.normal.z;
}

// The index in the segment of the texel at `coordinate` along its axis; -1 outside it.
fn segment_index(coordinate: i32) -> i32 {
    let index = coordinate - segment_start;
    return select(-1, index, index >= 0 && index < segment_length);
}

fn segment_source(index: i32) -> BlurSource {
    let normal = vec3<f32>(segment_normal_x[index], segment_normal_y[index], segment_normal_z[index]);
    return BlurSource(segment_value[index], segment_eye_distance[index], normal);
}
