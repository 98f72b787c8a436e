// Sunbeam's diffraction material in three.js (WebGL2), used by index.html (the
// interactive page) and render.mjs (headless frames of a scene file).
//
// The shading code is not a port: it is the GLSL ES 3.00 that
// `sunbeam-play --export-shader glsl-es` writes from the player's own WGSL
// (shaders/material.wgsl: the frame, exact Fresnel, G, Smith masking, the
// diffuse base's share; shaders/response_map.wgsl: the map; and the
// environment: shaders/env_cells.wgsl, the player's first-frame cells, with
// shaders/export_env.wgsl; the scale maps: shaders/scales.wgsl, the player's
// frame function, with shaders/export_scales.wgsl), adapted here only in its declarations (plain
// struct uniforms instead of uniform blocks, our varyings and light loop
// instead of its demo entry point). docs/ENGINES.md documents the interface.
// An environment comes as the files of `sunbeam-play SCENE
// --export-environment DIR` (parseEnvironment).
//
// The response map (NAME.response.ktx2, docs/PACK_FORMAT.md "Response map") is
// read with ktx-parse (shipped with three) into a Data3DTexture: RGBA half
// floats, linear filtering, repeat along the angle, clamp along radius and s.
import * as THREE from 'three';
import { read as readKTX2 } from 'three/addons/libs/ktx-parse.module.js';

/** Parse a response map: { texture, grid: {n_theta, n_rho, n_s, r0}, info }. */
export function parseResponseMap(arrayBuffer) {
  const ktx = readKTX2(new Uint8Array(arrayBuffer));
  if (ktx.vkFormat !== 97) throw new Error(`response map: vkFormat ${ktx.vkFormat}, expected 97 (R16G16B16A16_SFLOAT)`);
  const raw = ktx.keyValue['sunbeam.response'];
  if (!raw) throw new Error('response map: no sunbeam.response key');
  const info = JSON.parse(typeof raw === 'string' ? raw : new TextDecoder().decode(raw).replace(/\0+$/, ''));
  const g = info.grid;
  const level = ktx.levels[0].levelData;
  const data = new Uint16Array(level.buffer.slice(level.byteOffset, level.byteOffset + level.byteLength));
  if (data.length !== g.n_theta * g.n_rho * g.n_s * 4) throw new Error('response map: level 0 size does not match the grid');
  const tex = new THREE.Data3DTexture(data, g.n_theta, g.n_rho, g.n_s);
  tex.format = THREE.RGBAFormat;
  tex.type = THREE.HalfFloatType;
  tex.minFilter = THREE.LinearFilter;
  tex.magFilter = THREE.LinearFilter;
  tex.wrapS = THREE.RepeatWrapping;
  tex.wrapT = THREE.ClampToEdgeWrapping;
  tex.wrapR = THREE.ClampToEdgeWrapping;
  tex.generateMipmaps = false;
  tex.unpackAlignment = 1;
  tex.colorSpace = THREE.NoColorSpace;
  tex.needsUpdate = true;
  return { texture: tex, grid: g, info };
}

// ---- the environment (sunbeam-play --export-environment DIR, docs/ENGINES.md "Environment")

function ktxLevels(arrayBuffer, what, vkFormat) {
  const ktx = readKTX2(new Uint8Array(arrayBuffer));
  if (ktx.vkFormat !== vkFormat) throw new Error(`${what}: vkFormat ${ktx.vkFormat}, expected ${vkFormat}`);
  return ktx.levels.map((l, m) => ({
    width: Math.max(1, ktx.pixelWidth >> m),
    height: Math.max(1, ktx.pixelHeight >> m),
    bytes: l.levelData.buffer.slice(l.levelData.byteOffset, l.levelData.byteOffset + l.levelData.byteLength),
  }));
}

// An equirectangular RGBA16F texture (repeat in azimuth, clamp in the polar
// angle, linear; with its levels when given, linear between them).
function equirectTexture(levels) {
  const tex = new THREE.DataTexture(new Uint16Array(levels[0].bytes), levels[0].width, levels[0].height, THREE.RGBAFormat, THREE.HalfFloatType);
  if (levels.length > 1) {
    tex.mipmaps = levels.map((l) => ({ data: new Uint16Array(l.bytes), width: l.width, height: l.height }));
    tex.minFilter = THREE.LinearMipmapLinearFilter;
  } else {
    tex.minFilter = THREE.LinearFilter;
  }
  tex.magFilter = THREE.LinearFilter;
  tex.wrapS = THREE.RepeatWrapping;
  tex.wrapT = THREE.ClampToEdgeWrapping;
  tex.generateMipmaps = false;
  tex.unpackAlignment = 1;
  tex.colorSpace = THREE.NoColorSpace;
  tex.needsUpdate = true;
  return tex;
}

/**
 * The environment for sunbeamMaterial from the files of `sunbeam-play
 * SCENE.json --export-environment DIR`: `json` (environment.json, parsed),
 * `chain` (chain.ktx2), `irradianceSkin` (irradiance-skin.ktx2),
 * `irradiance` (irradiance.ktx2), `cells`, `suns` and `basis` (objects: file
 * name -> ArrayBuffer, of every meshes[].file, meshes[].sun and
 * meshes[].basis[k]), and `table` (table.ktx2, when environment.json names
 * one: the whole map, the chain being the rest of it after the hot spots).
 * Returns { json, chain, table (the whole map for a background: table.ktx2,
 * else the chain), irrSkin, irrPlain, cells: {file -> texture}, basisToRgb,
 * sun, hotSpots: the taps' texture (null without hot spots) }; `forMesh(i)`
 * the cells (and sun map, basis maps) of scene mesh i.
 */
export function parseEnvironment({ json, chain, irradianceSkin, irradiance, cells, suns = {}, basis = {}, table = null }) {
  if (json.format !== 'sunbeam-environment' || json.version !== 1) throw new Error('environment.json: not a sunbeam-environment version 1');
  const levels = ktxLevels(chain, 'chain.ktx2', 97);
  if (levels.length !== json.chain.levels) throw new Error(`chain.ktx2: ${levels.length} levels, environment.json says ${json.chain.levels}`);
  // WebGL samples a mipmapped texture only with every level down to 1 x 1:
  // the chain stops at 2 x 1 (or 3 x 1), so add its mean (equal columns: the
  // same solid angle). The shader never reads past chain.levels - 1.
  const last = levels[levels.length - 1];
  if (last.width > 1 || last.height > 1) {
    const h = new Uint16Array(last.bytes);
    const n = h.length / 4;
    const mean = new Uint16Array(4);
    for (let c = 0; c < 4; c++) {
      let acc = 0;
      for (let i = 0; i < n; i++) acc += THREE.DataUtils.fromHalfFloat(h[4 * i + c]);
      mean[c] = THREE.DataUtils.toHalfFloat(acc / n);
    }
    levels.push({ width: 1, height: 1, bytes: mean.buffer });
  }
  const out = {
    json,
    chain: equirectTexture(levels),
    irrSkin: equirectTexture(ktxLevels(irradianceSkin, 'irradiance-skin.ktx2', 97).slice(0, 1)),
    irrPlain: equirectTexture(ktxLevels(irradiance, 'irradiance.ktx2', 97).slice(0, 1)),
    cells: {},
    basisToRgb: json.basis_to_rgb,
    sun: json.sun,
    hotSpots: null,
  };
  if (json.table && !table) throw new Error(`environment: ${json.table} not given`);
  out.table = table ? equirectTexture(ktxLevels(table, 'table.ktx2', 97).slice(0, 1)) : out.chain;
  // The hot spots' taps (shaders/export_env.wgsl binding 12): one row of
  // RGBA32F, (2 i, 0) the direction, (2 i + 1, 0) the basis power.
  const taps = json.hot_spots ?? [];
  if (taps.length > 0) {
    const data = new Float32Array(8 * taps.length);
    taps.forEach((t, i) => {
      if (t.length !== 6) throw new Error(`environment.json: hot_spots[${i}] has ${t.length} numbers, not 6`);
      data.set([t[0], t[1], t[2], 0, t[3], t[4], t[5], 0], 8 * i);
    });
    const tex = new THREE.DataTexture(data, 2 * taps.length, 1, THREE.RGBAFormat, THREE.FloatType);
    tex.minFilter = THREE.NearestFilter;
    tex.magFilter = THREE.NearestFilter;
    tex.generateMipmaps = false;
    tex.needsUpdate = true;
    out.hotSpots = tex;
  }
  for (const [file, buf] of Object.entries(cells)) {
    const [l] = ktxLevels(buf, file, 107);
    const tex = new THREE.DataTexture(new Uint32Array(l.bytes), l.width, l.height, THREE.RGBAIntegerFormat, THREE.UnsignedIntType);
    tex.internalFormat = 'RGBA32UI';
    tex.minFilter = THREE.NearestFilter;
    tex.magFilter = THREE.NearestFilter;
    tex.generateMipmaps = false;
    tex.unpackAlignment = 1;
    tex.needsUpdate = true;
    out.cells[file] = tex;
  }
  const maps = {};
  for (const [file, buf] of [...Object.entries(suns), ...Object.entries(basis)]) maps[file] = parseResponseMap(buf);
  out.forMesh = (i) => {
    const m = json.meshes.find((e) => e.mesh === i);
    if (!m) return null;
    const sun = m.sun ? maps[m.sun] : null;
    if (m.sun && !sun) throw new Error(`environment: ${m.sun} not given`);
    const basisMaps = (m.basis ?? []).map((f) => {
      if (!maps[f]) throw new Error(`environment: ${f} not given`);
      return maps[f];
    });
    return {
      texture: out.cells[m.file], nTop: m.n_top, nS: m.n_s, nodes: m.nodes, sun, sunGrid: m.sun_grid,
      basis: basisMaps.length === 3 ? basisMaps : null, basisGrid: m.basis_grid,
    };
  };
  return out;
}

/** The exported GLSL ES with its declarations adapted for a three.js RawShaderMaterial. */
export function adaptExportedGlsl(src) {
  const lines = src.split('\n');
  const out = [];
  for (const l of lines) {
    if (l.startsWith('#version')) continue;
    if (l.startsWith('void main()')) break; // the demo entry point: ours follows
    if (/^(smooth|flat) in \w+ _vs2fs_location\d+;/.test(l)) continue;
    if (l.startsWith('layout(location = 0) out vec4')) continue;
    // naga's uniform blocks (the material's, the environment's) as plain struct uniforms
    const block = /^layout\(std140\) uniform (\w+)_block_\d+Fragment \{ (\w+) (\w+); \};/.exec(l);
    if (block) {
      out.push(`uniform ${block[2]} ${block[3]};`);
      continue;
    }
    out.push(l);
  }
  const text = out.join('\n');
  for (const need of ['vec3 sunbeam_shade(', 'vec3 sunbeam_shade_sun_footprint(', 'vec3 sunbeam_shade_sun_sample_point(', 'vec3 sunbeam_shade_sun_base(', 'vec2 sunbeam_sun_sample_offset(', 'const uint SB_SUN_SAMPLE_POINTS', 'vec3 sunbeam_shade_environment_footprint(', 'struct EnvFootprint', 'mat3x3 sb_frame(',
    'uniform SunbeamMaterial _group_0_binding_0_fs;', 'uniform SunbeamEnvironment _group_0_binding_8_fs;', '_group_0_binding_1_fs', '_group_0_binding_7_fs', '_group_0_binding_9_fs',
    'mat3x3 sunbeam_scale_frame(', 'float sunbeam_scale_id(', '_group_0_binding_10_fs', '_group_0_binding_11_fs']) {
    if (!text.includes(need)) throw new Error(`exported GLSL: ${need} not found (docs/ENGINES.md; export it with this sunbeam-play)`);
  }
  return text;
}

/** Fresnel reflectance at normal incidence, ((n - 1)/(n + 1))^2 (sunbeam_optics::gain::f0). */
export function fresnelF0(ior) {
  const r = (ior - 1) / (ior + 1);
  return r * r;
}

/**
 * The exported material's `skin` uniform (docs/ENGINES.md): [ior, norm, sx, sy]
 * with `norm` what G is divided by (1 for 'absolute' reflectance, the
 * default; F(0) for 'relative', sunbeam_optics::gain::Material::norm) and
 * (sx, sy) Smith masking's rms slopes ([0, 0]: no masking).
 */
export function skinUniform({ ior = 1.5, reflectance = 'absolute', rmsSlope = [0, 0] } = {}) {
  if (!(ior > 1 && ior <= 4)) throw new Error(`ior ${ior}: expected a refractive index in (1, 4]`);
  if (reflectance !== 'absolute' && reflectance !== 'relative') throw new Error(`reflectance '${reflectance}': expected 'absolute' or 'relative'`);
  const s = typeof rmsSlope === 'number' ? [rmsSlope, rmsSlope] : rmsSlope;
  if (!Array.isArray(s) || s.length !== 2 || !s.every((v) => Number.isFinite(v) && v >= 0)) throw new Error('rmsSlope: expected a number or [x, y], finite and >= 0');
  return new THREE.Vector4(ior, reflectance === 'relative' ? fresnelF0(ior) : 1, s[0], s[1]);
}

/**
 * The exported material's `energy` uniform (docs/ENGINES.md, docs/LIGHTING.md
 * "Energy bound"): the energy bound's table from the response map's info
 * (`energy.off`, or `energy.smith` when masking with the pack's table
 * present), 16 values in column-major order; zero (no bound) for relative
 * reflectance or a map without tables. The same choice as
 * sunbeam_response::energy::EnergyInfo::bound.
 */
export function energyUniform(map, { reflectance = 'absolute', rmsSlope = [0, 0] } = {}) {
  const m = new THREE.Matrix4().set(0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0);
  const e = map?.info?.energy;
  if (!e || reflectance !== 'absolute') return m;
  const s = typeof rmsSlope === 'number' ? [rmsSlope, rmsSlope] : rmsSlope;
  const masked = s[0] > 0 || s[1] > 0;
  const b = masked && e.smith ? e.smith : e.off;
  if (b.length !== 16) throw new Error(`response map: energy table of ${b.length} values, expected 16`);
  m.fromArray(b);
  return m;
}

/**
 * The rms slopes a mesh masks with (sunbeam_scene::MeshInstance::masking_slope):
 * none ([0, 0]) unless `masking` is 'smith'; then `rmsSlope` (a number or
 * [x, y]) if given, else the pack's (`rms_slope` of its manifest, which the
 * response map carries in `info.pack`). `what` names the field in errors.
 */
export function maskingSlope(masking, rmsSlope, map, what) {
  const m = masking ?? 'off';
  if (m === 'off') return [0, 0];
  if (m !== 'smith') throw new Error(`${what}.masking '${m}': expected 'off' or 'smith'`);
  if (rmsSlope !== undefined && rmsSlope !== null) return typeof rmsSlope === 'number' ? [rmsSlope, rmsSlope] : rmsSlope;
  const own = map?.info?.pack?.rms_slope;
  if (!own) throw new Error(`${what}.masking 'smith' needs rms slopes: the pack has no rms_slope and none is given`);
  return own;
}

const MAX_LIGHTS = 4;

const VERTEX = /* glsl */ `
precision highp float;
uniform mat4 modelMatrix;
uniform mat4 viewMatrix;
uniform mat4 projectionMatrix;
uniform mat3 sbNormalMatrix; // world-space normal matrix
in vec3 position;
in vec3 normal;
in vec3 sbOrient;
in vec4 sbTangent; // a mesh with scale maps (addScaleAttributes): the glTF TANGENT
in vec2 sbUv;      // and the maps' TEXCOORD; (0, 0, 0, 1) and (0, 0) otherwise
// centroid: under MSAA (a canvas with antialias: true) a partly covered
// pixel is shaded once, and at its centre the attributes would be
// extrapolated past the triangle; at the covered samples' centroid they are
// not (the baked snake under the sky at 4x MSAA: CIEDE2000 p99 inside 9.8
// without, 2.2 with; docs/ENGINES.md). Without MSAA it is the centre. The
// material takes no derivatives of them, which centroid would make coarse.
centroid out vec3 vWorld;
centroid out vec3 vNormal;
centroid out vec3 vOrient;
centroid out vec4 vTangent;
centroid out vec2 vUv;
void main() {
  vec4 w = modelMatrix * vec4(position, 1.0);
  vWorld = w.xyz;
  vNormal = sbNormalMatrix * normal;
  vOrient = mat3(modelMatrix) * sbOrient;
  vTangent = vec4(mat3(modelMatrix) * sbTangent.xyz, sbTangent.w);
  vUv = sbUv;
  gl_Position = projectionMatrix * viewMatrix * w;
}`;

function fragment(exported) {
  return `${exported}
uniform vec3 sbEye;
uniform int sbLightCount;
uniform vec4 sbLights[${MAX_LIGHTS}]; // xyz towards the light (unit), w intensity
uniform vec3 sbLightColors[${MAX_LIGHTS}]; // linear sRGB colour (scene lights[].color): tints the light's RGB
uniform float sbExposure;              // 2^exposure
uniform int sbHasMap;
uniform int sbDisplay;                 // 1: clip at 1 and sRGB-encode (drawing to a canvas)
uniform int sbEnvOn;                   // 1: lit by an environment (parseEnvironment)
uniform uint sbScales;                 // 0: no scale maps; else 16 + the wrap bits (shaders/export_scales.wgsl)
centroid in vec3 vWorld;
centroid in vec3 vNormal;
centroid in vec3 vOrient;
centroid in vec4 vTangent;
centroid in vec2 vUv;
layout(location = 0) out vec4 fragColor;
void main() {
  // The player's frame (shaders/material.wgsl sb_frame: t orthogonalised
  // against n), or on a mesh with scale maps the frame the maps give
  // (shaders/scales.wgsl sb_scale_frame, as the player's frame_at).
  mat3 f = sunbeam_scale_frame(vNormal, vOrient, vTangent, vUv, sbScales);
  vec3 t = f[0];
  vec3 b = f[1];
  vec3 n = f[2];
  vec3 wr = normalize(sbEye - vWorld);
  // The pixel's footprint for the environment's sharp lights (the sun's
  // disc, a map's hot spots): the frame's and the local view's screen
  // derivatives, taken here in uniform control flow (env_hotspots.wgsl
  // EnvFootprint, as the player's). On a mesh with scale maps, only inside
  // one scale: across a scale's border the derivatives jump and would smear
  // the orders of two scales together, so a pixel whose 2 x 2 quad sees two
  // scale ids (sunbeam_scale_id: the orientation map's alpha at the texel
  // under the uv) reads at a point (the player shades such pixels at their
  // samples instead; docs/LIGHTING.md "The sun over the pixel").
  vec3 wrl = vec3(dot(wr, t), dot(wr, b), dot(wr, n));
  float k = fwidth(sunbeam_scale_id(vUv, sbScales)) < 0.5 ? 1.0 : 0.0;
  EnvFootprint fp = EnvFootprint(k * dFdx(t), k * dFdy(t), k * dFdx(b), k * dFdy(b), k * dFdx(n), k * dFdy(n), k * dFdx(wrl), k * dFdy(wrl));
  // The attributes' screen derivatives (here, in uniform control flow): on a
  // mesh with scale maps each point of the sun's disc is read with the frame
  // and the view at its own place in the pixel (sunbeam_sun_sample_offset, 64 points),
  // the attributes carried there along them, and the scale maps read there:
  // within a pixel the scales' domes turn the sun's orders and their borders
  // jump them, which no footprint's linear model carries (the player's
  // env_sun_disc_carried; docs/ENGINES.md "Scale maps under an environment").
  vec3 dWx = dFdx(vWorld), dWy = dFdy(vWorld);
  vec3 dNx = dFdx(vNormal), dNy = dFdy(vNormal);
  vec3 dOx = dFdx(vOrient), dOy = dFdy(vOrient);
  vec4 dTx = dFdx(vTangent), dTy = dFdy(vTangent);
  vec2 dUx = dFdx(vUv), dUy = dFdy(vUv);
  vec3 rgb = vec3(0.0);
  for (int i = 0; i < ${MAX_LIGHTS}; i++) {
    if (i >= sbLightCount) break;
    vec3 wi = sbLights[i].xyz;
    vec3 c;
    if (sbHasMap == 1) {
      c = sunbeam_shade(t, b, n, wi, wr);
    } else {
      c = _group_0_binding_0_fs.base.rgb * max(dot(wi, n), 0.0);
    }
    rgb += sbLights[i].w * sbLightColors[i] * c;
  }
  if (sbEnvOn == 1) {
    // The environment without its sun (the exported sunbeam_shade_environment:
    // the player's first-frame cells), then the sky's sun from its centre
    // (sunbeam_shade_sun: its own spectral map).
    const float PI = 3.141592653589793;
    vec3 base = _group_0_binding_0_fs.base.rgb;
    vec4 sun = _group_0_binding_8_fs.sun_dir;
    if (sbHasMap == 1) {
      rgb += sunbeam_shade_environment_footprint(t, b, n, wr, fp);
      if (sbScales != 0u) {
        vec3 s = vec3(0.0);
        for (uint i = 0u; i < SB_SUN_SAMPLE_POINTS; i++) {
          vec2 o = sunbeam_sun_sample_offset(i);
          mat3 fi = sunbeam_scale_frame(vNormal + o.x * dNx + o.y * dNy, vOrient + o.x * dOx + o.y * dOy,
            vTangent + o.x * dTx + o.y * dTy, vUv + o.x * dUx + o.y * dUy, sbScales);
          vec3 wri = normalize(sbEye - (vWorld + o.x * dWx + o.y * dWy));
          s += sunbeam_shade_sun_sample_point(fi[0], fi[1], fi[2], sun.xyz, wri, i);
        }
        rgb += sunbeam_shade_sun_base(t, b, n, sun.xyz) + s / float(SB_SUN_SAMPLE_POINTS);
      } else {
        rgb += sunbeam_shade_sun_footprint(t, b, n, sun.xyz, wr, fp);
      }
    } else {
      rgb += base * env_irradiance(false, n) / PI;
      if (sun.w > 0.0) rgb += base * _group_0_binding_8_fs.sun_rgb.rgb * max(dot(sun.xyz, n), 0.0) / PI;
    }
  }
  vec3 c = rgb * sbExposure;
  if (sbDisplay == 1) {
    // sunbeam_optics::colour: clip, then the sRGB curve (what sunbeam-play writes).
    c = clamp(c, 0.0, 1.0);
    c = mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
  }
  fragColor = vec4(c, 1.0);
}`;
}

/**
 * The material: `exportedGlsl` (adapted, see adaptExportedGlsl), `map` from
 * parseResponseMap or null (base colour only), `baseColor` linear [r, g, b],
 * `diffuseWeight`, the skin: `ior` (1.5), `reflectance` ('absolute', the
 * default, or 'relative'), `rmsSlope` (Smith masking's [x, y] rms slopes;
 * [0, 0]: none; see maskingSlope), `lights` [{direction: [x, y, z] towards the
 * light, intensity, color: linear [r, g, b] (default white) tinting its RGB}], `exposure` in stops, `display`: clip and sRGB-encode
 * (for a canvas; off for linear float targets), `environment`: from
 * parseEnvironment (or null), with `envCells` its cells for this mesh
 * (environment.forMesh(i)): the environment lights the mesh through the
 * exported sunbeam_shade_environment and its sun through sunbeam_shade_sun;
 * the mesh's `ior` must be the one the transmitted irradiance was made for
 * (environment.json irradiance.ior). `scales`: the mesh's scale maps
 * (`sunbeam-bake --scales`; SunbeamDiffractionPlugin puts them on
 * `mesh.userData.sunbeamScales`, and the geometry needs addScaleAttributes)
 * or null. Uniforms can be changed later (material.uniforms; the skin
 * through skinUniform).
 */
export function sunbeamMaterial({ exportedGlsl, map, baseColor = [0.05, 0.05, 0.05], diffuseWeight = 0.2, ior = 1.5, reflectance = 'absolute', rmsSlope = [0, 0], lights = [], exposure = 0, display = false, environment = null, envCells = null, scales = null }) {
  const g = map ? map.grid : { n_theta: 1, n_rho: 2, n_s: 2, r0: 1 };
  const lightVecs = [];
  const lightColors = [];
  for (let i = 0; i < MAX_LIGHTS; i++) {
    const l = lights[i];
    if (!l) { lightVecs.push(new THREE.Vector4()); lightColors.push(new THREE.Vector3()); continue; }
    const d = new THREE.Vector3(...l.direction).normalize();
    lightVecs.push(new THREE.Vector4(d.x, d.y, d.z, l.intensity ?? 1));
    lightColors.push(new THREE.Vector3(...(l.color ?? [1, 1, 1])));
  }
  const placeholder = new THREE.Data3DTexture(new Uint16Array(4 * 2 * 2), 1, 2, 2);
  placeholder.type = THREE.HalfFloatType;
  placeholder.needsUpdate = true;
  // Stand-ins of the environment's textures (each sampler needs a texture of its type).
  const flat = new THREE.DataTexture(new Uint16Array(4), 1, 1, THREE.RGBAFormat, THREE.HalfFloatType);
  flat.needsUpdate = true;
  const noCells = new THREE.DataTexture(new Uint32Array(4), 1, 1, THREE.RGBAIntegerFormat, THREE.UnsignedIntType);
  noCells.internalFormat = 'RGBA32UI';
  noCells.needsUpdate = true;
  const noScale = new THREE.DataTexture(new Uint8Array([128, 128, 255, 255]), 1, 1, THREE.RGBAFormat, THREE.UnsignedByteType);
  noScale.needsUpdate = true;
  const env = environment;
  if (env && map && Math.abs(env.json.irradiance.ior - ior) > 1e-6) {
    throw new Error(`environment: the transmitted irradiance is for index ${env.json.irradiance.ior}, the mesh's is ${ior}`);
  }
  const sun = env?.sun;
  // A map's hot spots as lights: the taps and this mesh's basis maps.
  const hot = Boolean(env?.hotSpots && envCells?.basis);
  const noTaps = new THREE.DataTexture(new Float32Array(4), 1, 1, THREE.RGBAFormat, THREE.FloatType);
  noTaps.minFilter = THREE.NearestFilter; // float textures filter only with an extension
  noTaps.magFilter = THREE.NearestFilter;
  noTaps.needsUpdate = true;
  const m = new THREE.RawShaderMaterial({
    glslVersion: THREE.GLSL3,
    vertexShader: VERTEX,
    fragmentShader: fragment(exportedGlsl),
    uniforms: {
      sbNormalMatrix: { value: new THREE.Matrix3() },
      sbEye: { value: new THREE.Vector3() },
      sbLightCount: { value: Math.min(lights.length, MAX_LIGHTS) },
      sbLights: { value: lightVecs },
      sbLightColors: { value: lightColors },
      sbExposure: { value: Math.pow(2, exposure) },
      sbHasMap: { value: map ? 1 : 0 },
      sbDisplay: { value: display ? 1 : 0 },
      sbEnvOn: { value: env ? 1 : 0 },
      sbScales: { value: scales ? 16 | scales.wraps : 0 },
      _group_0_binding_10_fs: { value: scales ? scales.normal : noScale },
      _group_0_binding_11_fs: { value: scales ? scales.orient : noScale },
      _group_0_binding_1_fs: { value: map ? map.texture : placeholder },
      _group_0_binding_3_fs: { value: env ? env.chain : flat },
      _group_0_binding_4_fs: { value: env ? env.irrSkin : flat },
      _group_0_binding_5_fs: { value: env ? env.irrPlain : flat },
      _group_0_binding_7_fs: { value: envCells ? envCells.texture : noCells },
      _group_0_binding_9_fs: { value: envCells?.sun ? envCells.sun.texture : placeholder },
      _group_0_binding_12_fs: { value: hot ? env.hotSpots : noTaps },
      _group_0_binding_13_fs: { value: hot ? envCells.basis[0].texture : placeholder },
      _group_0_binding_14_fs: { value: hot ? envCells.basis[1].texture : placeholder },
      _group_0_binding_15_fs: { value: hot ? envCells.basis[2].texture : placeholder },
      _group_0_binding_8_fs: {
        value: {
          cells: new THREE.Vector4(envCells ? envCells.nTop : 0, envCells ? envCells.nS : 2, envCells ? envCells.nodes : 0, 0),
          chain: new THREE.Vector4(env ? env.json.chain.height : 1, env ? env.json.chain.levels : 1, env ? env.json.chain.phase ?? 0 : 0, 0),
          sun_dir: sun ? new THREE.Vector4(...sun.direction, 1) : new THREE.Vector4(),
          sun_rgb: sun ? new THREE.Vector4(...sun.rgb, sun.solid_angle) : new THREE.Vector4(),
          // a mesh without its sun map: n_theta 0 (no diffraction from the sun)
          sun_grid: envCells?.sun ? new THREE.Vector4(...envCells.sunGrid) : new THREE.Vector4(0, 2, 2, 1),
          // the hot spots' taps (0: none), read through the mesh's basis maps
          hot: new THREE.Vector4(hot ? env.json.hot_spots.length : 0, 0, 0, 0),
          basis_grid: hot ? new THREE.Vector4(...envCells.basisGrid) : new THREE.Vector4(1, 2, 2, 1),
        },
      },
      _group_0_binding_0_fs: {
        value: {
          grid: new THREE.Vector4(g.n_theta, g.n_rho, g.n_s, 0),
          warp: new THREE.Vector4(g.r0, Math.asinh(2 / g.r0), map ? diffuseWeight : 1, 0),
          base: new THREE.Vector4(baseColor[0], baseColor[1], baseColor[2], 0),
          skin: skinUniform({ ior, reflectance, rmsSlope }),
          energy: energyUniform(map, { reflectance, rmsSlope }),
        },
      },
    },
    side: THREE.FrontSide,
  });
  return m;
}

/** Set the per-object uniforms of every Sunbeam material under `root` (call before rendering). */
export function updateSunbeamUniforms(root, camera) {
  const eye = new THREE.Vector3().setFromMatrixPosition(camera.matrixWorld);
  root.traverse((o) => {
    if (o.isMesh && o.material && o.material.uniforms && o.material.uniforms.sbNormalMatrix) {
      o.onBeforeRender = (r, s, cam, geom, mat) => {
        // another material drawn in its place (scene.overrideMaterial) has none of these
        if (!mat.uniforms?.sbNormalMatrix) return;
        mat.uniforms.sbNormalMatrix.value.getNormalMatrix(o.matrixWorld);
        mat.uniforms.sbEye.value.copy(eye);
        mat.uniformsNeedUpdate = true;
      };
    }
  });
}

/** The orientation attribute a Sunbeam mesh needs (`sbOrient`): `_orientation` (sunbeam-bake), else TANGENT.xyz. */
export function addOrientation(geometry) {
  const o = geometry.getAttribute('_orientation') || geometry.getAttribute('tangent');
  if (!o) throw new Error('mesh has neither _ORIENTATION nor TANGENT (bake it with sunbeam-bake)');
  const n = geometry.getAttribute('position').count;
  const a = new Float32Array(n * 3);
  for (let i = 0; i < n; i++) {
    a[3 * i] = o.getX(i); a[3 * i + 1] = o.getY(i); a[3 * i + 2] = o.getZ(i);
  }
  geometry.setAttribute('sbOrient', new THREE.BufferAttribute(a, 3));
  return geometry;
}

/**
 * The attributes the scale maps need (`sbTangent`, `sbUv`): the glTF TANGENT
 * (three's `tangent`) and TEXCOORD_`texCoord` (three's `uv`, `uv1`, ...).
 */
export function addScaleAttributes(geometry, texCoord = 0) {
  const t = geometry.getAttribute('tangent');
  const uvName = texCoord === 0 ? 'uv' : `uv${texCoord}`;
  const uv = geometry.getAttribute(uvName);
  if (!t || !uv) throw new Error(`a mesh with scale maps needs TANGENT and TEXCOORD_${texCoord} (bake it with sunbeam-bake --scales)`);
  geometry.setAttribute('sbTangent', t);
  geometry.setAttribute('sbUv', uv);
  return geometry;
}

// A scale map as the exported shader reads it (textureLoad: texel for texel):
// the bytes as stored (GLTFLoader's image bitmaps: no premultiplied alpha, no
// colour-space conversion; flipY false), no mipmaps.
function scaleTexture(tex) {
  tex.colorSpace = THREE.NoColorSpace;
  tex.flipY = false;
  tex.premultiplyAlpha = false;
  tex.minFilter = THREE.NearestFilter;
  tex.magFilter = THREE.NearestFilter;
  tex.generateMipmaps = false;
  tex.needsUpdate = true;
  return tex;
}

/**
 * GLTFLoader plugin for the vendor extension SUNBEAM_materials_diffraction
 * (written by `sunbeam-bake --pack`, docs/ENGINES.md): every mesh whose glTF
 * material carries it gets `userData.sunbeam` = the extension's object
 * (`responseMap.uri` relative to the GLB, `grid`, `diffuseWeight`,
 * `baseColor`, and the skin where given: `ior`, `reflectance`, `masking`,
 * `rmsSlope`; see extensionSkin). With `orientationTexture` (`sunbeam-bake
 * --scales`) the mesh also gets `userData.sunbeamScales` = { normal (the
 * material's normalTexture), orient, wraps (bit 0 the normal map repeats
 * along s, 1 along t, 2 and 3 the orientation map's; a glTF wrap other than
 * CLAMP_TO_EDGE repeats, as the reference reads it), texCoord }: the
 * `scales` of sunbeamMaterial. Register with
 * `loader.register((p) => new SunbeamDiffractionPlugin(p))`.
 */
export class SunbeamDiffractionPlugin {
  constructor(parser) {
    this.parser = parser;
    this.name = 'SUNBEAM_materials_diffraction';
  }

  async afterRoot(gltf) {
    const json = this.parser.json;
    const mats = json.materials ?? [];
    const found = [];
    gltf.scene.traverse((o) => {
      if (!o.isMesh) return;
      const a = this.parser.associations.get(o.material);
      const mi = a && a.materials !== undefined ? a.materials : undefined;
      const ext = mi !== undefined ? mats[mi]?.extensions?.[this.name] : undefined;
      if (ext) {
        o.userData.sunbeam = ext;
        if (ext.orientationTexture) found.push([o, mi, ext]);
      }
    });
    const repeats = (ti) => {
      const s = json.samplers?.[json.textures?.[ti]?.sampler] ?? {};
      return [s.wrapS, s.wrapT].map((w) => (w ?? 10497) !== 33071);
    };
    for (const [o, mi, ext] of found) {
      const what = `materials[${mi}]`;
      const nt = mats[mi].normalTexture;
      const ot = ext.orientationTexture;
      if (!nt) throw new Error(`${what}: orientationTexture without normalTexture`);
      const texCoord = ot.texCoord ?? 0;
      if ((nt.texCoord ?? 0) !== texCoord) throw new Error(`${what}: the normal and orientation maps use different TEXCOORDs`);
      const [ns, nt2] = repeats(nt.index);
      const [os, ot2] = repeats(ot.index);
      const normal = await this.parser.getDependency('texture', nt.index);
      const orient = await this.parser.getDependency('texture', ot.index);
      if (!normal || !orient) throw new Error(`${what}: the scale maps could not be loaded`);
      o.userData.sunbeamScales = {
        normal: scaleTexture(normal),
        orient: scaleTexture(orient),
        wraps: (ns ? 1 : 0) | (nt2 ? 2 : 0) | (os ? 4 : 0) | (ot2 ? 8 : 0),
        texCoord,
      };
    }
  }
}

/**
 * The skin options of sunbeamMaterial from an extension object (the
 * plugin's userData.sunbeam) and its parsed map: `ior` (else from an older
 * extension's `f0`, else 1.5), `reflectance` (else 'absolute'), and the rms
 * slopes when its `masking` is 'smith' (its `rmsSlope`, else the pack's).
 */
export function extensionSkin(ext, map, what = 'SUNBEAM_materials_diffraction') {
  let ior = ext.ior;
  if (ior === undefined && typeof ext.f0 === 'number' && ext.f0 > 0 && ext.f0 < 1) {
    const r = Math.sqrt(ext.f0);
    ior = (1 + r) / (1 - r);
  }
  return {
    ior: ior ?? 1.5,
    reflectance: ext.reflectance ?? 'absolute',
    rmsSlope: maskingSlope(ext.masking, ext.rmsSlope, map, what),
  };
}

/** sunbeam-scene's built-in meshes (crates/sunbeam-scene/src/geometry.rs), same vertices and tangents. */
export function builtinGeometry(name) {
  const g = new THREE.BufferGeometry();
  if (name === 'quad') {
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array([-0.5, -0.5, 0, 0.5, -0.5, 0, 0.5, 0.5, 0, -0.5, 0.5, 0]), 3));
    g.setAttribute('normal', new THREE.BufferAttribute(new Float32Array([0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1]), 3));
    g.setAttribute('tangent', new THREE.BufferAttribute(new Float32Array([1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1]), 4));
    g.setIndex([0, 1, 2, 0, 2, 3]);
    return addOrientation(g);
  }
  if (name !== 'sphere') throw new Error(`unknown built-in mesh '${name}' (known: quad, sphere)`);
  const segments = 96, rings = 48;
  const pos = [], nor = [], tan = [], idx = [];
  for (let r = 0; r <= rings; r++) {
    const th = (r / rings) * Math.PI;
    for (let s = 0; s <= segments; s++) {
      const ph = (s / segments) * 2 * Math.PI;
      const n = [Math.sin(th) * Math.cos(ph), Math.cos(th), -Math.sin(th) * Math.sin(ph)];
      pos.push(0.5 * n[0], 0.5 * n[1], 0.5 * n[2]);
      nor.push(...n);
      if (Math.sin(th) > 1e-9) tan.push(-Math.sin(ph), 0, -Math.cos(ph), 1);
      else tan.push(1, 0, 0, 1);
    }
  }
  const row = segments + 1;
  for (let r = 0; r < rings; r++) {
    for (let s = 0; s < segments; s++) {
      const a = r * row + s, b = a + row;
      if (r !== 0) idx.push(a, b, a + 1);
      if (r !== rings - 1) idx.push(a + 1, b, b + 1);
    }
  }
  g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pos), 3));
  g.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(nor), 3));
  g.setAttribute('tangent', new THREE.BufferAttribute(new Float32Array(tan), 4));
  g.setIndex(idx);
  return addOrientation(g);
}

/**
 * The camera of a scene file (sunbeam_scene::camera): perspective, vertical
 * field of view, near 0.01 d and far 100 d with d the eye-target distance,
 * `shift` (lens shift) as a view offset (`setViewOffset`).
 */
export function sceneCamera(scene, aspect) {
  const c = scene.camera;
  const eye = new THREE.Vector3(...c.eye), target = new THREE.Vector3(...c.target);
  const d = eye.distanceTo(target);
  const cam = new THREE.PerspectiveCamera(c.fov_y_deg ?? 35, aspect, 0.01 * d, 100 * d);
  cam.position.copy(eye);
  cam.up.set(...(c.up ?? [0, 1, 0]));
  cam.lookAt(target);
  cam.updateMatrixWorld();
  // camera.shift (Blender's lens shift): the window moves right and up by
  // shift x the larger side (sunbeam_scene::camera::shift_ndc), as a view
  // offset in a frame of height 1 (kept by updateProjectionMatrix)
  const [sx, sy] = c.shift ?? [0, 0];
  if (sx !== 0 || sy !== 0) {
    const m = Math.max(aspect, 1);
    cam.setViewOffset(aspect, 1, sx * m, -sy * m, aspect, 1);
  }
  return cam;
}

/**
 * `"background": "environment"` (docs/SCENE.md): a full-screen triangle,
 * drawn first, showing the environment averaged over 16 view rays across each
 * pixel as the player's background pass does: the exported sb_env_texel (the texel of the
 * coefficient table holding the direction: table.ktx2, or level 0 of the
 * chain when there are no hot spots; its columns start chain.phase turns
 * after phi = 0) times
 * basis_to_rgb, plus the sky's sun inside its disc, times 2^exposure. `camera` is the scene camera; the
 * rays follow whichever camera draws it (its view, projection and view offset, read before each draw). `display`:
 * clip and sRGB-encode, as sunbeamMaterial's (drawing to a canvas).
 */
export function environmentBackground(exportedGlsl, environment, camera, exposure = 0, display = false) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array([-1, -1, 0, 3, -1, 0, -1, 3, 0]), 3));
  const m = environment.basisToRgb;
  const sun = environment.json.sun;
  const material = new THREE.RawShaderMaterial({
    glslVersion: THREE.GLSL3,
    vertexShader: `precision highp float;
in vec3 position;
out vec2 vNdc;
void main() { vNdc = position.xy; gl_Position = vec4(position.xy, 1.0, 1.0); }`,
    fragmentShader: `${exportedGlsl}
uniform mat4 sbInvViewProj;
uniform vec3 sbEye;
uniform mat3 sbBasisToRgb;
uniform uvec2 sbTable;
uniform float sbPhase;
uniform float sbExposure;
uniform int sbDisplay;
uniform highp sampler2D sbChain;
uniform vec4 sbSunDir;
uniform vec3 sbSunRadiance;
in vec2 vNdc;
layout(location = 0) out vec4 fragColor;
vec3 sbBackgroundAt(vec2 ndc) {
  vec4 p = sbInvViewProj * vec4(ndc, 1.0, 1.0);
  vec3 d = normalize(p.xyz / p.w - sbEye);
  vec3 c = sbBasisToRgb * sb_env_texel(sbChain, sbTable.x, sbTable.y, sbPhase, d);
  // the sky's sun: its disc (w: the cosine of its angular radius; 2 without a sun)
  if (dot(d, sbSunDir.xyz) >= sbSunDir.w) c += sbSunRadiance;
  return c;
}
void main() {
  // 16 rays over the pixel's square (a Hammersley set: one in every 1/16-wide
  // row and column), the box the reference's sub-pixel samples average, as
  // the player's background pass takes it
  vec2 px = dFdx(vNdc), py = dFdy(vNdc);
  vec3 c = vec3(0.0);
  for (int k = 0; k < 16; k++) {
    int r = ((k & 1) << 3) | ((k & 2) << 1) | ((k & 4) >> 1) | ((k & 8) >> 3);
    vec2 o = (vec2(float(k), float(r)) + 0.5) / 16.0 - 0.5;
    c += sbBackgroundAt(vNdc + o.x * px + o.y * py);
  }
  c = c / 16.0 * sbExposure;
  if (sbDisplay == 1) {
    c = clamp(c, 0.0, 1.0);
    c = mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
  }
  fragColor = vec4(c, 1.0);
}`,
    uniforms: {
      sbInvViewProj: { value: new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse).invert() },
      sbEye: { value: new THREE.Vector3().setFromMatrixPosition(camera.matrixWorld) },
      // row-major rows of environment.json, as three's Matrix3.set takes them
      sbBasisToRgb: { value: new THREE.Matrix3().set(...m[0], ...m[1], ...m[2]) },
      sbTable: { value: new THREE.Vector2(environment.json.chain.width, environment.json.chain.height) },
      sbPhase: { value: environment.json.chain.phase ?? 0 },
      sbExposure: { value: Math.pow(2, exposure) },
      sbDisplay: { value: display ? 1 : 0 },
      sbChain: { value: environment.table },
      // environment.json `sun`: `rgb` is its Omega L, `solid_angle` Omega = 2 pi (1 - cos r)
      sbSunDir: { value: sun ? new THREE.Vector4(...sun.direction, 1 - sun.solid_angle / (2 * Math.PI)) : new THREE.Vector4(0, 1, 0, 2) },
      sbSunRadiance: { value: sun ? new THREE.Vector3(...sun.rgb.map((v) => v / sun.solid_angle)) : new THREE.Vector3() },
    },
    depthTest: false,
    depthWrite: false,
  });
  const mesh = new THREE.Mesh(geometry, material);
  mesh.frustumCulled = false;
  mesh.renderOrder = -1;
  mesh.onBeforeRender = (r, s, cam, geom, mat) => {
    mat.uniforms.sbInvViewProj.value.multiplyMatrices(cam.projectionMatrix, cam.matrixWorldInverse).invert();
    mat.uniforms.sbEye.value.setFromMatrixPosition(cam.matrixWorld);
    mat.uniformsNeedUpdate = true;
  };
  return mesh;
}
