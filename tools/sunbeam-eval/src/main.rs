//! sunbeam-eval (placeholder until its issue lands).
fn main() {
    sunbeam_common::error::run_main("sunbeam-eval", || {
        Err(sunbeam_common::Error::internal("sunbeam-eval is not implemented yet"))
    })
}
