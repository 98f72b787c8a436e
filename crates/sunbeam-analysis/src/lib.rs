//! What `sunbeam-eval` measures, as a library: `R(u, v, w, lambda)` from a pack
//! or from the float64 ground truth of a height field behind one interface
//! ([`source::Source`]), deterministic sampling ([`sample`]), a pack against
//! its truth ([`compare`]: spectral and colour error), what the BRDF pictures
//! show ([`brdf`]), `R` at the points of a points file ([`probe`]), the grating period a
//! surface's diffraction peaks imply ([`grating`]), and the pack facts those
//! need ([`packinfo`]). The tool keeps argument parsing, plots, progress and
//! exit codes (docs/EVAL.md).

pub mod brdf;
pub mod compare;
pub mod grating;
pub mod packinfo;
pub mod probe;
pub mod sample;
pub mod source;

pub use source::{par_map, Source};
