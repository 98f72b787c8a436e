// The page render.mjs drives in headless Chromium: window.sunbeamRender(job)
// draws the scene with three.js into a float target at K x K times the frame
// size, box-filters it in linear light and returns the linear RGB pixels
// (rows top first, exposure applied), as sunbeam-eval render --samples K*K does.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import {
  adaptExportedGlsl, addOrientation, addScaleAttributes, builtinGeometry, environmentBackground, extensionSkin, maskingSlope,
  parseEnvironment, parseResponseMap, sceneCamera, SunbeamDiffractionPlugin, sunbeamMaterial, updateSunbeamUniforms,
} from './sunbeam-three.mjs';

// Colours are linear values as given (no sRGB conversion of inputs or outputs).
THREE.ColorManagement.enabled = false;

// Luminance Y of linear sRGB (sunbeam_frame::linear::luminance) and the
// luminance under which a pixel counts as unlit (sunbeam_frame::linear::LIT_Y).
const luminance = (r, g, b) => 0.2126729 * r + 0.7151522 * g + 0.072175 * b;
const LIT_Y = 0.0011;

/**
 * The pixels of a K-times supersampled frame to render again at more
 * positions: the player's criterion (crates/sunbeam-render/src/refine.rs
 * `flag_pixels`, docs/LIGHTING.md "Edge refinement"), here because the page
 * holds the sub-pixels. `sy`: the sub-pixels' luminance, `cover`: their
 * coverage by the meshes (0..1), `W x H` sub-pixels, `k` per pixel side. A
 * pixel is flagged where its sub-pixels with the ring around them are partly
 * covered, or where a covered sub-pixel (its axis neighbours covered too)
 * differs from the mean of its neighbours along each axis by more than
 * `threshold` times the pixel's mean luminance (plus LIT_Y): the midpoint
 * rule's error term, so a gradient is not flagged and a sheen or a step is;
 * then the neighbours of a flagged pixel that a mesh touches.
 */
function flagPixels(sy, cover, W, H, k, threshold) {
  const FULL = 0.99, NONE = 0.01;
  const w = W / k, h = H / k;
  const inside = (x, y) => x >= 0 && y >= 0 && x < W && y < H;
  const bend = (x, y) => {
    const i = y * W + x;
    if (cover[i] < FULL) return 0;
    let sum = 0, n = 0;
    for (const [dx, dy] of [[1, 0], [0, 1]]) {
      if (!inside(x - dx, y - dy) || !inside(x + dx, y + dy)) continue;
      const a = (y - dy) * W + x - dx, b = (y + dy) * W + x + dx;
      if (cover[a] < FULL || cover[b] < FULL) return 0;
      sum += 0.5 * (sy[a] + sy[b]);
      n += 1;
    }
    return n > 0 ? Math.abs(sy[i] - sum / n) : 0;
  };
  const own = new Uint8Array(w * h), touched = new Uint8Array(w * h);
  for (let py = 0; py < h; py++) {
    for (let px = 0; px < w; px++) {
      let some = false, all = true;
      for (let y = py * k - 1; y <= (py + 1) * k; y++) {
        for (let x = px * k - 1; x <= (px + 1) * k; x++) {
          if (!inside(x, y)) continue;
          const c = cover[y * W + x];
          some ||= c > NONE;
          all &&= c >= FULL;
        }
      }
      const p = py * w + px;
      touched[p] = some;
      if (!some) continue;
      if (!all) { own[p] = 1; continue; }
      let mean = 0;
      for (let y = py * k; y < (py + 1) * k; y++) for (let x = px * k; x < (px + 1) * k; x++) mean += sy[y * W + x];
      mean /= k * k;
      const limit = threshold * (mean + LIT_Y);
      let bent = false;
      for (let y = py * k; y < (py + 1) * k && !bent; y++) for (let x = px * k; x < (px + 1) * k && !bent; x++) bent = bend(x, y) > limit;
      own[p] = bent;
    }
  }
  const out = new Uint8Array(w * h);
  for (let py = 0; py < h; py++) {
    for (let px = 0; px < w; px++) {
      if (!touched[py * w + px]) continue;
      for (let dy = -1; dy <= 1 && !out[py * w + px]; dy++) {
        for (let dx = -1; dx <= 1; dx++) {
          const x = px + dx, y = py + dy;
          if (x >= 0 && y >= 0 && x < w && y < h && own[y * w + x]) { out[py * w + px] = 1; break; }
        }
      }
    }
  }
  return out;
}

// Tiles of the refinement: about 256 positions a side, 4 to 16 pixels (the
// player's refine.rs tile_pixels).
const edgeTilePixels = (m) => Math.min(16, Math.max(4, Math.floor(256 / m)));

/**
 * Whether a refined pixel's m x m positions are still unsettled: the
 * player's criterion (crates/sunbeam-render/src/refine.rs `unsettled`). `m`
 * even, and one of the four interleaved quarter-lattices of positions
 * (every other one along each axis) has a mean luminance off the block's
 * by more than `threshold` times the block's mean (plus LIT_Y). `buf`: the
 * tile's RGBA texels, `ew x eh`, rows bottom-up; the block's top-left texel
 * at (i0, j0) counted from the top.
 */
function unsettled(buf, ew, eh, m, i0, j0, threshold) {
  if (m < 2 || m % 2 === 1) return false;
  const lattice = [0, 0, 0, 0];
  for (let j = 0; j < m; j++) {
    const row = eh - 1 - (j0 + j);
    for (let i = 0; i < m; i++) {
      const q = 4 * (row * ew + i0 + i);
      lattice[(j % 2) * 2 + (i % 2)] += luminance(buf[q], buf[q + 1], buf[q + 2]);
    }
  }
  const quarter = (m * m) / 4;
  const means = lattice.map((v) => v / quarter);
  const mean = (means[0] + means[1] + means[2] + means[3]) / 4;
  return means.some((l) => Math.abs(l - mean) > threshold * (mean + LIT_Y));
}

window.sunbeamRender = async (job) => {
  try {
    const { scene: desc, meshes, size, supersample: k, msaa = 1, glsl, env: envJob, tile: tileAsked = 0, edge = 0, edgeThreshold = 0.05, edgeLevels = 1 } = job;
    const [w, h] = size;
    const W = w * k, H = h * k;
    const canvas = document.createElement('canvas');
    canvas.width = 1;
    canvas.height = 1;
    document.body.appendChild(canvas);
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
    renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
    const gl = renderer.getContext();
    // The K-times frame is drawn in tiles (camera.setViewOffset) no larger
    // than the GPU's render targets allow, capped at 2048 texels a side to
    // bound the float read-back: any size and K render, and every texel
    // sees the same projection as in one pass.
    const limit = Math.min(gl.getParameter(gl.MAX_RENDERBUFFER_SIZE), gl.getParameter(gl.MAX_TEXTURE_SIZE), 2048);
    const tile = tileAsked > 0 ? Math.min(tileAsked, limit) : limit;
    const exported = adaptExportedGlsl(glsl);
    const scale = Math.pow(2, desc.exposure);
    const root = new THREE.Scene();
    const maps = new Map();
    const loadMap = async (url) => {
      if (!maps.has(url)) maps.set(url, parseResponseMap(await (await fetch(url)).arrayBuffer()));
      return maps.get(url);
    };
    // The environment's files (sunbeam-play --export-environment, served by render.mjs).
    let environment = null;
    if (envJob) {
      const get = async (url) => (await fetch(url)).arrayBuffer();
      const cells = {};
      for (const [file, url] of Object.entries(envJob.cells)) cells[file] = await get(url);
      const suns = {};
      for (const [file, url] of Object.entries(envJob.suns)) suns[file] = await get(url);
      const basis = {};
      for (const [file, url] of Object.entries(envJob.basis ?? {})) basis[file] = await get(url);
      environment = parseEnvironment({
        json: envJob.json, chain: await get(envJob.chain), irradianceSkin: await get(envJob.irradianceSkin),
        irradiance: await get(envJob.irradiance), cells, suns, basis,
        table: envJob.table ? await get(envJob.table) : null,
      });
    }
    let meshIndex = 0;
    const make = (map, baseColor, diffuseWeight, skin, scales = null) => sunbeamMaterial({
      exportedGlsl: exported, map, baseColor, diffuseWeight, ...skin, lights: desc.lights, exposure: desc.exposure,
      environment, envCells: environment && map ? environment.forMesh(meshIndex) : null, scales,
    });
    // The scene's skin for a mesh: its index, normalisation and masking (the
    // pack's rms slopes unless the scene gives them).
    const sceneSkin = (m, map) => ({
      ior: m.ior, reflectance: m.reflectance, rmsSlope: map ? maskingSlope(m.masking, m.rmsSlope, map, m.what) : [0, 0],
    });
    for (const [mi, m] of meshes.entries()) {
      meshIndex = mi;
      // The scene's pack wins; else the GLB's own SUNBEAM_materials_diffraction.
      const sceneMap = m.map ? await loadMap(m.map) : null;
      if (m.builtin) {
        root.add(new THREE.Mesh(builtinGeometry(m.builtin), make(sceneMap, m.baseColor, m.diffuseWeight, sceneSkin(m, sceneMap))));
        continue;
      }
      const loader = new GLTFLoader();
      loader.register((p) => new SunbeamDiffractionPlugin(p));
      const gltf = await loader.loadAsync(m.url);
      const meshObjs = [];
      gltf.scene.traverse((o) => { if (o.isMesh) meshObjs.push(o); });
      for (const o of meshObjs) {
        addOrientation(o.geometry);
        const ext = o.userData.sunbeam;
        // The GLB's scale maps (sunbeam-bake --scales), whichever pack the mesh has.
        const scales = o.userData.sunbeamScales ?? null;
        if (scales) addScaleAttributes(o.geometry, scales.texCoord);
        if (sceneMap || !ext || m.packGiven) {
          o.material = make(sceneMap, m.baseColor, m.diffuseWeight, sceneSkin(m, sceneMap), scales);
        } else {
          const url = m.extMaps?.[ext.responseMap.uri];
          if (!url) return { error: `${m.url}: SUNBEAM_materials_diffraction map ${ext.responseMap.uri} not served` };
          const map = await loadMap(url);
          // The extension's skin; the scene's masking when the extension says none.
          const skin = extensionSkin(ext, map, `${m.what} (${m.url}: SUNBEAM_materials_diffraction)`);
          if (ext.masking === undefined) skin.rmsSlope = maskingSlope(m.masking, m.rmsSlope, map, m.what);
          if (ext.ior === undefined && ext.f0 === undefined) skin.ior = m.ior;
          if (ext.reflectance === undefined) skin.reflectance = m.reflectance;
          o.material = make(map, ext.baseColor ?? m.baseColor, ext.diffuseWeight ?? m.diffuseWeight, skin, scales);
        }
      }
      root.add(gltf.scene);
    }
    const camera = sceneCamera(desc, w / h);
    const background = desc.background === 'environment' ? environmentBackground(exported, environment, camera, desc.exposure) : null;
    if (background) root.add(background);
    root.updateMatrixWorld(true);
    updateSunbeamUniforms(root, camera);
    // msaa > 1: a multisampled target, resolved (averaged) before the read.
    const rt = new THREE.WebGLRenderTarget(Math.min(tile, W), Math.min(tile, H), {
      type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true, samples: msaa > 1 ? msaa : 0,
    });
    renderer.setRenderTarget(rt);
    const bg = Array.isArray(desc.background) ? desc.background : [0, 0, 0];
    renderer.setClearColor(new THREE.Color(bg[0] * scale, bg[1] * scale, bg[2] * scale), 1);
    // Box filter K x K in linear light: each texel of each tile adds to its pixel.
    const rgb = new Float64Array(w * h * 3);
    const buf = new Float32Array(Math.min(tile, W) * Math.min(tile, H) * 4);
    // With --edge-supersample: the sub-pixels' luminance and the meshes'
    // coverage (a second pass, the meshes white on a clear of 0 and no
    // background, through the same target and its MSAA).
    const subY = edge ? new Float32Array(W * H) : null;
    const cover = edge ? new Float32Array(W * H) : null;
    const white = edge ? new THREE.MeshBasicMaterial({ color: 0xffffff }) : null;
    const coverage = (target, tw, th, into, x0, y0, stride) => {
      root.overrideMaterial = white;
      if (background) background.visible = false;
      renderer.setClearColor(new THREE.Color(0, 0, 0), 0);
      renderer.setRenderTarget(target);
      renderer.render(root, camera);
      renderer.readRenderTargetPixels(target, 0, 0, tw, th, into.buf);
      root.overrideMaterial = null;
      if (background) background.visible = true;
      renderer.setClearColor(new THREE.Color(bg[0] * scale, bg[1] * scale, bg[2] * scale), 1);
      for (let j = 0; j < th; j++) {
        const row = th - 1 - j;
        for (let i = 0; i < tw; i++) into.out[(y0 + j) * stride + x0 + i] = into.buf[4 * (row * tw + i)];
      }
    };
    // The tile's window within the camera's own (a lens shift is a view offset already).
    const shifted = camera.view?.enabled === true;
    const view = shifted ? { ...camera.view } : { fullWidth: W, fullHeight: H, offsetX: 0, offsetY: 0, width: W, height: H };
    const sx = view.width / W, sy = view.height / H;
    for (let y0 = 0; y0 < H; y0 += tile) {
      for (let x0 = 0; x0 < W; x0 += tile) {
        const tw = Math.min(tile, W - x0), th = Math.min(tile, H - y0);
        camera.setViewOffset(view.fullWidth, view.fullHeight, view.offsetX + x0 * sx, view.offsetY + y0 * sy, tw * sx, th * sy);
        rt.viewport.set(0, 0, tw, th);
        renderer.setRenderTarget(rt);
        renderer.render(root, camera);
        renderer.readRenderTargetPixels(rt, 0, 0, tw, th, buf);
        // WebGL rows run bottom-up; the tile's top row is y0.
        for (let j = 0; j < th; j++) {
          const y = Math.floor((y0 + j) / k);
          const row = th - 1 - j;
          for (let i = 0; i < tw; i++) {
            const p = 4 * (row * tw + i);
            const o = 3 * (y * w + Math.floor((x0 + i) / k));
            rgb[o] += buf[p]; rgb[o + 1] += buf[p + 1]; rgb[o + 2] += buf[p + 2];
            if (subY) subY[(y0 + j) * W + x0 + i] = luminance(buf[p], buf[p + 1], buf[p + 2]);
          }
        }
        if (cover) coverage(rt, tw, th, { buf, out: cover }, x0, y0, W);
      }
    }
    for (let i = 0; i < rgb.length; i++) rgb[i] /= k * k;
    // Edge refinement: the flagged pixels' tiles at edge x edge positions per
    // pixel, each a frame of its own through the camera narrowed to the tile;
    // each further level (edgeLevels) takes the refined pixels whose
    // positions are still unsettled to twice the positions per side.
    let refined = null;
    const refineLevel = (flags, edge) => {
      const tp = edgeTilePixels(edge);
      const tw = Math.min(tp, w), th = Math.min(tp, h);
      const ew = tw * edge, eh = th * edge;
      const et = new THREE.WebGLRenderTarget(ew, eh, {
        type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true, samples: msaa > 1 ? msaa : 0,
      });
      const ebuf = new Float32Array(ew * eh * 4);
      const done = new Uint8Array(w * h);
      const level = { pixels: 0, tiles: 0, unsettled: new Uint8Array(w * h) };
      for (let ty = 0; ty < h; ty += th) {
        for (let tx = 0; tx < w; tx += tw) {
          // the last row and column of tiles end at the image's edge
          const x0 = Math.min(tx, w - tw), y0 = Math.min(ty, h - th);
          let any = false;
          for (let y = y0; y < y0 + th && !any; y++) for (let x = x0; x < x0 + tw && !any; x++) any = flags[y * w + x] && !done[y * w + x];
          if (!any) continue;
          // Only the pixels to refine are shaded: each run of them along a
          // row (merged with the same run in the rows below) is one draw
          // under a scissor rectangle (SwiftShader tests depth after the
          // fragment shader, so a depth mask would not save the shading).
          const rects = [];
          const open = new Map();
          for (let y = y0; y < y0 + th; y++) {
            const seen = new Set();
            for (let x = x0; x < x0 + tw; x++) {
              if (!flags[y * w + x] || done[y * w + x]) continue;
              let e = x;
              while (e + 1 < x0 + tw && flags[y * w + e + 1] && !done[y * w + e + 1]) e++;
              const key = `${x},${e}`;
              const r = open.get(key);
              if (r && r.y1 === y) r.y1 = y + 1;
              else { const n = { x, e, y, y1: y + 1 }; rects.push(n); open.set(key, n); }
              seen.add(key);
              x = e;
            }
            for (const key of [...open.keys()]) if (!seen.has(key)) open.delete(key);
          }
          camera.setViewOffset(view.fullWidth, view.fullHeight, view.offsetX + x0 * k * sx, view.offsetY + y0 * k * sy, tw * k * sx, th * k * sy);
          et.scissorTest = false;
          renderer.setRenderTarget(et);
          renderer.clear();
          renderer.autoClear = false;
          et.scissorTest = true;
          for (const r of rects) {
            // scissor in the target's texels, rows bottom-up
            et.scissor.set((r.x - x0) * edge, (y0 + th - r.y1) * edge, (r.e + 1 - r.x) * edge, (r.y1 - r.y) * edge);
            renderer.setRenderTarget(et);
            renderer.render(root, camera);
          }
          renderer.autoClear = true;
          et.scissorTest = false;
          renderer.setRenderTarget(et);
          renderer.readRenderTargetPixels(et, 0, 0, ew, eh, ebuf);
          level.tiles += 1;
          for (let y = y0; y < y0 + th; y++) {
            for (let x = x0; x < x0 + tw; x++) {
              const p = y * w + x;
              if (!flags[p] || done[p]) continue;
              const c = [0, 0, 0];
              for (let j = (y - y0) * edge; j < (y - y0 + 1) * edge; j++) {
                const row = eh - 1 - j;
                for (let i = (x - x0) * edge; i < (x - x0 + 1) * edge; i++) {
                  const q = 4 * (row * ew + i);
                  c[0] += ebuf[q]; c[1] += ebuf[q + 1]; c[2] += ebuf[q + 2];
                }
              }
              for (let ch = 0; ch < 3; ch++) rgb[3 * p + ch] = c[ch] / (edge * edge);
              done[p] = 1;
              level.unsettled[p] = unsettled(ebuf, ew, eh, edge, (x - x0) * edge, (y - y0) * edge, edgeThreshold);
              level.pixels += 1;
            }
          }
        }
      }
      et.dispose();
      return level;
    };
    if (edge) {
      let flags = flagPixels(subY, cover, W, H, k, edgeThreshold);
      const levels = [];
      for (let l = 0, m = edge; l < edgeLevels; l++, m *= 2) {
        const level = refineLevel(flags, m);
        flags = level.unsettled;
        levels.push({ positions: m, pixels: level.pixels, tiles: level.tiles, unsettled: flags.reduce((a, b) => a + b, 0) });
      }
      refined = { pixels: levels[0].pixels, tiles: levels.reduce((a, l) => a + l.tiles, 0), levels };
    }
    if (shifted) camera.setViewOffset(view.fullWidth, view.fullHeight, view.offsetX, view.offsetY, view.width, view.height);
    else camera.clearViewOffset();
    const dbg = gl.getExtension('WEBGL_debug_renderer_info');
    const name = dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
    const glError = gl.getError();
    if (glError !== gl.NO_ERROR) return { error: `WebGL error 0x${glError.toString(16)}` };
    renderer.dispose();
    return { rgb: Array.from(rgb), renderer: name, tiles: Math.ceil(W / tile) * Math.ceil(H / tile), edge: refined };
  } catch (e) {
    return { error: `three.js: ${e.message}` };
  }
};
