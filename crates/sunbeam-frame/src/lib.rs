//! The prepared scene and the images both renderers share: the CPU reference
//! (`sunbeam-raster`) and the wgpu player (`sunbeam-render`) draw a
//! [`Prepared`] scene (the render scene with its meshes, packs and environment
//! loaded: [`prepare`]) into an [`Image`] (display values, PNG/APNG) or a
//! [`LinearImage`] (linear light, EXR), compared by CIEDE2000 ([`compare`],
//! [`compare_linear`], [`diff`]). [`spectral::Samples`] are the wavelengths of
//! both renderers' colour integrals; [`fixtures`] the renderers' test scenes.
//! No rendering here.

pub mod diff;
pub mod fixtures;
pub mod image;
pub mod linear;
pub mod scales;
pub mod spectral;

pub use diff::ColourDiff;
pub use image::{compare, Image};
pub use linear::{compare_linear, LinearImage};
pub use scales::{load_mesh_with_scales, MeshScales};
pub use sunbeam_scene::geometry::Mesh;

use std::any::Any;
use std::path::Path;
use std::sync::{Arc, OnceLock};
use sunbeam_common::{Error, Result};
use sunbeam_optics::masking::Masking;
use sunbeam_pack::Pack;
use sunbeam_scene::Scene;

/// What one mesh instance is shaded with.
#[derive(Debug, Clone)]
pub struct Material {
    pub pack: Option<Arc<Pack>>,
    /// Linear sRGB.
    pub base_color: [f64; 3],
    pub diffuse_weight: f64,
    /// Shadowing-masking on the diffraction's `G` (scene `masking`, `rms_slope`).
    pub masking: Masking,
    /// The skin's interface: index and normalisation of `G` (scene `ior`, `reflectance`).
    pub skin: sunbeam_optics::gain::Material,
    /// The mesh's scale maps (`sunbeam-bake --scales`; the reference applies them).
    pub scales: Option<Arc<MeshScales>>,
}

/// A scene with its meshes and packs loaded (shared by both renderers).
#[derive(Debug, Clone)]
pub struct Prepared {
    pub scene: Scene,
    pub meshes: Vec<(Arc<Mesh>, Material)>,
    /// The scene's environment, loaded (None: point lights only).
    pub environment: Option<Arc<sunbeam_light::Environment>>,
    /// What a renderer builds once for this scene and keeps with it (shared
    /// by clones: a turntable's frames build the reference's environment
    /// quadrature once).
    pub cache: RendererCache,
}

/// A slot for what one renderer builds once per prepared scene (the
/// reference fills it with its environment shaders), shared by the clones of
/// a [`Prepared`]. Its type is the renderer's: this crate does not know it.
#[derive(Clone, Default)]
pub struct RendererCache(Arc<OnceLock<Arc<dyn Any + Send + Sync>>>);

impl RendererCache {
    /// The value in the slot, made by `init` when the slot is empty; None when
    /// it holds a value of another type.
    pub fn get_or_init<T: Any + Send + Sync>(&self, init: impl FnOnce() -> T) -> Option<Arc<T>> {
        let v = self
            .0
            .get_or_init(|| Arc::new(init()) as Arc<dyn Any + Send + Sync>);
        v.clone().downcast::<T>().ok()
    }
}

impl std::fmt::Debug for RendererCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let state = if self.0.get().is_some() {
            "filled"
        } else {
            "empty"
        };
        write!(f, "RendererCache({state})")
    }
}

/// Load a mesh named by a scene: `builtin:quad`, `builtin:sphere`, or a glTF/GLB/OBJ
/// file through `sunbeam_mesh::load_scene_mesh` (its orientation field becomes `t`).
pub fn load_mesh(path: &Path) -> Result<Mesh> {
    if let Some(b) = Mesh::builtin(path) {
        return b.map_err(Error::input);
    }
    mesh_from_trimesh(sunbeam_mesh::load_scene_mesh(path)?, path)
}

/// The render mesh of a loaded scene mesh (its orientation field becomes `t`).
pub(crate) fn mesh_from_trimesh(tm: sunbeam_mesh::TriMesh, path: &Path) -> Result<Mesh> {
    let tangents = tm
        .orientation
        .iter()
        .zip(&tm.tangents)
        .map(|(o, t)| [o[0], o[1], o[2], if t[3] < 0.0 { -1.0 } else { 1.0 }])
        .collect();
    let m = Mesh {
        positions: tm.positions,
        normals: tm.normals,
        uvs: tm.uvs,
        tangents,
        indices: tm.indices,
    };
    m.check().map_err(|e| Error::input_file(path, e))?;
    Ok(m)
}

/// Bounds of the mesh a `--mesh M` form names (for `Scene::default_for`).
pub fn mesh_bounds(path: &Path) -> Result<([f64; 3], [f64; 3])> {
    Ok(load_mesh(path)?.bounds())
}

/// The scene the `--mesh M --pack P` form of `sunbeam-play` and `sunbeam-eval
/// render` draws under `lighting` (their `--lighting`, default sky).
pub fn default_scene(
    mesh: &Path,
    pack: Option<&Path>,
    lighting: sunbeam_scene::DefaultLighting,
) -> Result<Scene> {
    let b = mesh_bounds(mesh)?;
    let mut s = Scene::default_lit(mesh.to_path_buf(), pack.map(Path::to_path_buf), b, lighting);
    s.validate()?;
    Ok(s)
}

/// The negative texels of the scene's map set to 0 when it was loaded
/// (docs/SCENE.md "environment"): None without a map or without any.
pub fn environment_clamped(p: &Prepared) -> Option<sunbeam_light::Clamped> {
    match p.environment.as_deref() {
        Some(sunbeam_light::Environment::Map(m)) if m.clamped().values > 0 => Some(m.clamped()),
        _ => None,
    }
}

/// The one warning line (without the tool's prefix) for the negative texels
/// of the scene's map set to 0, with their counts (for a `--json` report's
/// `"environment_negatives_zeroed"`), or None when there were none.
pub fn environment_clamped_warning(p: &Prepared) -> Option<(String, sunbeam_light::Clamped)> {
    let c = environment_clamped(p)?;
    let map = p
        .scene
        .environment
        .as_ref()
        .and_then(|e| e.map.as_ref())
        .map(|m| m.display().to_string())
        .unwrap_or_default();
    let line = format!(
        "environment.map {map}: set {} negative values in {} texels to 0 (down to {:.3e}; \
         lossy compression; refused below -{:.3e}, {} x the mean luminance)",
        c.values,
        c.texels,
        c.min,
        c.bound,
        sunbeam_light::NEGATIVE_TEXEL_LIMIT
    );
    Some((line, c))
}

/// Load every mesh and pack of a scene (each file once).
pub fn prepare(scene: &Scene) -> Result<Prepared> {
    prepare_with(scene, &Pack::read)
}

/// [`prepare`] with the packs read by `load_pack` (the player reads only a
/// pack's manifest when a current response map stands beside it).
pub fn prepare_with(scene: &Scene, load_pack: &dyn Fn(&Path) -> Result<Pack>) -> Result<Prepared> {
    let environment = scene
        .environment
        .as_ref()
        .map(load_environment)
        .transpose()?;
    let mut meshes = Vec::new();
    type Loaded = (Arc<Mesh>, Option<Arc<MeshScales>>);
    let mut mesh_cache: Vec<(std::path::PathBuf, Loaded)> = Vec::new();
    let mut pack_cache: Vec<(std::path::PathBuf, Arc<Pack>)> = Vec::new();
    for (i, mi) in scene.meshes.iter().enumerate() {
        let (mesh, scales) = match mesh_cache.iter().find(|(p, _)| *p == mi.mesh) {
            Some((_, m)) => m.clone(),
            None => {
                let (m, sc) = load_mesh_with_scales(&mi.mesh)
                    .map_err(|e| e.context(format!("meshes[{i}].mesh")))?;
                let m = (Arc::new(m), sc.map(Arc::new));
                mesh_cache.push((mi.mesh.clone(), m.clone()));
                m
            }
        };
        let pack = match &mi.pack {
            None => None,
            Some(pp) => Some(match pack_cache.iter().find(|(p, _)| p == pp) {
                Some((_, k)) => k.clone(),
                None => {
                    let k = Arc::new(
                        load_pack(pp).map_err(|e| e.context(format!("meshes[{i}].pack")))?,
                    );
                    pack_cache.push((pp.clone(), k.clone()));
                    k
                }
            }),
        };
        if !(mi.diffuse_weight.is_finite() && (0.0..=1.0).contains(&mi.diffuse_weight)) {
            return Err(Error::input(format!(
                "meshes[{i}].diffuse_weight must be in [0, 1]"
            )));
        }
        let (lo, hi) = sunbeam_scene::IOR_RANGE;
        if !(mi.ior.is_finite() && mi.ior > lo && mi.ior <= hi) {
            return Err(Error::input(format!(
                "meshes[{i}].ior {} must be in ({lo}, {hi}]",
                mi.ior
            )));
        }
        let skin = sunbeam_optics::gain::Material {
            ior: mi.ior,
            reflectance: match mi.reflectance {
                sunbeam_scene::ReflectanceMode::Absolute => {
                    sunbeam_optics::gain::Reflectance::Absolute
                }
                sunbeam_scene::ReflectanceMode::Relative => {
                    sunbeam_optics::gain::Reflectance::Relative
                }
            },
            // filled by the renderer from the pack's response map
            energy: sunbeam_optics::energy::EnergyBound::OFF,
        };
        let masking = match (&pack, &mi.pack) {
            (Some(k), Some(path)) => mi
                .masking_slope(i, k.manifest.rms_slope)
                .map_err(|e| e.context(format!("meshes[{i}].pack {}", path.display())))?
                .map_or(Masking::Off, Masking::smith),
            _ => Masking::Off,
        };
        meshes.push((
            mesh,
            Material {
                pack,
                base_color: mi.base_color,
                diffuse_weight: mi.diffuse_weight,
                masking,
                skin,
                scales,
            },
        ));
    }
    Ok(Prepared {
        scene: scene.clone(),
        meshes,
        environment,
        cache: RendererCache::default(),
    })
}

/// The scene's `environment` block as a light source (the sky built, the map read).
pub fn load_environment(e: &sunbeam_scene::Environment) -> Result<Arc<sunbeam_light::Environment>> {
    e.validate()?;
    Ok(Arc::new(match (&e.sky, &e.map) {
        (Some(s), _) => sunbeam_light::Environment::Sky(Box::new(sunbeam_light::sky::Sky::new(
            s.sun_elevation_deg,
            s.sun_azimuth_deg,
            s.turbidity,
            e.intensity,
        ))),
        (None, Some(m)) => sunbeam_light::Environment::Map(sunbeam_light::io::load(
            m,
            e.rotation_deg,
            e.intensity,
        )?),
        (None, None) => {
            return Err(Error::input(
                "environment needs exactly one of 'sky' and 'map'",
            ))
        }
    }))
}

#[cfg(test)]
mod tests {
    use super::RendererCache;
    use std::sync::Arc;

    /// The slot is filled once and shared by clones; another type gets None
    /// and leaves the slot alone.
    #[test]
    fn the_renderer_cache_is_filled_once_and_shared() {
        let a = RendererCache::default();
        let b = a.clone();
        let x = a.get_or_init(|| 7u32).expect("a u32");
        let y = b.get_or_init(|| 8u32).expect("the same u32");
        assert!(Arc::ptr_eq(&x, &y) && *y == 7);
        assert!(b.get_or_init(|| "other").is_none());
        assert_eq!(*a.get_or_init(|| 9u32).unwrap(), 7);
        assert!(format!("{a:?}").contains("filled"));
    }
}
