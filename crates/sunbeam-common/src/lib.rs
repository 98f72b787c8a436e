//! Conventions every Sunbeam tool follows (see DESIGN.md "Conventions"):
//! quantities with units on the command line, documented exit codes, outputs
//! written atomically, Make-style depfiles.

pub mod cli;
pub mod depfile;
pub mod error;
pub mod magic;
pub mod output;
pub mod rng;
pub mod testdata;
pub mod units;

pub use error::{Error, ExitCode, Result};
