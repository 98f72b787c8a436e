//! The point map as `sunbeam-pack --response` writes it and the player
//! builds it when there is none: the map ([`crate::build::build_with`]) and,
//! from the white furnace's set built in the same pass over the pack, the
//! energy bound's tables in its info ([`crate::energy::EnergyInfo`]).

use crate::build::{build_with, Options};
use crate::energy::{white_weights, EnergyInfo};
use crate::Response;
use sunbeam_pack::Pack;

/// Build the response map of `pack` with its energy-bound tables.
pub fn build(pack: &Pack, o: &Options) -> Response {
    let (mut resp, mut extra) = build_with(pack, o, vec![white_weights(pack, o.lambda_samples)]);
    let white = extra.pop().expect("the white furnace's set");
    resp.info.energy = Some(EnergyInfo::from_white(
        resp.info.grid,
        &white,
        pack.manifest.rms_slope,
    ));
    resp
}
