//! The height field: the type every Sunbeam tool exchanges (PHYSICS.md 1),
//! its files (EXR, GSF), and the processing `sunbeam-import` applies.
//!
//! `data[r * width + c]` is the height in metres of row `r` (row 0 at the top,
//! as Gwyddion shows it) and column `c`. Image x runs along columns, image y
//! runs *up* the image, so `y = (height - 1 - r) * dy`.

pub mod align;
mod field;
pub mod fill;
pub mod geom;
pub mod io;
pub mod level;
pub mod pipeline;
pub mod preview;
pub mod resample;
pub mod scars;
pub mod stats;

pub use field::{HeightField, Provenance, MAX_SIDE};
