// Load a sunbeam KTX2 pack with three.js's KTX2Loader under node and print what
// three.js sees as JSON: node three_ktx2.mjs NODE_MODULES_DIR PACK.ktx2
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const [nodeModules, file] = process.argv.slice(2);
const three = (p) => pathToFileURL(path.join(nodeModules, 'three', p)).href;
const { KTX2Loader } = await import(three('examples/jsm/loaders/KTX2Loader.js'));
const { read } = await import(three('examples/jsm/libs/ktx-parse.module.js'));
const THREE = await import(three('build/three.module.js'));

const bytes = fs.readFileSync(file);
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
const container = read(new Uint8Array(buffer));
const loader = new KTX2Loader();
// Uncompressed formats need no transcoder, so no renderer/detectSupport: the raw path.
const texture = await loader._createTexture(buffer);
const mip = texture.mipmaps && texture.mipmaps.length ? texture.mipmaps[0] : texture.image;
const data = mip.data;
// KTX2Loader ignores layerCount for uncompressed data: wrap as an array texture.
const layers = container.layerCount;
const arr = new THREE.DataArrayTexture(data, container.pixelWidth, container.pixelHeight, layers);
const manifestBytes = container.keyValue['sunbeam.manifest'];
const manifest = JSON.parse(typeof manifestBytes === 'string' ? manifestBytes : new TextDecoder().decode(manifestBytes));
const writer = container.keyValue['KTXwriter'];
const f = (v) => Array.from(data.slice(0, 4));
console.log(JSON.stringify({
  vkFormat: container.vkFormat,
  width: container.pixelWidth,
  height: container.pixelHeight,
  layers,
  format: texture.format === THREE.RGFormat ? 'RG' : String(texture.format),
  type: texture.type === THREE.FloatType ? 'float' : texture.type === THREE.HalfFloatType ? 'half' : String(texture.type),
  colorSpace: texture.colorSpace,
  dataLength: data.length,
  arrayDepth: arr.image.depth,
  first: f(data),
  terms: manifest.terms,
  writer: typeof writer === 'string' ? writer : new TextDecoder().decode(writer),
}));
