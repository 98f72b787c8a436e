//! Diffraction term packs (PHYSICS.md 3, docs/PACK_FORMAT.md): basis terms of a
//! height field, FFT, crop, KTX2/EXR I/O and the CPU evaluator the player follows.
//!
//! The physics core: depends on sunbeam-field, sunbeam-optics and sunbeam-common
//! only. Reading instrument files into a height field is `sunbeam_afm::height`;
//! the directions a scene can reach (`--scene`) are `sunbeam_scene::reach`.
pub mod build;
pub mod formats;
pub mod kernel;
pub mod manifest;
pub mod pack;
pub mod series;

/// The old name of [`formats`] (tools/sunbeam-play/tests use it).
#[doc(hidden)]
pub use formats as io;
pub use formats::{exr_io, ktx2};

pub use build::{build, BuildOptions, FieldRef};
pub use manifest::{Basis, Manifest, Model, Precision};
pub use pack::Pack;
