//! sunbeam-import (placeholder until its issue lands).
fn main() {
    sunbeam_common::error::run_main("sunbeam-import", || {
        Err(sunbeam_common::Error::internal("sunbeam-import is not implemented yet"))
    })
}
