// A static server for the web viewer (index.html) and the demo's outputs:
//
//   node serve.mjs [ROOT] [--port N]
//
// ROOT defaults to examples/ (this folder's parent), so that
// http://127.0.0.1:PORT/threejs/index.html finds ../out/ (make demo's outputs)
// and ./node_modules (npm install here). Loopback only; no directory listings.
import { createServer } from 'node:http';
import { createReadStream, statSync } from 'node:fs';
import { dirname, extname, join, normalize, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
let root = resolve(here, '..');
let port = 8765;
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--port') port = Number(args[++i]);
  else root = resolve(args[i]);
}
const types = {
  '.html': 'text/html', '.mjs': 'text/javascript', '.js': 'text/javascript', '.json': 'application/json',
  '.glb': 'model/gltf-binary', '.ktx2': 'image/ktx2', '.frag': 'text/plain', '.png': 'image/png',
};

export function startServer(dir, p = 0) {
  const server = createServer((req, res) => {
    const path = normalize(decodeURIComponent(new URL(req.url, 'http://x').pathname));
    const file = join(dir, path);
    let st;
    try { st = statSync(file); } catch { st = null; }
    if (!file.startsWith(dir) || !st || !st.isFile()) {
      res.writeHead(path === '/favicon.ico' ? 204 : 404);
      res.end();
      return;
    }
    res.writeHead(200, { 'content-type': types[extname(file)] ?? 'application/octet-stream', 'content-length': st.size });
    createReadStream(file).pipe(res);
  });
  return new Promise((ok) => server.listen(p, '127.0.0.1', () => ok(server)));
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const server = await startServer(root, port);
  console.log(`serving ${root} at http://127.0.0.1:${server.address().port}/threejs/index.html`);
}
