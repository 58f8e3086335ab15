//! Support for the criterion benches (`benches/`): the image size they render at ([`bench_size`]).

/// The image size of the criterion benches: `SSM_BENCH_SIZE=WxH`, or `full`
/// for 1280×720; 256×192 by default, small enough for lavapipe.
///
/// # Errors
/// A value that is neither `full` nor `WxH` with positive sides.
pub fn bench_size() -> Result<(u32, u32), String> {
    match std::env::var("SSM_BENCH_SIZE").as_deref() {
        Ok("full") => Ok((1280, 720)),
        Ok(text) => text
            .split_once('x')
            .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
            .filter(|&(w, h): &(u32, u32)| w > 0 && h > 0)
            .ok_or_else(|| format!("SSM_BENCH_SIZE={text}: expected WxH or full")),
        Err(_) => Ok((256, 192)),
    }
}
