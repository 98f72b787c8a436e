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
    const { scene: desc, meshes, size, supersample: k, msaa = 1, glsl, env: envJob } = job;
    const [w, h] = size;
    const W = w * k, H = h * k;
    const canvas = document.createElement('canvas');
    canvas.width = W;
    canvas.height = H;
    document.body.appendChild(canvas);
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
    renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
    const gl = renderer.getContext();
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
    const rt = new THREE.WebGLRenderTarget(W, H, {
      type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true, samples: msaa > 1 ? msaa : 0,
    });
    renderer.setRenderTarget(rt);
    const bg = Array.isArray(desc.background) ? desc.background : [0, 0, 0];
    renderer.setClearColor(new THREE.Color(bg[0] * scale, bg[1] * scale, bg[2] * scale), 1);
    renderer.render(root, camera);
    const buf = new Float32Array(W * H * 4);
    renderer.readRenderTargetPixels(rt, 0, 0, W, H, buf);
    // Box filter K x K in linear light; WebGL rows run bottom-up.
    const rgb = new Array(w * h * 3).fill(0);
    for (let y = 0; y < h; y++) {
      for (let x = 0; x < w; x++) {
        let r = 0, g = 0, b = 0;
        for (let j = 0; j < k; j++) {
          const row = H - 1 - (y * k + j);
          for (let i = 0; i < k; i++) {
            const p = 4 * (row * W + x * k + i);
            r += buf[p]; g += buf[p + 1]; b += buf[p + 2];
          }
        }
        const o = 3 * (y * w + x);
        rgb[o] = r / (k * k); rgb[o + 1] = g / (k * k); rgb[o + 2] = b / (k * k);
      }
    }
    const dbg = gl.getExtension('WEBGL_debug_renderer_info');
    const name = dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
    const glError = gl.getError();
    if (glError !== gl.NO_ERROR) return { error: `WebGL error 0x${glError.toString(16)}` };
    renderer.dispose();
    return { rgb, renderer: name };
  } catch (e) {
    return { error: `three.js: ${e.message}` };
  }
};
