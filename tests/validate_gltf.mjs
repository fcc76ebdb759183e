// Validates glTF 2.0 files with the Khronos glTF validator (npm package
// gltf-validator, installed by tools/setup.sh into .cache/npm).
//
//   node tests/validate_gltf.mjs [--modules DIR] [--all] FILE.glb|FILE.gltf ...
//
// DIR is the node_modules folder that holds gltf-validator (default: the
// project's .cache/npm/node_modules). External resources (a .gltf's .bin)
// are read from the file's own folder. Prints the counts of errors,
// warnings, infos and hints per file, every error and warning (--all: every
// message), and exits 1
// when any file has an error (2 for bad usage or a missing package).

import { createRequire } from 'node:module';
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
let modules = path.join(here, '..', '.cache', 'npm', 'node_modules');
const files = [];
let all = false;
for (let i = 0; i < args.length; ++i) {
  if (args[i] === '--modules') modules = args[++i];
  else if (args[i] === '--all') all = true;
  else files.push(args[i]);
}
if (files.length === 0 || !modules) {
  console.error('usage: node validate_gltf.mjs [--modules DIR] [--all] FILE.glb|FILE.gltf ...');
  process.exit(2);
}

let validator;
try {
  validator = createRequire(path.join(path.resolve(modules), 'index.js'))('gltf-validator');
} catch (e) {
  console.error(`gltf-validator not found under ${modules}: run tools/setup.sh (${e.message})`);
  process.exit(2);
}

const severities = ['error', 'warning', 'info', 'hint'];
let failed = false;
for (const file of files) {
  const folder = path.dirname(path.resolve(file));
  const report = await validator.validateBytes(new Uint8Array(await readFile(file)), {
    uri: path.basename(file),
    maxIssues: 0,  // all of them
    externalResourceFunction: (uri) =>
      readFile(path.join(folder, decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  const issues = report.issues;
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
              `${issues.numInfos} infos, ${issues.numHints} hints ` +
              `(gltf-validator ${report.validatorVersion})`);
  for (const m of issues.messages) {
    if (m.severity > 1 && !all) continue;
    console.log(`  ${severities[m.severity]} ${m.code} at ${m.pointer ?? m.offset ?? ''}: ${m.message}`);
  }
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
