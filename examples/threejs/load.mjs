// Load Sunbeam's outputs in three.js (runs in node or a browser bundler):
//   node load.mjs snake.glb elaphe.ktx2
// - the baked GLB through GLTFLoader: POSITION, NORMAL, TANGENT (xyzw) and the
//   custom _ORIENTATION (three names it `_orientation`: unknown glTF attributes
//   are kept, lower-cased);
// - the KTX2 pack as a THREE.DataArrayTexture (RGFormat, FloatType: R = real,
//   G = imaginary part of term n in layer n), parsed with ktx-parse (three ships
//   it); the manifest JSON is the key/value entry `sunbeam.manifest`.
// It prints a JSON summary on stdout (the tests in tests/threejs.rs check it).
// docs/ENGINES.md explains how a shader evaluates the pack (docs/PACK_FORMAT.md).
import { readFileSync } from 'node:fs';
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { read as readKTX2 } from 'three/addons/libs/ktx-parse.module.js';

const [glbPath, ktx2Path] = process.argv.slice(2);
if (!glbPath || !ktx2Path) {
  console.error('usage: node load.mjs MESH.glb PACK.ktx2');
  process.exit(1);
}

function toArrayBuffer(buf) {
  return buf.buffer.slice(buf.byteOffset, buf.byteOffset + buf.byteLength);
}

// ---- the mesh -------------------------------------------------------------------
async function loadGLB(path) {
  const loader = new GLTFLoader();
  const gltf = await loader.parseAsync(toArrayBuffer(readFileSync(path)), '');
  const meshes = [];
  gltf.scene.traverse((o) => { if (o.isMesh) meshes.push(o); });
  if (meshes.length === 0) throw new Error(`${path}: no mesh`);
  const g = meshes[0].geometry;
  const orient = g.getAttribute('_orientation');
  const tangent = g.getAttribute('tangent');
  if (!orient) throw new Error(`${path}: no _ORIENTATION attribute`);
  g.computeBoundingBox();
  // The orientation is a unit vector in the tangent plane (orthogonal to the normal).
  const normal = g.getAttribute('normal');
  let maxDot = 0, maxLenErr = 0;
  for (let i = 0; i < orient.count; i++) {
    const o = new THREE.Vector3().fromBufferAttribute(orient, i);
    const n = new THREE.Vector3().fromBufferAttribute(normal, i);
    maxLenErr = Math.max(maxLenErr, Math.abs(o.length() - 1));
    maxDot = Math.max(maxDot, Math.abs(o.dot(n)));
  }
  return {
    meshes: meshes.length,
    vertices: g.getAttribute('position').count,
    triangles: g.index ? g.index.count / 3 : g.getAttribute('position').count / 3,
    orientation_item_size: orient.itemSize,
    tangent_item_size: tangent ? tangent.itemSize : 0,
    orientation_max_length_error: maxLenErr,
    orientation_max_dot_normal: maxDot,
    bbox_min: g.boundingBox.min.toArray(),
    bbox_max: g.boundingBox.max.toArray(),
  };
}

// ---- the pack ---------------------------------------------------------------------
const VK_FORMAT_R16G16_SFLOAT = 83;
const VK_FORMAT_R32G32_SFLOAT = 103;

function loadPack(path) {
  const ktx = readKTX2(new Uint8Array(readFileSync(path)));
  const manifest = JSON.parse(new TextDecoder().decode(ktx.keyValue['sunbeam.manifest']));
  const { pixelWidth: w, pixelHeight: h, layerCount: layers } = ktx;
  const level = ktx.levels[0].levelData;
  let data, type;
  if (ktx.vkFormat === VK_FORMAT_R32G32_SFLOAT) {
    data = new Float32Array(level.buffer.slice(level.byteOffset, level.byteOffset + level.byteLength));
    type = THREE.FloatType;
  } else if (ktx.vkFormat === VK_FORMAT_R16G16_SFLOAT) {
    data = new Uint16Array(level.buffer.slice(level.byteOffset, level.byteOffset + level.byteLength));
    type = THREE.HalfFloatType;
  } else {
    throw new Error(`${path}: vkFormat ${ktx.vkFormat} is not a Sunbeam pack format`);
  }
  if (data.length !== w * h * layers * 2) throw new Error(`${path}: ${data.length} values for ${w}x${h}x${layers}x2`);
  const tex = new THREE.DataArrayTexture(data, w, h, layers);
  tex.format = THREE.RGFormat;
  tex.type = type;
  // The shader reads exact texels (docs/PACK_FORMAT.md "Evaluation": taps with its own kernel).
  tex.minFilter = THREE.NearestFilter;
  tex.magFilter = THREE.NearestFilter;
  tex.generateMipmaps = false;
  tex.needsUpdate = true;
  // Term 0 at the centre texel (frequency 0) of a window-model pack.
  const { kx, ky } = manifest.crop;
  const centre = (ky * w + kx) * 2;
  return {
    texture: tex,
    summary: {
      is_data_array_texture: tex.isDataArrayTexture === true,
      width: tex.image.width, height: tex.image.height, depth: tex.image.depth,
      type: type === THREE.FloatType ? 'FloatType' : 'HalfFloatType',
      format: 'RGFormat',
      manifest_terms: manifest.terms,
      manifest_crop: manifest.crop,
      manifest_model: manifest.model,
      height_half_range_m: manifest.height_half_range_m,
      term0_centre: type === THREE.FloatType ? [data[centre], data[centre + 1]] : null,
    },
  };
}

const mesh = await loadGLB(glbPath);
const pack = loadPack(ktx2Path);
// A material would bind it like this (shader code: docs/ENGINES.md).
const material = new THREE.ShaderMaterial({
  uniforms: { uTerms: { value: pack.texture }, uTermCount: { value: pack.summary.manifest_terms } },
  glslVersion: THREE.GLSL3,
});
console.log(JSON.stringify({ mesh, pack: pack.summary, material: material.type }, null, 1));
