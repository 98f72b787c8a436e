//! The reference's environment shaders and its packs' energy-bound tables,
//! built once per prepared scene: kept in the scene's
//! [`sunbeam_frame::RendererCache`] slot.

use crate::environment;
use std::sync::{Arc, Mutex};
use sunbeam_frame::Prepared;
use sunbeam_optics::masking::Masking;
use sunbeam_pack::Pack;

/// The cache of `p` (a fresh one, not kept, when another renderer holds
/// the slot).
pub(crate) fn of(p: &Prepared) -> Arc<EnvCache> {
    p.cache.get_or_init(EnvCache::default).unwrap_or_default()
}

/// Built [`environment::EnvShader`]s, keyed by estimator, environment,
/// packs (the same `Arc`s: a changed environment or pack builds anew; the key
/// holds them, so their addresses cannot be reused by others while cached)
/// and the meshes' masking and skins.
#[derive(Default)]
pub(crate) struct EnvCache(Mutex<Vec<EnvEntry>>, Mutex<Vec<EnergyEntry>>);

/// A pack's energy-bound tables (the same `Arc` keys them).
struct EnergyEntry {
    pack: Arc<Pack>,
    info: Arc<sunbeam_response::energy::EnergyInfo>,
}

struct EnvEntry {
    estimator: environment::EnvEstimator,
    masking: Vec<Masking>,
    skins: Vec<sunbeam_optics::gain::Material>,
    env: Arc<sunbeam_light::Environment>,
    packs: Vec<Option<Arc<Pack>>>,
    shader: Arc<environment::EnvShader>,
}

impl EnvCache {
    /// The energy bound's tables of `pack`, built on first use as
    /// `sunbeam-pack --response` builds them.
    pub(crate) fn energy(&self, pack: &Arc<Pack>) -> Arc<sunbeam_response::energy::EnergyInfo> {
        let mut v = self.1.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(e) = v.iter().find(|e| Arc::ptr_eq(&e.pack, pack)) {
            return e.info.clone();
        }
        let info = Arc::new(sunbeam_response::energy::EnergyInfo::from_pack(
            pack,
            &sunbeam_response::Options::default(),
        ));
        v.push(EnergyEntry {
            pack: pack.clone(),
            info: info.clone(),
        });
        info
    }

    /// The shader for `env`, `packs` (with their meshes' `masking` and
    /// `skins`) and `estimator`, built on first use.
    pub(crate) fn get(
        &self,
        env: Arc<sunbeam_light::Environment>,
        packs: &[Option<Arc<Pack>>],
        masking: &[Masking],
        skins: &[sunbeam_optics::gain::Material],
        estimator: environment::EnvEstimator,
    ) -> Arc<environment::EnvShader> {
        let same_packs = |a: &[Option<Arc<Pack>>]| {
            a.len() == packs.len()
                && a.iter().zip(packs).all(|(x, y)| match (x, y) {
                    (Some(x), Some(y)) => Arc::ptr_eq(x, y),
                    (None, None) => true,
                    _ => false,
                })
        };
        let mut v = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(e) = v.iter().find(|e| {
            e.estimator == estimator
                && e.masking == masking
                && e.skins == skins
                && Arc::ptr_eq(&e.env, &env)
                && same_packs(&e.packs)
        }) {
            return e.shader.clone();
        }
        let shader = Arc::new(
            environment::EnvShader::with_estimator(env.clone(), packs, estimator)
                .with_masking(masking)
                .with_skin(skins),
        );
        v.push(EnvEntry {
            estimator,
            masking: masking.to_vec(),
            skins: skins.to_vec(),
            env,
            packs: packs.to_vec(),
            shader: shader.clone(),
        });
        shader
    }
}
