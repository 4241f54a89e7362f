// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors
//
// Validates glTF binary files with the Khronos glTF validator (npm gltf-validator, installed in
// tests/gltf/node_modules by scripts/setup.sh with `npm ci`):
//   node tests/gltf/validate.mjs FILE.glb...
// Prints every message (errors, warnings, infos); exits 1 if any file has an error, 77 (the
// "skipped" code of the CTest test gltf_validator) if the validator is not installed, 2 on usage
// errors. Warnings and infos are allowed.

import { readFile } from 'node:fs/promises';
import { basename } from 'node:path';

let validator;
try {
  validator = await import('gltf-validator');
} catch (error) {
  console.log(`skipped: the npm package gltf-validator is not installed (${error.code ?? error}); ` +
    'run bash scripts/setup.sh (npm ci in tests/gltf)');
  process.exit(77);
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('usage: node validate.mjs FILE.glb...');
  process.exit(2);
}

const severities = ['error', 'warning', 'info', 'hint'];
let failed = false;
console.log(`glTF validator ${validator.version()}`);
for (const file of files) {
  const bytes = new Uint8Array(await readFile(file));
  let report;
  try {
    report = await validator.validateBytes(bytes, { uri: basename(file) });
  } catch (error) {
    console.log(`${file}: the validator could not read it: ${error}`);
    failed = true;
    continue;
  }
  const issues = report.issues;
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
    `${issues.numInfos} infos, ${issues.numHints} hints`);
  for (const m of issues.messages) {
    console.log(`  ${severities[m.severity] ?? m.severity} ${m.code} at ${m.pointer ?? '-'}: ${m.message}`);
  }
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
