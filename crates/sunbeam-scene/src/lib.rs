//! The scene format (JSON), shared by `sunbeam-play`, `sunbeam-eval render` and
//! `sunbeam-pack --scene`. Documented in docs/SCENE.md. Paths inside a scene are
//! relative to the scene file. World space is right-handed, y up.
//!
//! The `--mesh M.glb --pack P.ktx2` form of the tools builds [`Scene::default_for`],
//! so the defaults live in exactly one place.

pub mod camera;
pub mod geometry;
pub mod reach;

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use sunbeam_common::{Error, Result};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    pub camera: Camera,
    #[serde(default = "default_lights")]
    pub lights: Vec<Light>,
    pub meshes: Vec<MeshInstance>,
    /// Exposure in stops (EV): linear colour is multiplied by 2^exposure before tone mapping.
    #[serde(default)]
    pub exposure: f64,
    /// Background: a linear sRGB colour, or `"environment"` (the scene's
    /// environment seen along each view ray).
    #[serde(default)]
    pub background: Background,
    /// Output size in pixels (width, height) for headless renders.
    #[serde(default = "default_size")]
    pub size: [u32; 2],
    /// Extended light around the scene: a built-in sky or an equirectangular map.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<Environment>,
}

/// `"background"`: what a pixel that sees no mesh shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Background {
    /// A constant linear sRGB colour (`[r, g, b]`).
    Colour([f64; 3]),
    /// The scene's environment (sky or map, rotated, times its intensity)
    /// along the pixel's view ray (`"environment"`).
    Environment,
}

impl Default for Background {
    fn default() -> Self {
        Background::Colour([0.0; 3])
    }
}

impl Background {
    /// The constant colour, or None for `"environment"`.
    pub fn colour(&self) -> Option<[f64; 3]> {
        match self {
            Background::Colour(c) => Some(*c),
            Background::Environment => None,
        }
    }
}

impl Serialize for Background {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            Background::Colour(c) => c.serialize(s),
            Background::Environment => s.serialize_str("environment"),
        }
    }
}

impl<'de> Deserialize<'de> for Background {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        use serde::de::Error as _;
        const WANT: &str =
            "background: expected an [r, g, b] array of 3 numbers (linear sRGB) or \"environment\"";
        match serde_json::Value::deserialize(d)? {
            serde_json::Value::String(s) if s == "environment" => Ok(Background::Environment),
            serde_json::Value::Array(a) if a.len() == 3 => {
                let mut c = [0.0; 3];
                for (k, v) in a.iter().enumerate() {
                    c[k] = v.as_f64().ok_or_else(|| D::Error::custom(WANT))?;
                }
                Ok(Background::Colour(c))
            }
            _ => Err(D::Error::custom(WANT)),
        }
    }
}

/// `"environment"`: exactly one of `sky` or `map`, scaled by `intensity`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Environment {
    /// Built-in analytic sky and sun.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sky: Option<Sky>,
    /// Equirectangular HDR image (`.hdr` or `.exr`), width = 2 * height,
    /// relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub map: Option<PathBuf>,
    /// Rotation of the map about +y, degrees (towards +z from +x); maps only.
    #[serde(default)]
    pub rotation_deg: f64,
    /// Scale on the environment's radiance, finite and >= 0.
    #[serde(default = "one")]
    pub intensity: f64,
}

/// `"environment.sky"`: sun position and atmospheric turbidity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sky {
    /// Sun elevation above the horizon, degrees, in [-90, 90].
    pub sun_elevation_deg: f64,
    /// Sun azimuth, degrees, from +x towards +z (the map's convention).
    #[serde(default)]
    pub sun_azimuth_deg: f64,
    /// Atmospheric turbidity, in [1.7, 10] (Preetham's model's range).
    #[serde(default = "default_turbidity")]
    pub turbidity: f64,
}

fn default_turbidity() -> f64 {
    3.0
}

impl Environment {
    /// Check the fields (not the map's pixels: the loader does that).
    pub fn validate(&self) -> Result<()> {
        if !(self.intensity.is_finite() && self.intensity >= 0.0) {
            return Err(Error::input(format!(
                "environment.intensity {} must be finite and >= 0",
                self.intensity
            )));
        }
        if !self.rotation_deg.is_finite() {
            return Err(Error::input("environment.rotation_deg must be finite"));
        }
        match (&self.sky, &self.map) {
            (Some(_), Some(_)) | (None, None) => {
                return Err(Error::input(
                    "environment needs exactly one of 'sky' and 'map'",
                ))
            }
            (Some(sky), None) => {
                if !(-90.0..=90.0).contains(&sky.sun_elevation_deg) {
                    return Err(Error::input(
                        "environment.sky.sun_elevation_deg must be in [-90, 90]",
                    ));
                }
                if !sky.sun_azimuth_deg.is_finite() {
                    return Err(Error::input(
                        "environment.sky.sun_azimuth_deg must be finite",
                    ));
                }
                if !(1.7..=10.0).contains(&sky.turbidity) {
                    return Err(Error::input(
                        "environment.sky.turbidity must be in [1.7, 10]",
                    ));
                }
            }
            (None, Some(map)) => {
                let ext = map
                    .extension()
                    .and_then(|e| e.to_str())
                    .map(|e| e.to_ascii_lowercase());
                if !matches!(ext.as_deref(), Some("hdr") | Some("exr")) {
                    return Err(Error::input(format!(
                        "environment.map {}: must be a .hdr or .exr file",
                        map.display()
                    )));
                }
            }
        }
        Ok(())
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub eye: [f64; 3],
    pub target: [f64; 3],
    #[serde(default = "default_up")]
    pub up: [f64; 3],
    /// Vertical field of view, degrees.
    #[serde(default = "default_fov")]
    pub fov_y_deg: f64,
    /// Lens shift `[x, y]` (Blender's): the image window moves right by `x`
    /// and up by `y` times the image's larger side, the view direction and
    /// field of view unchanged (an off-axis projection).
    #[serde(
        default,
        skip_serializing_if = "is_zero2",
        deserialize_with = "camera_shift"
    )]
    pub shift: [f64; 2],
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Light {
    /// Direction *towards* the light (world space); normalised on load.
    pub direction: [f64; 3],
    /// Scale on the light's spectrum.
    #[serde(default = "one")]
    pub intensity: f64,
    /// Spectral power distribution: "D65" (the default; the only one for now).
    #[serde(default = "default_spectrum")]
    pub spectrum: String,
    /// Linear sRGB colour `[r, g, b]` multiplying the light's contribution
    /// channel by channel (finite, >= 0; default white). The diffraction is
    /// computed under the spectrum and its RGB result tinted: an
    /// approximation for a coloured light (docs/SCENE.md).
    #[serde(
        default = "white",
        skip_serializing_if = "is_white",
        deserialize_with = "light_color"
    )]
    pub color: [f64; 3],
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshInstance {
    /// glTF/GLB file (baked by sunbeam-bake so it has TANGENT / _ORIENTATION).
    pub mesh: PathBuf,
    /// Diffraction pack (KTX2). None: the mesh is shaded with its base colour only.
    #[serde(default)]
    pub pack: Option<PathBuf>,
    /// Base (diffuse) colour, linear sRGB.
    #[serde(default = "default_base")]
    pub base_color: [f64; 3],
    /// Weight of the diffuse base colour blended with the diffraction colour (thesis' diffuse weight).
    #[serde(default = "default_diffuse_weight")]
    pub diffuse_weight: f64,
    /// Shadowing and masking by the surface's own relief on top of `G`
    /// (sunbeam_optics::masking): `off` (PHYSICS.md's reference) or `smith`.
    #[serde(default)]
    pub masking: MaskingMode,
    /// The rms slopes `smith` uses, `[along t, along b]` or one value for both;
    /// none: the pack's (`rms_slope` in its manifest).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rms_slope: Option<RmsSlope>,
    /// The skin's refractive index (Fresnel, PHYSICS.md 2): 1.5 by default,
    /// in (1, 4].
    #[serde(default = "default_ior")]
    pub ior: f64,
    /// `absolute` (default: a dielectric reflects F(0) = 4 % head-on) or
    /// `relative` (divided by F(0), the thesis' normalisation).
    #[serde(default)]
    pub reflectance: ReflectanceMode,
}

/// `meshes[].reflectance`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ReflectanceMode {
    /// Physical reflectance (what engines assume for a dielectric).
    #[default]
    Absolute,
    /// Divided by `F(0)`: a flat patch head-on reflects 1.
    Relative,
}

// Hand-written so that a bad value names its field.
impl<'de> Deserialize<'de> for ReflectanceMode {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        match s.as_str() {
            "absolute" => Ok(ReflectanceMode::Absolute),
            "relative" => Ok(ReflectanceMode::Relative),
            _ => Err(serde::de::Error::custom(format!(
                "meshes[].reflectance \"{s}\": expected \"absolute\" or \"relative\""
            ))),
        }
    }
}

/// The range `meshes[].ior` accepts.
pub const IOR_RANGE: (f64, f64) = (1.0, 4.0);

fn default_ior() -> f64 {
    1.5
}

/// `meshes[].masking`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MaskingMode {
    /// `G` alone (PHYSICS.md 2).
    #[default]
    Off,
    /// Smith's height-correlated shadowing-masking, Beckmann slopes.
    Smith,
}

// Hand-written so that a bad value names its field (serde's derived messages
// for enums do not).
impl<'de> Deserialize<'de> for MaskingMode {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        match s.as_str() {
            "off" => Ok(MaskingMode::Off),
            "smith" => Ok(MaskingMode::Smith),
            _ => Err(serde::de::Error::custom(format!(
                "meshes[].masking \"{s}\": expected \"off\" or \"smith\""
            ))),
        }
    }
}

/// `meshes[].rms_slope`: one value (isotropic) or `[x, y]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum RmsSlope {
    Both(f64),
    Axes([f64; 2]),
}

impl<'de> Deserialize<'de> for RmsSlope {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let bad = || serde::de::Error::custom("meshes[].rms_slope: expected a number or [x, y]");
        match serde_json::Value::deserialize(d)? {
            serde_json::Value::Number(n) => n.as_f64().map(RmsSlope::Both).ok_or_else(bad),
            serde_json::Value::Array(a) if a.len() == 2 => match (a[0].as_f64(), a[1].as_f64()) {
                (Some(x), Some(y)) => Ok(RmsSlope::Axes([x, y])),
                _ => Err(bad()),
            },
            _ => Err(bad()),
        }
    }
}

impl RmsSlope {
    pub fn axes(self) -> [f64; 2] {
        match self {
            RmsSlope::Both(v) => [v, v],
            RmsSlope::Axes(a) => a,
        }
    }
}

impl MeshInstance {
    /// The rms slopes the shading masks with, `None` when masking is off.
    /// `pack_slope` is the pack's `rms_slope` (none for packs that predate it);
    /// mesh `i` names the field in errors.
    pub fn masking_slope(
        &self,
        i: usize,
        pack_slope: Option<[f64; 2]>,
    ) -> Result<Option<[f64; 2]>> {
        match self.masking {
            MaskingMode::Off => Ok(None),
            MaskingMode::Smith => match self.rms_slope.map(RmsSlope::axes).or(pack_slope) {
                Some(s) => Ok(Some(s)),
                None => Err(Error::input(format!(
                    "meshes[{i}].masking \"smith\" needs rms slopes: the pack has no rms_slope \
                     (rebuild it with this sunbeam-pack) and meshes[{i}].rms_slope is not given"
                ))),
            },
        }
    }
}

fn one() -> f64 {
    1.0
}
fn white() -> [f64; 3] {
    [1.0; 3]
}
fn is_white(c: &[f64; 3]) -> bool {
    *c == [1.0; 3]
}
fn is_zero2(v: &[f64; 2]) -> bool {
    *v == [0.0; 2]
}

/// An array of `N` numbers, or an error naming `field` and what it wants.
fn numbers<'de, D: serde::Deserializer<'de>, const N: usize>(
    d: D,
    field: &str,
    want: &str,
) -> std::result::Result<[f64; N], D::Error> {
    let bad = || serde::de::Error::custom(format!("{field}: expected {want}"));
    match serde_json::Value::deserialize(d)? {
        serde_json::Value::Array(a) if a.len() == N => {
            let mut out = [0.0; N];
            for (o, v) in out.iter_mut().zip(&a) {
                *o = v.as_f64().ok_or_else(bad)?;
            }
            Ok(out)
        }
        _ => Err(bad()),
    }
}
fn light_color<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<[f64; 3], D::Error> {
    numbers(d, "lights[].color", "[r, g, b], 3 numbers (linear sRGB)")
}
fn camera_shift<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<[f64; 2], D::Error> {
    numbers(d, "camera.shift", "[x, y], 2 numbers")
}
fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f64 {
    35.0
}
fn default_spectrum() -> String {
    "D65".into()
}
fn default_base() -> [f64; 3] {
    [0.05, 0.05, 0.05]
}
fn default_diffuse_weight() -> f64 {
    0.2
}
fn default_size() -> [u32; 2] {
    [512, 512]
}
fn default_lights() -> Vec<Light> {
    vec![Light::default_light()]
}

impl Light {
    /// The documented default light: D65 from above and a little behind the viewer.
    pub fn default_light() -> Self {
        Light {
            direction: [0.3, 1.0, 0.6],
            intensity: 1.0,
            spectrum: default_spectrum(),
            color: white(),
        }
    }
}

/// What lights the default scene of `--mesh M --pack P` (the tools' `--lighting`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DefaultLighting {
    /// The built-in sky with its sun ([`Scene::default_sky`]): what makes the
    /// whole body of a snake shimmer (docs/LIGHTING.md).
    Sky,
    /// One directional D65 light ([`Light::default_light`]), exposure 0.
    Point,
}

impl std::str::FromStr for DefaultLighting {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "sky" => Ok(DefaultLighting::Sky),
            "point" => Ok(DefaultLighting::Point),
            _ => Err(format!("unknown lighting '{s}' (sky or point)")),
        }
    }
}

impl Scene {
    /// The environment of the default scene: the sun 35 degrees up, 70 degrees
    /// from +x towards +z (above, a little right of and behind a camera on +z,
    /// as the point light), turbidity 3, intensity 1.
    pub fn default_sky() -> Environment {
        Environment {
            sky: Some(Sky {
                sun_elevation_deg: 35.0,
                sun_azimuth_deg: 70.0,
                turbidity: 3.0,
            }),
            map: None,
            rotation_deg: 0.0,
            intensity: 1.0,
        }
    }

    /// Exposure of the sky-lit default scene (stops): the sun's diffraction
    /// orders are several times the radiance of a white diffuser.
    pub const DEFAULT_SKY_EXPOSURE: f64 = -1.0;

    /// The scene the `--mesh M --pack P` form of the tools renders: lit by the
    /// built-in sky ([`Scene::default_sky`], no point light, exposure
    /// [`Scene::DEFAULT_SKY_EXPOSURE`]); the camera as [`Scene::default_lit`].
    pub fn default_for(mesh: PathBuf, pack: Option<PathBuf>, bounds: ([f64; 3], [f64; 3])) -> Self {
        Scene::default_lit(mesh, pack, bounds, DefaultLighting::Sky)
    }

    /// The default scene under `lighting`: the default camera looks at the
    /// mesh's bounding box centre from +z (the caller passes the bounds once
    /// the mesh is loaded); `Point`: the default light, exposure 0; `Sky`: the
    /// default sky, no point light.
    pub fn default_lit(
        mesh: PathBuf,
        pack: Option<PathBuf>,
        bounds: ([f64; 3], [f64; 3]),
        lighting: DefaultLighting,
    ) -> Self {
        let (lo, hi) = bounds;
        let c = [
            (lo[0] + hi[0]) / 2.0,
            (lo[1] + hi[1]) / 2.0,
            (lo[2] + hi[2]) / 2.0,
        ];
        let r = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2))
            .sqrt()
            / 2.0;
        let r = if r > 0.0 && r.is_finite() { r } else { 1.0 };
        let fov = default_fov();
        let dist = r / (fov.to_radians() / 2.0).sin() * 1.05;
        let mut scene = Scene {
            camera: Camera {
                eye: [c[0], c[1], c[2] + dist],
                target: c,
                up: default_up(),
                fov_y_deg: fov,
                shift: [0.0; 2],
            },
            lights: default_lights(),
            meshes: vec![MeshInstance {
                mesh,
                pack,
                base_color: default_base(),
                diffuse_weight: default_diffuse_weight(),
                masking: MaskingMode::Off,
                rms_slope: None,
                ior: default_ior(),
                reflectance: ReflectanceMode::Absolute,
            }],
            exposure: 0.0,
            background: Background::default(),
            size: default_size(),
            environment: None,
        };
        if lighting == DefaultLighting::Sky {
            scene.lights.clear();
            scene.environment = Some(Scene::default_sky());
            scene.exposure = Scene::DEFAULT_SKY_EXPOSURE;
            // The sky is drawn behind the mesh: what is lighting it is in view.
            scene.background = Background::Environment;
            // The sky reaches every grazing view: without masking a limb pixel
            // does not settle (docs/LIGHTING.md "Grazing views: masking").
            if scene.meshes[0].pack.is_some() {
                scene.meshes[0].masking = MaskingMode::Smith;
            }
        }
        scene
    }

    /// Read a scene file; relative paths are resolved against its folder.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::input_file(path, e))?;
        let mut s: Scene = serde_json::from_str(&text)
            .map_err(|e| Error::input_file(path, format!("invalid scene: {e}")))?;
        // Under an environment, omitted `lights` means none (the sky has its own
        // sun); otherwise the documented default light.
        if s.environment.is_some() {
            let raw: serde_json::Value = serde_json::from_str(&text)
                .map_err(|e| Error::input_file(path, format!("invalid scene: {e}")))?;
            if raw.get("lights").is_none() {
                s.lights.clear();
            }
        }
        let base = path.parent().unwrap_or(Path::new(""));
        if let Some(map) = s.environment.as_mut().and_then(|e| e.map.as_mut()) {
            if map.is_relative() {
                *map = base.join(&*map);
            }
        }
        for m in &mut s.meshes {
            if m.mesh.is_relative() && !geometry::is_builtin(&m.mesh) {
                m.mesh = base.join(&m.mesh);
            }
            if let Some(p) = &mut m.pack {
                if p.is_relative() {
                    *p = base.join(&*p);
                }
            }
        }
        s.validate().map_err(|e| e.context(path.display()))?;
        Ok(s)
    }

    /// Check values a JSON schema cannot: non-zero directions, sane field of view.
    pub fn validate(&mut self) -> Result<()> {
        if self.meshes.is_empty() {
            return Err(Error::input("scene has no meshes"));
        }
        if !(self.camera.fov_y_deg > 0.1 && self.camera.fov_y_deg < 179.0) {
            return Err(Error::input("camera.fov_y_deg must be in (0.1, 179)"));
        }
        if !self
            .camera
            .shift
            .iter()
            .all(|v| v.is_finite() && v.abs() <= 10.0)
        {
            return Err(Error::input(format!(
                "camera.shift {:?} must be finite, each in [-10, 10]",
                self.camera.shift
            )));
        }
        for (i, l) in self.lights.iter_mut().enumerate() {
            let n = (l.direction.iter().map(|v| v * v).sum::<f64>()).sqrt();
            if !(n.is_finite() && n > 0.0) {
                return Err(Error::input(format!(
                    "lights[{i}].direction must be a non-zero vector"
                )));
            }
            l.direction = l.direction.map(|v| v / n);
            if l.spectrum != "D65" {
                return Err(Error::input(format!(
                    "lights[{i}].spectrum '{}': only D65 is supported",
                    l.spectrum
                )));
            }
            if !(l.intensity.is_finite() && l.intensity >= 0.0) {
                return Err(Error::input(format!(
                    "lights[{i}].intensity {} must be finite and >= 0",
                    l.intensity
                )));
            }
            if !l.color.iter().all(|v| v.is_finite() && *v >= 0.0) {
                return Err(Error::input(format!(
                    "lights[{i}].color {:?} must be finite and >= 0 (linear sRGB [r, g, b])",
                    l.color
                )));
            }
        }
        if self.size[0] == 0 || self.size[1] == 0 || self.size[0] > 16384 || self.size[1] > 16384 {
            return Err(Error::input("size must be 1..16384 pixels per side"));
        }
        for (i, m) in self.meshes.iter().enumerate() {
            if let Some(s) = m.rms_slope {
                if !s.axes().iter().all(|v| v.is_finite() && *v >= 0.0) {
                    return Err(Error::input(format!(
                        "meshes[{i}].rms_slope must be finite and >= 0"
                    )));
                }
            }
        }
        if let Some(env) = &self.environment {
            env.validate()?;
        }
        if self.background == Background::Environment && self.environment.is_none() {
            return Err(Error::input(
                "background \"environment\" needs an \"environment\" (sky or map) in the scene",
            ));
        }
        if let Some(c) = self.background.colour() {
            if !c.iter().all(|v| v.is_finite()) {
                return Err(Error::input("background must be finite"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn parses_minimal_and_refuses_unknown() {
        let mut s: Scene = serde_json::from_str(
            r#"{"camera":{"eye":[0,0,3],"target":[0,0,0]},"meshes":[{"mesh":"a.glb","pack":"p.ktx2"}]}"#,
        )
        .unwrap();
        s.validate().unwrap();
        assert_eq!(s.lights.len(), 1);
        assert!((s.lights[0].direction.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-12);
        assert!(serde_json::from_str::<Scene>(
            r#"{"camera":{"eye":[0,0,3],"target":[0,0,0]},"meshes":[],"bogus":1}"#
        )
        .is_err());
    }

    /// The default scene is sky-lit (issue #13); `point` keeps the old one.
    /// The sun must be above the horizon and in front of the camera (+z), or
    /// the default frame is dark.
    #[test]
    fn default_scene_is_sky_lit_and_point_is_available() {
        let b = ([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]);
        let mut s = Scene::default_for("m.glb".into(), Some("p.ktx2".into()), b);
        s.validate().unwrap();
        assert!(s.lights.is_empty());
        let sky = s.environment.as_ref().and_then(|e| e.sky.as_ref()).unwrap();
        assert!(sky.sun_elevation_deg > 10.0 && sky.sun_elevation_deg < 80.0);
        let az = sky.sun_azimuth_deg.to_radians();
        assert!(az.sin() > 0.5, "sun behind the camera on +z: {az}");
        assert!(s.exposure < 0.0);
        let mut p = Scene::default_lit("m.glb".into(), None, b, DefaultLighting::Point);
        p.validate().unwrap();
        assert!(p.environment.is_none());
        assert_eq!(p.lights.len(), 1);
        assert_eq!(p.exposure, 0.0);
        assert_eq!(p.camera.eye, s.camera.eye);
        assert_eq!("sky".parse::<DefaultLighting>(), Ok(DefaultLighting::Sky));
        assert!("bogus".parse::<DefaultLighting>().is_err());
    }

    fn env_scene(env: &str) -> Result<Scene> {
        let text = format!(
            r#"{{"camera":{{"eye":[0,0,3],"target":[0,0,0]}},"meshes":[{{"mesh":"a.glb"}}],"environment":{env}}}"#
        );
        let mut s: Scene = serde_json::from_str(&text).map_err(|e| Error::input(e.to_string()))?;
        s.validate()?;
        Ok(s)
    }

    #[test]
    fn environment_sky_and_map() {
        let s = env_scene(
            r#"{"sky":{"sun_elevation_deg":30,"sun_azimuth_deg":120,"turbidity":2.5},"intensity":2}"#,
        )
        .unwrap();
        let e = s.environment.unwrap();
        assert_eq!(e.intensity, 2.0);
        assert_eq!(e.sky.unwrap().turbidity, 2.5);
        let s = env_scene(r#"{"map":"sky.EXR","rotation_deg":45}"#).unwrap();
        assert_eq!(s.environment.unwrap().rotation_deg, 45.0);
        for (bad, field) in [
            (r#"{"map":"a.hdr","intensity":-1}"#, "intensity"),
            (
                r#"{"sky":{"sun_elevation_deg":10},"intensity":-0.5}"#,
                "intensity",
            ),
            (r#"{"sky":{"sun_elevation_deg":100}}"#, "sun_elevation_deg"),
            (
                r#"{"sky":{"sun_elevation_deg":10,"turbidity":0.5}}"#,
                "turbidity",
            ),
            (r#"{"map":"a.png"}"#, "environment.map"),
            (r#"{"intensity":1}"#, "exactly one"),
            (
                r#"{"map":"a.hdr","sky":{"sun_elevation_deg":10}}"#,
                "exactly one",
            ),
            (r#"{"map":"a.hdr","bogus":1}"#, "bogus"),
        ] {
            let msg = env_scene(bad).unwrap_err().to_string();
            assert!(msg.contains(field), "{bad}: {msg}");
        }
        // JSON has no NaN: a NaN intensity can only come from code; refused too.
        // (masking: see masking_modes_and_slopes)
        let mut s = env_scene(r#"{"map":"a.hdr"}"#).unwrap();
        s.environment.as_mut().unwrap().intensity = f64::NAN;
        assert!(s.validate().is_err());
    }

    #[test]
    fn background_colour_or_environment() {
        let parse = |bg: &str, env: &str| -> Result<Scene> {
            let text = format!(
                r#"{{"camera":{{"eye":[0,0,3],"target":[0,0,0]}},"meshes":[{{"mesh":"a.glb"}}]{bg}{env}}}"#
            );
            let mut s: Scene =
                serde_json::from_str(&text).map_err(|e| Error::input(e.to_string()))?;
            s.validate()?;
            Ok(s)
        };
        let env = r#","environment":{"map":"a.hdr"}"#;
        assert_eq!(
            parse("", "").unwrap().background,
            Background::Colour([0.0; 3])
        );
        assert_eq!(
            parse(r#","background":[0.1,0.2,0.3]"#, "")
                .unwrap()
                .background,
            Background::Colour([0.1, 0.2, 0.3])
        );
        let s = parse(r#","background":"environment""#, env).unwrap();
        assert_eq!(s.background, Background::Environment);
        // round trip
        let again: Scene = serde_json::from_str(&serde_json::to_string(&s).unwrap()).unwrap();
        assert_eq!(again.background, Background::Environment);
        let msg = parse(r#","background":"environment""#, "")
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("background") && msg.contains("environment"),
            "{msg}"
        );
        for bad in [r#""sky""#, "[1,2]", r#"[1,2,"x"]"#, "1", "{}"] {
            let msg = parse(&format!(r#","background":{bad}"#), env)
                .unwrap_err()
                .to_string();
            assert!(msg.contains("background"), "{bad}: {msg}");
        }
    }

    #[test]
    fn masking_modes_and_slopes() {
        let scene = |mesh: &str| -> Result<Scene> {
            let text =
                format!(r#"{{"camera":{{"eye":[0,0,3],"target":[0,0,0]}},"meshes":[{mesh}]}}"#);
            let mut s: Scene =
                serde_json::from_str(&text).map_err(|e| Error::input(e.to_string()))?;
            s.validate()?;
            Ok(s)
        };
        let m = &scene(r#"{"mesh":"a.glb"}"#).unwrap().meshes[0];
        assert_eq!(m.masking, MaskingMode::Off);
        assert_eq!(m.masking_slope(0, Some([0.3, 0.2])).unwrap(), None);
        let m = &scene(r#"{"mesh":"a.glb","masking":"smith"}"#)
            .unwrap()
            .meshes[0];
        assert_eq!(
            m.masking_slope(0, Some([0.3, 0.2])).unwrap(),
            Some([0.3, 0.2])
        );
        let msg = m.masking_slope(0, None).unwrap_err().to_string();
        assert!(msg.contains("meshes[0].rms_slope"), "{msg}");
        let m = &scene(r#"{"mesh":"a.glb","masking":"smith","rms_slope":0.25}"#)
            .unwrap()
            .meshes[0];
        assert_eq!(
            m.masking_slope(0, Some([0.3, 0.2])).unwrap(),
            Some([0.25, 0.25])
        );
        let m = &scene(r#"{"mesh":"a.glb","masking":"smith","rms_slope":[0.4,0.1]}"#)
            .unwrap()
            .meshes[0];
        assert_eq!(m.masking_slope(0, None).unwrap(), Some([0.4, 0.1]));
        assert!(scene(r#"{"mesh":"a.glb","masking":"beckmann"}"#).is_err());
        let msg = scene(r#"{"mesh":"a.glb","rms_slope":-1}"#)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("meshes[0].rms_slope"), "{msg}");
        // the sky-lit default scene masks (a pack is given), the point-lit one does not
        let b = ([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]);
        let s = Scene::default_lit(
            "m.glb".into(),
            Some("p.ktx2".into()),
            b,
            DefaultLighting::Sky,
        );
        assert_eq!(s.meshes[0].masking, MaskingMode::Smith);
        let p = Scene::default_lit(
            "m.glb".into(),
            Some("p.ktx2".into()),
            b,
            DefaultLighting::Point,
        );
        assert_eq!(p.meshes[0].masking, MaskingMode::Off);
    }

    #[test]
    fn light_color_and_camera_shift() {
        let scene = |light: &str, cam: &str| -> Result<Scene> {
            let text = format!(
                r#"{{"camera":{{"eye":[0,0,3],"target":[0,0,0]{cam}}},"meshes":[{{"mesh":"a.glb"}}],"lights":[{light}]}}"#
            );
            let mut s: Scene =
                serde_json::from_str(&text).map_err(|e| Error::input(e.to_string()))?;
            s.validate()?;
            Ok(s)
        };
        let s = scene(r#"{"direction":[0,0,1]}"#, "").unwrap();
        assert_eq!(s.lights[0].color, [1.0; 3]);
        assert_eq!(s.camera.shift, [0.0; 2]);
        // defaults are not written back
        let text = serde_json::to_string(&s).unwrap();
        assert!(
            !text.contains("\"color\"") && !text.contains("shift"),
            "{text}"
        );
        let s = scene(
            r#"{"direction":[0,0,1],"color":[1,0.2,0]}"#,
            r#","shift":[0.1,-0.2]"#,
        )
        .unwrap();
        assert_eq!(s.lights[0].color, [1.0, 0.2, 0.0]);
        assert_eq!(s.camera.shift, [0.1, -0.2]);
        let again: Scene = serde_json::from_str(&serde_json::to_string(&s).unwrap()).unwrap();
        assert_eq!(again, s);
        for (light, cam, field) in [
            (
                r#"{"direction":[0,0,1],"color":[1,-0.1,0]}"#,
                "",
                "lights[0].color",
            ),
            (r#"{"direction":[0,0,1],"color":[1,1]}"#, "", "color"),
            (
                r#"{"direction":[0,0,1],"intensity":-1}"#,
                "",
                "lights[0].intensity",
            ),
            (r#"{"direction":[0,0,1]}"#, r#","shift":[0.1]"#, "shift"),
            (
                r#"{"direction":[0,0,1]}"#,
                r#","shift":[1e3,0]"#,
                "camera.shift",
            ),
        ] {
            let msg = scene(light, cam).unwrap_err().to_string();
            assert!(msg.contains(field), "{light} {cam}: {msg}");
        }
        let mut s = scene(r#"{"direction":[0,0,1]}"#, "").unwrap();
        s.lights[0].color[2] = f64::NAN;
        assert!(s
            .validate()
            .unwrap_err()
            .to_string()
            .contains("lights[0].color"));
        s.lights[0].color[2] = 1.0;
        s.camera.shift[1] = f64::INFINITY;
        assert!(s
            .validate()
            .unwrap_err()
            .to_string()
            .contains("camera.shift"));
    }
}
