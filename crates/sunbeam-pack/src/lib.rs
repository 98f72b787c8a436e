//! Diffraction term packs (PHYSICS.md 3, docs/PACK_FORMAT.md): basis terms of a
//! height field, FFT, crop, KTX2/EXR I/O and the CPU evaluator the player follows.
pub mod build;
pub mod exr_io;
pub mod kernel;
pub mod ktx2;
pub mod manifest;
pub mod pack;
pub mod series;

pub use build::{build, BuildOptions, FieldRef};
pub use manifest::{Basis, Manifest, Model, Precision};
pub use pack::Pack;
pub mod io;
pub mod scene;
