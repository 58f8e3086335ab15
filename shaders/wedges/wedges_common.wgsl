// Penumbra wedges (Akenine-Möller and Assarsson 2002, Assarsson and
// Akenine-Möller 2003) with Forest, Barthe and Paulin's blending of
// overlapping penumbrae (Graphics Hardware 2006): what every wedges shader
// shares. The buffers' layouts are those of ssm-techniques/wedges/src/ (lib.rs,
// mesh.rs, silhouettes.rs).

// #import common/light_frame.wgsl

// No face: the second face of an edge record used by one face only.
const NO_FACE: u32 = 0xffffffffu;
// Threads per workgroup of every compute pass.
const WORKGROUP: u32 = 256u;
// Most silhouette buffers (Forest et al., Sec. 3: one per silhouette; here
// silhouettes are grouped round-robin into at most this many).
const MAX_SILHOUETTE_BUFFERS: u32 = 64u;
// Vertices drawn per silhouette half-edge: a shadow-volume side quad (two
// triangles), and a penumbra wedge (eight triangles); per cap face, the near
// and far caps.
const SIDE_VERTICES: u32 = 6u;
const CAP_VERTICES: u32 = 6u;
const WEDGE_VERTICES: u32 = 24u;
// u32 offset of the first group's draw arguments in the indirect buffer (after two dispatches).
const DRAW_ARGUMENTS: u32 = 8u;
// u32s of indirect arguments per group: draws of the sides, caps and wedges, and the blend's dispatch.
const GROUP_ARGUMENTS: u32 = 16u;

// Face.component of a face whose connected component is not a closed,
// consistently wound manifold: its faces are two-sided (each faces the light).
const TWO_SIDED_COMPONENT: u32 = 0xffffffffu;
// Fixed-point units of a closed component's winding number around the light's
// centre (the solid angle it subtends, summed over its faces with i32
// atomics): one full turn, 4 pi steradians, is 2^24 units.
const WINDING_TURN: f32 = 16777216.0;
// Face state bits, computed per frame from the light's centre.
const STATE_PARTICIPATES: u32 = 1u;
const STATE_REVERSED: u32 = 2u;
// Wedge record flags (in `flags` of WedgeRecord): no wedge; a fallback bounded by
// its screen rectangle; a fallback bounded by the pyramid from its apex (the end
// nearer the light, a' unless WEDGE_APEX_B) to the far rectangle.
const WEDGE_EMPTY: u32 = 1u;
const WEDGE_FALLBACK: u32 = 2u;
const WEDGE_PYRAMID: u32 = 4u;
const WEDGE_APEX_B: u32 = 8u;

// The technique's parameters (`WedgesSettings`) and the casting mesh's sizes and the scene's
// bounds (`WedgesMesh`), declared once in Rust (`WedgesSettingsUniform` in
// ssm-techniques/wedges/src/lib.rs, `WedgesMeshUniform` in src/silhouettes.rs), whose derive
// writes these structs.
// #import rust/WedgesSettings
// #import rust/WedgesMesh

// One triangle of the welded casting mesh (Requirements::adjacency).
struct Face {
    v0: u32,
    v1: u32,
    v2: u32,
    // Index of the face's closed component (into the winding numbers), or TWO_SIDED_COMPONENT.
    component: u32,
};

// One edge incidence: `v0 -> v1` is the edge as `face_a` winds it; `face_b`,
// when present, winds it `v1 -> v0` (a manifold, consistently wound edge), or
// `v0 -> v1` as well when `face_b_winds_forward` is 1 (two faces of a
// two-sided surface whose windings disagree).
struct EdgeRecord {
    v0: u32,
    v1: u32,
    face_a: u32,
    face_b: u32,
    face_b_winds_forward: u32,
};

// Whether face_b, turned to face the light, runs the edge v1 -> v0 (the
// opposite of face_a's stored winding) given its state.
fn face_b_runs_backwards(record: EdgeRecord, reversed_b: bool) -> bool {
    return (record.face_b_winds_forward == 0u) != reversed_b;
}

// One silhouette half-edge and its penumbra wedge (Sec. 4.2; Lengyel 2005).
// `a -> b` is the edge oriented so that its shadow volume (the prism of its
// face, turned towards the light) lies on the negative side of the plane
// through the light's centre, a and b (the split plane). The wedge is the
// convex polyhedron of a', b' (the edge clipped to the geometric near plane)
// and four far points, on the plane past the frame's far depth, where the
// inner and outer tangent planes meet the side planes. A fallback wedge keeps
// instead the four corners of its far rectangle.
struct WedgeRecord {
    // xyz: a; w: parameter along a -> b where the wedge's spine starts.
    a: vec4<f32>,
    // xyz: b; w: parameter where it ends.
    b: vec4<f32>,
    // Far points of the inner tangent plane, at a's side plane and at b's (fallback: two corners).
    inner0: vec4<f32>,
    inner1: vec4<f32>,
    // Far points of the outer tangent plane (fallback: the other two corners).
    outer0: vec4<f32>,
    // xyz: the last far point; w: flags (bitcast u32: WEDGE_EMPTY, WEDGE_FALLBACK, WEDGE_PYRAMID, WEDGE_APEX_B).
    outer1: vec4<f32>,
};

// The frame's counters (a storage buffer cleared by the reset pass).
struct Counters {
    // Set by a hook pass that linked two labels.
    changed: atomic<u32>,
    // Label-propagation rounds that linked anything.
    rounds: atomic<u32>,
    // Silhouette regions (connected sets of faces turned to the light).
    regions: u32,
    // Silhouette half-edges emitted, cap faces emitted.
    half_edges: u32,
    caps: u32,
    // Wedges drawn as a full-screen fallback (degenerate geometry).
    fallback_wedges: atomic<u32>,
    // Groups with anything in them.
    groups_used: u32,
    _pad0: u32,
    edge_count: array<atomic<u32>, 64>,
    edge_cursor: array<atomic<u32>, 64>,
    cap_count: array<atomic<u32>, 64>,
    cap_cursor: array<atomic<u32>, 64>,
    edge_offset: array<u32, 64>,
    cap_offset: array<u32, 64>,
    // Per buffer, a bound on any point's stencil count: one per region of a convex closed
    // component (a ray enters or leaves it once), one per face of any other.
    stencil_levels: array<atomic<u32>, 64>,
};

// A point at infinity in the direction from the light's centre through `p`, in clip space.
fn clip_at_infinity(view_proj: mat4x4<f32>, frame: LightFrame, p: vec3<f32>) -> vec4<f32> {
    return view_proj * vec4<f32>(p - frame.centre.xyz, 0.0);
}

// The camera depth (NDC) by which wedges_depth_copy moves the G-buffer's depth at a point
// `position` with normal `normal` (turned towards the camera): `depth_bias` towards the side of
// the surface facing the light's centre (towards the camera when the centre is on its side).
fn volume_depth_offset(frame: LightFrame, depth_bias: f32, position: vec3<f32>, normal: vec3<f32>) -> f32 {
    return select(depth_bias, -depth_bias, dot(normal, frame.centre.xyz - position) >= 0.0);
}

// The point whose depth the shadow volumes' stencil test judges at the pixel showing
// `position`: `position` moved along the view ray from `eye` until its NDC depth has moved by
// `offset`. Along the ray eye + s (position - eye), clip z and w are affine in s with w = 0 at
// the eye, so NDC depth is z_eye / (s w) + const, and moving it by `offset` gives
// 1 / s = 1 + offset w / z_eye (z_eye is never 0 for a perspective projection).
fn volume_test_point(view_proj: mat4x4<f32>, eye: vec3<f32>, position: vec3<f32>, offset: f32) -> vec3<f32> {
    let z_eye = (view_proj * vec4<f32>(eye, 1.0)).z;
    let w = (view_proj * vec4<f32>(position, 1.0)).w;
    return eye + (position - eye) / (1.0 + offset * w / z_eye);
}
