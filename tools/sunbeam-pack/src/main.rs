//! sunbeam-pack (placeholder until its issue lands).
fn main() {
    sunbeam_common::error::run_main("sunbeam-pack", || {
        Err(sunbeam_common::Error::internal("sunbeam-pack is not implemented yet"))
    })
}
