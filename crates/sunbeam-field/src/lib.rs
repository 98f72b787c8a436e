//! The height field: the type every Sunbeam tool exchanges (PHYSICS.md 1).
//!
//! `data[r * width + c]` is the height in metres of row `r` (row 0 at the top,
//! as Gwyddion shows it) and column `c`. Image x runs along columns, image y
//! runs *up* the image, so `y = (height - 1 - r) * dy`.

mod field;

pub use field::{HeightField, Provenance};
