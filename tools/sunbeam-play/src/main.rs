//! sunbeam-play (placeholder until its issue lands).
fn main() {
    sunbeam_common::error::run_main("sunbeam-play", || {
        Err(sunbeam_common::Error::internal("sunbeam-play is not implemented yet"))
    })
}
