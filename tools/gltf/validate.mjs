// Validates .glb files with the Khronos glTF validator (the version pinned in package-lock.json): prints a
// line per file with its error, warning and info counts, and every error and warning; exits 1 when any
// file has an error, or when no file was given (a check that validated nothing must not pass).
//   node tools/gltf/validate.mjs FILE.glb...
import { readFileSync } from 'node:fs';
import { validateBytes, version } from 'gltf-validator';

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('validate.mjs: no .glb files given');
  process.exit(1);
}
let failed = 0;
for (const file of files) {
  const report = await validateBytes(new Uint8Array(readFileSync(file)), { maxIssues: 50 });
  const i = report.issues;
  console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos (gltf-validator ${version()})`);
  for (const m of i.messages)
    if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} at ${m.pointer ?? ''}: ${m.message}`);
  if (i.numErrors > 0) failed += 1;
}
if (failed > 0) {
  console.error(`validate.mjs: ${failed} of ${files.length} files have errors`);
  process.exit(1);
}
