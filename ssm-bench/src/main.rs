//! `ssm`: render scenes with any registered soft-shadow technique.
//!
//! Every technique crate of the workspace is linked through the library ([`ssm_bench::registry`]
//! goes through the `ssm-techniques` facade), so this binary is the library's command line.

fn main() -> std::process::ExitCode {
    // First thing, before any thread exists (see its documentation).
    ssm_bench::run()
}
