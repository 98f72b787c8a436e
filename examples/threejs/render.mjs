// Render a Sunbeam scene file (docs/SCENE.md) with three.js in headless
// Chromium, as a browser would draw it:
//
//   node render.mjs SCENE.json -o FRAME.png [--exr FRAME.exr] [--size WxH] [--supersample K] [--msaa N] [--tile T]
//                   [--edge-supersample M [--edge-threshold T] [--edge-levels N]]
//
// - the material is sunbeam-three.mjs: the GLSL ES that
//   `sunbeam-play --export-shader glsl-es` writes from the player's WGSL
//   (SUNBEAM_PLAY or ../../target/release/sunbeam-play, or --glsl FILE);
// - each mesh's pack is read through its response map, NAME.response.ktx2
//   beside the pack (`sunbeam-pack --response`);
// - an "environment" (sky or map) lights the meshes through the exported
//   sunbeam_shade_environment (the player's first-frame cells) with the
//   files `sunbeam-play SCENE --export-environment DIR` writes, and its sun
//   through sunbeam_shade_sun; "background": "environment" draws it behind;
// - the frame is rendered into a float target at K x K times the size (default
//   K = 4) and box-filtered in linear light (a pixel is the average over its
//   area), then written as PNG (exposure, clip at 1, sRGB curve: what
//   sunbeam-eval render and sunbeam-play write) and, with --exr, as a linear
//   OpenEXR (exposure applied, no tone curve) for comparisons; K runs 1 to
//   16, and the K-times frame is drawn in tiles of at most --tile T texels a
//   side (default and cap: 2048, or less where the GPU's render targets are
//   smaller), so any size and K render and the tiles' frame equals one pass;
// - --msaa N (1 or 4, default 1) renders that target with N samples per
//   texel, as a page with `antialias: true` draws its canvas: coverage at N
//   samples, the material shaded once per texel at the centroid of the
//   covered samples (docs/ENGINES.md "The baked snake under the sky");
// - --edge-supersample M (1..64) renders the pixels whose K x K sub-pixels
//   disagree (a mesh's outline, the limb's sheen: the player's criterion,
//   --edge-threshold T, default 0.05) again at M x M positions each, in
//   tiles through camera.setViewOffset, and replaces them with that box
//   (sunbeam-play's --edge-supersample; docs/LIGHTING.md "Edge refinement").
//   --edge-levels N (1..4, default 1; an even M, M 2^(N-1) <= 64): each
//   further level takes the refined pixels whose positions still disagree
//   (their four interleaved quarter-lattices, the player's criterion) to
//   twice the positions per side (sunbeam-play's --edge-levels).
//
// Needs three and playwright-core next to it (node_modules) and Debian's
// chromium (CHROMIUM or /usr/bin/chromium; playwright gives it a fresh
// temporary profile). WebGL2 runs on SwiftShader.
import { readFileSync, writeFileSync, existsSync, mkdtempSync, rmSync, renameSync } from 'node:fs';
import { createServer } from 'node:http';
import { tmpdir } from 'node:os';
import { dirname, join, resolve, extname, basename } from 'node:path';
import { fileURLToPath } from 'node:url';
import { execFileSync } from 'node:child_process';
import zlib from 'node:zlib';

const here = dirname(fileURLToPath(import.meta.url));

function usage(msg) {
  if (msg) console.error(`render.mjs: error: ${msg}`);
  console.error('usage: node render.mjs SCENE.json -o FRAME.png [--exr FRAME.exr] [--size WxH] [--supersample K] [--msaa N] [--tile T] [--edge-supersample M [--edge-threshold T] [--edge-levels N]] [--glsl FILE]');
  process.exit(1);
}

function fail(code, msg) {
  console.error(`render.mjs: error: ${msg}`);
  process.exit(code);
}

// ---- arguments -----------------------------------------------------------------
const args = process.argv.slice(2);
const opt = { supersample: 4, msaa: 1 };
for (let i = 0; i < args.length; i++) {
  const a = args[i];
  const next = () => (i + 1 < args.length ? args[++i] : usage(`${a} needs a value`));
  if (a === '-o' || a === '--output') opt.output = next();
  else if (a === '--exr') opt.exr = next();
  else if (a === '--size') {
    const m = /^(\d+)x(\d+)$/.exec(next());
    if (!m || +m[1] < 1 || +m[2] < 1 || +m[1] > 8192 || +m[2] > 8192) usage('--size: expected WxH');
    opt.size = [+m[1], +m[2]];
  } else if (a === '--supersample') {
    opt.supersample = Number(next());
    if (!Number.isInteger(opt.supersample) || opt.supersample < 1 || opt.supersample > 16) usage('--supersample: 1..16');
  } else if (a === '--tile') {
    opt.tile = Number(next());
    if (!Number.isInteger(opt.tile) || opt.tile < 1) usage('--tile: a positive number of texels');
  } else if (a === '--msaa') {
    opt.msaa = Number(next());
    if (opt.msaa !== 1 && opt.msaa !== 4) usage('--msaa: 1 or 4');
  } else if (a === '--edge-supersample') {
    opt.edge = Number(next());
    if (!Number.isInteger(opt.edge) || opt.edge < 1 || opt.edge > 64) usage('--edge-supersample: 1..64 positions per pixel side');
  } else if (a === '--edge-threshold') {
    opt.edgeThreshold = Number(next());
    if (!(opt.edgeThreshold > 0 && Number.isFinite(opt.edgeThreshold))) usage('--edge-threshold: a positive number (of the pixel\'s mean luminance)');
  } else if (a === '--edge-levels') {
    opt.edgeLevels = Number(next());
    if (!Number.isInteger(opt.edgeLevels) || opt.edgeLevels < 1 || opt.edgeLevels > 4) usage('--edge-levels: 1..4');
  } else if (a === '--glsl') opt.glsl = next();
  else if (a === '-h' || a === '--help') usage();
  else if (a.startsWith('-')) usage(`unknown option ${a}`);
  else if (!opt.scene) opt.scene = a;
  else usage(`unexpected argument ${a}`);
}
if (!opt.scene || !opt.output) usage('SCENE.json and -o FRAME.png are required');
if (opt.edgeThreshold !== undefined && !opt.edge) usage('--edge-threshold needs --edge-supersample');
if (opt.edgeLevels !== undefined && !opt.edge) usage('--edge-levels needs --edge-supersample');
if ((opt.edgeLevels ?? 1) > 1) {
  if (opt.edge % 2 === 1) usage('--edge-levels above 1 needs an even --edge-supersample (its quarter-lattices decide the next level)');
  const last = opt.edge * 2 ** (opt.edgeLevels - 1);
  if (last > 64) usage(`--edge-supersample ${opt.edge} with --edge-levels ${opt.edgeLevels} reaches ${last} positions per pixel side; at most 64`);
}

// ---- the scene (the same defaults as crates/sunbeam-scene) -------------------------
let scene;
try {
  scene = JSON.parse(readFileSync(opt.scene, 'utf8'));
} catch (e) {
  fail(2, `${opt.scene}: ${e.message}`);
}
const sceneDir = dirname(resolve(opt.scene));
if (!scene.camera || !Array.isArray(scene.camera.eye) || !Array.isArray(scene.camera.target)) fail(2, `${opt.scene}: camera.eye and camera.target are required`);
if (!Array.isArray(scene.meshes) || scene.meshes.length === 0) fail(2, `${opt.scene}: meshes: at least one mesh is required`);
scene.meshes.forEach((m, i) => {
  const at = `${opt.scene}: meshes[${i}]`;
  if (!['off', 'smith'].includes(m.masking ?? 'off')) fail(2, `${at}.masking "${m.masking}": expected "off" or "smith"`);
  const s = m.rms_slope;
  if (s !== undefined && !((typeof s === 'number' && s >= 0) || (Array.isArray(s) && s.length === 2 && s.every((v) => typeof v === 'number' && v >= 0)))) fail(2, `${at}.rms_slope: expected a number or [x, y], finite and >= 0`);
  if (m.ior !== undefined && !(typeof m.ior === 'number' && m.ior > 1 && m.ior <= 4)) fail(2, `${at}.ior: expected a refractive index in (1, 4]`);
  if (!['absolute', 'relative'].includes(m.reflectance ?? 'absolute')) fail(2, `${at}.reflectance "${m.reflectance}": expected "absolute" or "relative"`);
});
if (scene.environment !== undefined) {
  const e = scene.environment;
  if (!e || typeof e !== 'object' || (e.sky === undefined) === (e.map === undefined)) fail(2, `${opt.scene}: environment: expected exactly one of "sky" or "map" (docs/SCENE.md)`);
}
const bgOk = scene.background === undefined || (Array.isArray(scene.background) && scene.background.length === 3 && scene.background.every(Number.isFinite))
  || (scene.background === 'environment' && scene.environment);
if (!bgOk) fail(2, `${opt.scene}: background: expected [r, g, b] or "environment" (with an environment)`);
// With an environment an omitted lights means none (the sky has its own sun).
scene.lights = scene.lights ?? (scene.environment ? [] : [{ direction: [0.3, 1.0, 0.6], intensity: 1 }]);
scene.lights.forEach((l, i) => {
  const c = l.color;
  if (c !== undefined && !(Array.isArray(c) && c.length === 3 && c.every((v) => typeof v === 'number' && Number.isFinite(v) && v >= 0))) fail(2, `${opt.scene}: lights[${i}].color: expected [r, g, b], finite and >= 0 (linear sRGB)`);
});
const shift = scene.camera.shift;
if (shift !== undefined && !(Array.isArray(shift) && shift.length === 2 && shift.every((v) => typeof v === 'number' && Math.abs(v) <= 10))) fail(2, `${opt.scene}: camera.shift: expected [x, y], each in [-10, 10]`);
scene.exposure = scene.exposure ?? 0;
scene.background = scene.background ?? [0, 0, 0];
const size = opt.size ?? scene.size ?? [512, 512];

const problems = []; // what the page or the server reported
const files = new Map(); // url path -> absolute file
function serve(abs) {
  const key = `/fs/${files.size}${extname(abs)}`;
  files.set(key, abs);
  return key;
}
// The response maps a GLB names in SUNBEAM_materials_diffraction (sunbeam-bake --pack), served.
function extensionMaps(glb, what) {
  const b = readFileSync(glb);
  if (b.length < 20 || b.readUInt32LE(0) !== 0x46546c67) fail(2, `${what}: ${glb} is not a GLB`);
  const json = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString('utf8'));
  const maps = {};
  for (const mat of json.materials ?? []) {
    const e = mat.extensions?.SUNBEAM_materials_diffraction;
    if (!e) continue;
    const uri = e.responseMap?.uri;
    if (typeof uri !== 'string') fail(2, `${what}: SUNBEAM_materials_diffraction.responseMap.uri missing`);
    const abs = resolve(dirname(glb), decodeURIComponent(uri));
    if (!existsSync(abs)) fail(2, `${what}: SUNBEAM_materials_diffraction.responseMap.uri: ${abs} not found`);
    maps[uri] = serve(abs);
  }
  return maps;
}

const meshes = scene.meshes.map((m, i) => {
  if (typeof m.mesh !== 'string') fail(2, `${opt.scene}: meshes[${i}].mesh is required`);
  const out = {
    baseColor: m.base_color ?? [0.05, 0.05, 0.05],
    diffuseWeight: m.diffuse_weight ?? 0.2,
    // the skin (docs/SCENE.md): index, normalisation, masking
    ior: m.ior ?? 1.5,
    reflectance: m.reflectance ?? 'absolute',
    masking: m.masking ?? 'off',
    rmsSlope: m.rms_slope ?? null,
    what: `meshes[${i}]`,
  };
  if (m.mesh.startsWith('builtin:')) out.builtin = m.mesh.slice(8);
  else {
    const p = resolve(sceneDir, m.mesh);
    if (!existsSync(p)) fail(2, `${opt.scene}: meshes[${i}].mesh: ${p} not found`);
    if (!/\.(glb|gltf)$/i.test(p)) fail(2, `${opt.scene}: meshes[${i}].mesh: three.js path reads glTF/GLB only (${p})`);
    out.url = serve(p);
    if (/\.glb$/i.test(p) && !m.pack) out.extMaps = extensionMaps(p, `${opt.scene}: meshes[${i}].mesh`);
  }
  if (m.pack) {
    out.packGiven = true;
    const p = resolve(sceneDir, m.pack);
    const side = join(dirname(p), `${basename(p, extname(p))}.response.ktx2`);
    if (!existsSync(side)) fail(2, `${opt.scene}: meshes[${i}].pack: no response map ${side} (write it with sunbeam-pack --response)`);
    out.map = serve(side);
  }
  return out;
});

// ---- the exported material -------------------------------------------------------
let glsl;
if (opt.glsl) glsl = readFileSync(opt.glsl, 'utf8');
else {
  const play = process.env.SUNBEAM_PLAY ?? resolve(here, '../../target/release/sunbeam-play');
  const tmp = mkdtempSync(join(tmpdir(), 'sunbeam-glsl-'));
  try {
    execFileSync(play, ['--export-shader', 'glsl-es', '-o', join(tmp, 'm.frag'), '-q']);
    glsl = readFileSync(join(tmp, 'm.frag'), 'utf8');
  } catch (e) {
    fail(2, `cannot export the material with ${play} (set SUNBEAM_PLAY or --glsl FILE): ${e.message}`);
  } finally {
    rmSync(tmp, { recursive: true, force: true });
  }
}

// ---- the environment's files (sunbeam-play SCENE --export-environment DIR) ----------
// The maps, the pack's response and the cells are built (or read) by the tool
// from the scene file itself, so they are the player's; sunbeam-play checks
// the environment's fields and files (exit 2 naming them).
let env = null;
let envDir = null;
// The temporary folder goes however render.mjs exits (fail() exits at once).
process.on('exit', () => { if (envDir) rmSync(envDir, { recursive: true, force: true }); });
if (scene.environment) {
  const play = process.env.SUNBEAM_PLAY ?? resolve(here, '../../target/release/sunbeam-play');
  envDir = mkdtempSync(join(tmpdir(), 'sunbeam-env-'));
  try {
    execFileSync(play, [resolve(opt.scene), '--export-environment', envDir, '-q'], { stdio: ['ignore', 'ignore', 'pipe'] });
  } catch (e) {
    rmSync(envDir, { recursive: true, force: true });
    const why = e.stderr ? e.stderr.toString().trim() : e.message;
    fail(e.status === 2 ? 2 : 4, `environment: ${play} --export-environment failed: ${why}`);
  }
  const json = JSON.parse(readFileSync(join(envDir, 'environment.json'), 'utf8'));
  const cells = {};
  const suns = {};
  const basis = {};
  for (const m of json.meshes) {
    cells[m.file] = serve(join(envDir, m.file));
    if (m.sun) suns[m.sun] = serve(join(envDir, m.sun));
    for (const f of m.basis ?? []) basis[f] = serve(join(envDir, f));
  }
  env = {
    json, cells, suns, basis, chain: serve(join(envDir, json.chain.file)),
    table: json.table ? serve(join(envDir, json.table)) : null,
    irradianceSkin: serve(join(envDir, json.irradiance.skin)), irradiance: serve(join(envDir, json.irradiance.plain)),
  };
}

// ---- a local server for the page, three and the scene's files ----------------------
const page = `<!doctype html><html><head><meta charset="utf-8">
<script type="importmap">{"imports":{"three":"/node_modules/three/build/three.module.js","three/addons/":"/node_modules/three/examples/jsm/"}}</script>
<script type="module" src="/render-page.mjs"></script></head><body></body></html>`;
const types = { '.mjs': 'text/javascript', '.js': 'text/javascript', '.html': 'text/html', '.glb': 'model/gltf-binary', '.ktx2': 'image/ktx2', '.json': 'application/json' };
const server = createServer((req, res) => {
  const path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
  let file;
  if (path === '/favicon.ico') {
    res.writeHead(204);
    res.end();
    return;
  }
  if (path === '/render.html') {
    res.writeHead(200, { 'content-type': 'text/html' });
    res.end(page);
    return;
  } else if (files.has(path)) file = files.get(path);
  else if (path === '/render-page.mjs' || path === '/sunbeam-three.mjs') file = join(here, path);
  else if (path.startsWith('/node_modules/three/') && !path.includes('..')) file = join(here, path);
  if (!file || !existsSync(file)) {
    problems.push(`404: ${path}`);
    res.writeHead(404);
    res.end();
    return;
  }
  res.writeHead(200, { 'content-type': types[extname(file)] ?? 'application/octet-stream' });
  res.end(readFileSync(file));
});
await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
const base = `http://127.0.0.1:${server.address().port}`;

// ---- headless Chromium -----------------------------------------------------------
const { chromium } = await import('playwright-core');
let browser;
let pixels;
try {
  browser = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
      '--disable-quic', '--no-first-run', '--disable-background-networking', '--disable-component-update',
      '--disable-sync'],
  });
  const p = await browser.newPage();
  p.on('console', (m) => { if (m.type() === 'error' || m.type() === 'warning') problems.push(`console ${m.type()}: ${m.text()}`); });
  p.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  await p.goto(`${base}/render.html`);
  await p.waitForFunction(() => window.sunbeamRender !== undefined, null, { timeout: 60000 });
  const job = { scene, meshes, size, supersample: opt.supersample, msaa: opt.msaa, glsl, env, tile: opt.tile ?? 0,
    edge: opt.edge ?? 0, edgeThreshold: opt.edgeThreshold ?? 0.05, edgeLevels: opt.edgeLevels ?? 1 };
  pixels = await p.evaluate((j) => window.sunbeamRender(j), job);
} catch (e) {
  fail(4, `rendering in Chromium failed: ${e.message}${problems.length ? `\n${problems.join('\n')}` : ''}`);
} finally {
  if (browser) await browser.close();
  server.close();
}
if (pixels.error) fail(2, pixels.error);
const errors = problems.filter((s) => !/GPU stall due to ReadPixels|Automatic fallback to software WebGL/.test(s));
if (errors.length) fail(4, `the page reported problems:\n${errors.join('\n')}`);

// ---- outputs: linear EXR and display PNG ---------------------------------------------
const [w, h] = size;
const lin = Float32Array.from(pixels.rgb); // rows top first, RGB, exposure applied

function atomicWrite(path, bytes) {
  const tmp = join(dirname(resolve(path)), `.${basename(path)}.tmp.${process.pid}`);
  try {
    writeFileSync(tmp, bytes);
    renameSync(tmp, path);
  } catch (e) {
    rmSync(tmp, { force: true });
    fail(3, `${path}: cannot write: ${e.message}`);
  }
}

function pngBytes(rgb8) {
  const crcTable = [];
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    crcTable[n] = c >>> 0;
  }
  const crc = (buf) => { let c = 0xffffffff; for (const b of buf) c = crcTable[(c ^ b) & 0xff] ^ (c >>> 8); return (c ^ 0xffffffff) >>> 0; };
  const chunk = (type, data) => {
    const len = Buffer.alloc(4); len.writeUInt32BE(data.length);
    const td = Buffer.concat([Buffer.from(type, 'ascii'), data]);
    const c = Buffer.alloc(4); c.writeUInt32BE(crc(td));
    return Buffer.concat([len, td, c]);
  };
  const ihdr = Buffer.alloc(13);
  ihdr.writeUInt32BE(w, 0); ihdr.writeUInt32BE(h, 4); ihdr[8] = 8; ihdr[9] = 2; ihdr[10] = 0; ihdr[11] = 0; ihdr[12] = 0;
  const raw = Buffer.alloc((w * 3 + 1) * h);
  for (let y = 0; y < h; y++) {
    raw[y * (w * 3 + 1)] = 0;
    rgb8.copy(raw, y * (w * 3 + 1) + 1, y * w * 3, (y + 1) * w * 3);
  }
  return Buffer.concat([Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]), chunk('IHDR', ihdr), chunk('IDAT', zlib.deflateSync(raw)), chunk('IEND', Buffer.alloc(0))]);
}

// sunbeam_optics::colour: clip at 1, sRGB OETF, round to 8 bits.
const oetf = (x) => (x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055);
const rgb8 = Buffer.alloc(w * h * 3);
for (let i = 0; i < w * h * 3; i++) {
  let x = lin[i];
  if (!(x > 0)) x = 0;
  rgb8[i] = Math.round(oetf(Math.min(x, 1)) * 255);
}
atomicWrite(opt.output, pngBytes(rgb8));

// Uncompressed scanline OpenEXR, channels B, G, R as FLOAT (alphabetical, as the format wants).
function exrBytes() {
  const attrs = [];
  const attr = (name, type, data) => attrs.push(Buffer.concat([Buffer.from(`${name}\0${type}\0`, 'latin1'), (() => { const b = Buffer.alloc(4); b.writeInt32LE(data.length); return b; })(), data]));
  const chl = Buffer.concat(['B', 'G', 'R'].map((c) => { const b = Buffer.alloc(c.length + 1 + 16); b.write(c, 0, 'latin1'); b.writeInt32LE(2, c.length + 1); b.writeInt32LE(1, c.length + 9); b.writeInt32LE(1, c.length + 13); return b; }).concat([Buffer.from([0])]));
  attr('channels', 'chlist', chl);
  attr('compression', 'compression', Buffer.from([0]));
  const box = Buffer.alloc(16); box.writeInt32LE(0, 0); box.writeInt32LE(0, 4); box.writeInt32LE(w - 1, 8); box.writeInt32LE(h - 1, 12);
  attr('dataWindow', 'box2i', box);
  attr('displayWindow', 'box2i', box);
  attr('lineOrder', 'lineOrder', Buffer.from([0]));
  const f = Buffer.alloc(4); f.writeFloatLE(1); attr('pixelAspectRatio', 'float', f);
  attr('screenWindowCenter', 'v2f', Buffer.alloc(8));
  attr('screenWindowWidth', 'float', f);
  const header = Buffer.concat([Buffer.from([0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0]), ...attrs, Buffer.from([0])]);
  const lineBytes = 8 + w * 12;
  const table = Buffer.alloc(8 * h);
  const start = header.length + table.length;
  const lines = Buffer.alloc(lineBytes * h);
  for (let y = 0; y < h; y++) {
    table.writeBigUInt64LE(BigInt(start + y * lineBytes), 8 * y);
    const o = y * lineBytes;
    lines.writeInt32LE(y, o); lines.writeInt32LE(w * 12, o + 4);
    for (let x = 0; x < w; x++) {
      const p = 3 * (y * w + x);
      lines.writeFloatLE(lin[p + 2], o + 8 + 4 * x);
      lines.writeFloatLE(lin[p + 1], o + 8 + 4 * (w + x));
      lines.writeFloatLE(lin[p], o + 8 + 4 * (2 * w + x));
    }
  }
  return Buffer.concat([header, table, lines]);
}
if (opt.exr) atomicWrite(opt.exr, exrBytes());
console.error(`render.mjs: wrote ${opt.output}${opt.exr ? ` and ${opt.exr}` : ''} (${w}x${h}, ${opt.supersample}x${opt.supersample} samples per pixel${opt.msaa > 1 ? `, ${opt.msaa}x MSAA` : ''}${pixels.tiles > 1 ? `, ${pixels.tiles} tiles` : ''}${pixels.edge ? `, edge pixels ${pixels.edge.levels.map((l) => `${l.pixels} at ${l.positions}x${l.positions}`).join(', ')} in ${pixels.edge.tiles} tiles` : ''}, ${pixels.renderer})`);
