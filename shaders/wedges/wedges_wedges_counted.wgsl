// The wedge pass as built for `--count-work` (issue #40): the same fragment (wedges_wedges.wgsl)
// with its depth test forced before the shader. Counting is a side effect (an atomic per
// fragment), and a fragment shader with side effects runs before its depth test, so without this
// every wedge fragment behind the scene's surface would run, and be counted, where the timed pass
// (no side effect) rejects it first: the count would be of more work than the timed frame does.
// The wedges write no depth and no stencil, so testing first changes no result. Needs
// SHADER_EARLY_DEPTH_TEST, which only the counting build asks for.

// #import wedges/wedges_wedges.wgsl

@early_depth_test(force)
@fragment
fn wedges_wedge_fragment_counted(in: WedgeVarying) -> WedgeTargets {
    return wedge_fragment(in);
}
