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

window.sunbeamRender = async (job) => {
  try {
    const { scene: desc, meshes, size, supersample: k, msaa = 1, glsl, env: envJob, tile: tileAsked = 0 } = job;
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
    if (desc.background === 'environment') root.add(environmentBackground(exported, environment, camera, desc.exposure));
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
          }
        }
      }
    }
    if (shifted) camera.setViewOffset(view.fullWidth, view.fullHeight, view.offsetX, view.offsetY, view.width, view.height);
    else camera.clearViewOffset();
    for (let i = 0; i < rgb.length; i++) rgb[i] /= k * k;
    const dbg = gl.getExtension('WEBGL_debug_renderer_info');
    const name = dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
    const glError = gl.getError();
    if (glError !== gl.NO_ERROR) return { error: `WebGL error 0x${glError.toString(16)}` };
    renderer.dispose();
    return { rgb: Array.from(rgb), renderer: name, tiles: Math.ceil(W / tile) * Math.ceil(H / tile) };
  } catch (e) {
    return { error: `three.js: ${e.message}` };
  }
};
