//! Optics for Sunbeam (PHYSICS.md): CIE tables, colour science, the gain `G`,
//! and the float64 ground truth `R(u, v, w, lambda)` that every fast path is
//! tested against.
//!
//! - [`cie`]: CIE 1931 2-degree colour matching functions and D65 at 1 nm, and
//!   the spectral integral of PHYSICS.md 2.
//! - [`colour`]: XYZ -> linear sRGB, CIELAB, CIEDE2000, and THE tone mapping +
//!   sRGB encoding shared by the player and the CPU reference renderer.
//! - [`energy`]: the energy bound on `G` at grazing views (albedo <= 1).
//! - [`gain`]: `G(wi, wr)` with the exact Fresnel power reflectance, once
//!   (n = 1.5, absolute reflectance by default), and the diffuse base's `1 - F`.
//! - [`grazing`]: the window model's exact Kirchhoff amplitude (PHYSICS.md 2b).
//! - [`masking`]: optional Smith shadowing-masking on top of `G` (grazing views).
//! - [`truth`]: the ground truth (window and tiled models), sharing no code
//!   with `sunbeam-pack`.

pub mod cie;
mod cie_data;
pub mod colour;
pub mod energy;
pub mod gain;
pub mod grazing;
pub mod masking;
pub mod truth;

pub use truth::Model;
