// Sunbeam's diffraction material in three.js (WebGL2), used by index.html (the
// interactive page) and render.mjs (headless frames of a scene file).
//
// The shading code is not a port: it is the GLSL ES 3.00 that
// `sunbeam-play --export-shader glsl-es` writes from the player's own WGSL
// (shaders/material.wgsl: the frame, exact Fresnel, G, Smith masking, the
// diffuse base's share; shaders/response_map.wgsl: the map), adapted here only
// in its declarations (a plain struct uniform instead of a uniform block, our
// varyings and light loop instead of its demo entry point). docs/ENGINES.md
// documents the interface.
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

/** The exported GLSL ES with its declarations adapted for a three.js RawShaderMaterial. */
export function adaptExportedGlsl(src) {
  const lines = src.split('\n');
  const out = [];
  for (const l of lines) {
    if (l.startsWith('#version')) continue;
    if (l.startsWith('void main()')) break; // the demo entry point: ours follows
    if (/^smooth in vec3 _vs2fs_location\d;/.test(l)) continue;
    if (l.startsWith('layout(location = 0) out vec4')) continue;
    if (l.startsWith('layout(std140) uniform SunbeamMaterial_block')) {
      out.push('uniform SunbeamMaterial _group_0_binding_0_fs;');
      continue;
    }
    out.push(l);
  }
  const text = out.join('\n');
  if (!text.includes('vec3 sunbeam_shade(') || !text.includes('mat3x3 sb_frame(') || !text.includes('_group_0_binding_1_fs')) {
    throw new Error('exported GLSL: sunbeam_shade, sb_frame or the map binding not found (docs/ENGINES.md)');
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
out vec3 vWorld;
out vec3 vNormal;
out vec3 vOrient;
void main() {
  vec4 w = modelMatrix * vec4(position, 1.0);
  vWorld = w.xyz;
  vNormal = sbNormalMatrix * normal;
  vOrient = mat3(modelMatrix) * sbOrient;
  gl_Position = projectionMatrix * viewMatrix * w;
}`;

function fragment(exported) {
  return `${exported}
uniform vec3 sbEye;
uniform int sbLightCount;
uniform vec4 sbLights[${MAX_LIGHTS}]; // xyz towards the light (unit), w intensity
uniform float sbExposure;              // 2^exposure
uniform int sbHasMap;
uniform int sbDisplay;                 // 1: clip at 1 and sRGB-encode (drawing to a canvas)
in vec3 vWorld;
in vec3 vNormal;
in vec3 vOrient;
layout(location = 0) out vec4 fragColor;
void main() {
  // The player's frame (shaders/material.wgsl sb_frame): t orthogonalised against n.
  mat3 f = sb_frame(vNormal, vOrient);
  vec3 t = f[0];
  vec3 b = f[1];
  vec3 n = f[2];
  vec3 wr = normalize(sbEye - vWorld);
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
    rgb += sbLights[i].w * c;
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
 * light, intensity}], `exposure` in stops, `display`: clip and sRGB-encode
 * (for a canvas; off for linear float targets). Uniforms can be changed later
 * (material.uniforms; the skin through skinUniform).
 */
export function sunbeamMaterial({ exportedGlsl, map, baseColor = [0.05, 0.05, 0.05], diffuseWeight = 0.2, ior = 1.5, reflectance = 'absolute', rmsSlope = [0, 0], lights = [], exposure = 0, display = false }) {
  const g = map ? map.grid : { n_theta: 1, n_rho: 2, n_s: 2, r0: 1 };
  const lightVecs = [];
  for (let i = 0; i < MAX_LIGHTS; i++) {
    const l = lights[i];
    if (!l) { lightVecs.push(new THREE.Vector4()); continue; }
    const d = new THREE.Vector3(...l.direction).normalize();
    lightVecs.push(new THREE.Vector4(d.x, d.y, d.z, l.intensity ?? 1));
  }
  const placeholder = new THREE.Data3DTexture(new Uint16Array(4 * 2 * 2), 1, 2, 2);
  placeholder.type = THREE.HalfFloatType;
  placeholder.needsUpdate = true;
  const m = new THREE.RawShaderMaterial({
    glslVersion: THREE.GLSL3,
    vertexShader: VERTEX,
    fragmentShader: fragment(exportedGlsl),
    uniforms: {
      sbNormalMatrix: { value: new THREE.Matrix3() },
      sbEye: { value: new THREE.Vector3() },
      sbLightCount: { value: Math.min(lights.length, MAX_LIGHTS) },
      sbLights: { value: lightVecs },
      sbExposure: { value: Math.pow(2, exposure) },
      sbHasMap: { value: map ? 1 : 0 },
      sbDisplay: { value: display ? 1 : 0 },
      _group_0_binding_1_fs: { value: map ? map.texture : placeholder },
      _group_0_binding_0_fs: {
        value: {
          grid: new THREE.Vector4(g.n_theta, g.n_rho, g.n_s, 0),
          warp: new THREE.Vector4(g.r0, Math.asinh(2 / g.r0), map ? diffuseWeight : 1, 0),
          base: new THREE.Vector4(baseColor[0], baseColor[1], baseColor[2], 0),
          skin: skinUniform({ ior, reflectance, rmsSlope }),
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
 * GLTFLoader plugin for the vendor extension SUNBEAM_materials_diffraction
 * (written by `sunbeam-bake --pack`, docs/ENGINES.md): every mesh whose glTF
 * material carries it gets `userData.sunbeam` = the extension's object
 * (`responseMap.uri` relative to the GLB, `grid`, `diffuseWeight`,
 * `baseColor`, and the skin where given: `ior`, `reflectance`, `masking`,
 * `rmsSlope`; see extensionSkin). Register with
 * `loader.register((p) => new SunbeamDiffractionPlugin(p))`.
 */
export class SunbeamDiffractionPlugin {
  constructor(parser) {
    this.parser = parser;
    this.name = 'SUNBEAM_materials_diffraction';
  }

  afterRoot(gltf) {
    const mats = this.parser.json.materials ?? [];
    gltf.scene.traverse((o) => {
      if (!o.isMesh) return;
      const a = this.parser.associations.get(o.material);
      const ext = a && a.materials !== undefined ? mats[a.materials]?.extensions?.[this.name] : undefined;
      if (ext) o.userData.sunbeam = ext;
    });
    return null;
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
 * field of view, near 0.01 d and far 100 d with d the eye-target distance.
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
  return cam;
}
