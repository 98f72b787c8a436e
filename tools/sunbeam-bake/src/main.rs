//! sunbeam-bake (placeholder until its issue lands).
fn main() {
    sunbeam_common::error::run_main("sunbeam-bake", || {
        Err(sunbeam_common::Error::internal("sunbeam-bake is not implemented yet"))
    })
}
