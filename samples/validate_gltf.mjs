// node validate_gltf.mjs FILE.gltf...: runs the Khronos glTF-Validator (npm package
// `gltf-validator`, a library without a command line) on each file, prints its
// counts and every error and warning, and exits 1 if any file has errors.
import { createRequire } from 'node:module';
import { execSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';

// Resolve the package from the local tree first, then from the global npm root.
const require = createRequire(import.meta.url);
let validator;
try {
  validator = require('gltf-validator');
} catch {
  const globalRoot = execSync('npm root -g', { stdio: ['ignore', 'pipe', 'ignore'] }).toString().trim();
  validator = require(path.join(globalRoot, 'gltf-validator'));
}

let failed = false;
for (const file of process.argv.slice(2)) {
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: file,
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      Promise.resolve(new Uint8Array(fs.readFileSync(path.resolve(path.dirname(file), decodeURIComponent(uri))))),
  });
  const counts = report.issues;
  console.log(`${file}: ${counts.numErrors} errors, ${counts.numWarnings} warnings, ` +
              `${counts.numInfos} infos, ${counts.numHints} hints`);
  for (const message of counts.messages)
    if (message.severity <= 1) console.log(`  ${message.severity === 0 ? 'error' : 'warning'} ${message.code} ${message.pointer ?? ''}: ${message.message}`);
  failed ||= counts.numErrors > 0;
}
process.exit(failed ? 1 : 0);
