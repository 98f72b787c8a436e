// Run the Khronos glTF-Validator on each file given; print one JSON line per
// file ({file, errors, warnings, messages}) and exit 1 if any file has errors.
// Usage: node validate.mjs NODE_DIR FILE...   (NODE_DIR holds node_modules/gltf-validator)
import fs from 'fs';
import path from 'path';
import { createRequire } from 'module';

const [nodeDir, ...files] = process.argv.slice(2);
const require = createRequire(path.resolve(nodeDir) + '/');
const validator = require('gltf-validator');
let bad = 0;
for (const f of files) {
  const dir = path.dirname(path.resolve(f));
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(f)), {
    maxIssues: 100,
    uri: path.basename(f),
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(dir, decodeURIComponent(uri)), (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
      }),
  });
  const errors = report.issues.messages.filter((m) => m.severity === 0);
  console.log(JSON.stringify({ file: f, errors: report.issues.numErrors, warnings: report.issues.numWarnings, messages: errors.slice(0, 10) }));
  if (report.issues.numErrors > 0) bad++;
}
process.exit(bad ? 1 : 0);
