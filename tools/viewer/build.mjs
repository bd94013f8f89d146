// Bundles src/viewer.js with three.js (its GLTFLoader, meshopt decoder and OrbitControls), at the versions
// package-lock.json pins, into ONE classic script, dist/growbench-viewer.js: the only form of script a page
// opened from file:// can load from another file in Chromium (module scripts are fetched with CORS, which
// file:// pages, of origin "null", cannot pass). The report copies it once into REPORT/viewer/.
//   node tools/viewer/build.mjs            (after `npm ci` in tools/viewer)
import { build } from 'esbuild';
import { readFileSync, mkdirSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const version = name => JSON.parse(readFileSync(join(here, 'node_modules', name, 'package.json'), 'utf8')).version;
mkdirSync(join(here, 'dist'), { recursive: true });
const t0 = performance.now();
const result = await build({
  entryPoints: [join(here, 'src', 'viewer.js')],
  outfile: join(here, 'dist', 'growbench-viewer.js'),
  bundle: true,
  format: 'iife',        // a classic script: no import/export left
  minify: true,
  target: ['es2020'],
  legalComments: 'eof',  // three's and meshoptimizer's MIT notices stay in the file
  banner: { js: `/* growbench report viewer: three ${version('three')} (MIT), bundled by esbuild ${version('esbuild')}. Source: tools/viewer/src/viewer.js */` },
  metafile: true,
  logLevel: 'warning',
});
const out = Object.entries(result.metafile.outputs)[0];
// The notices of what the bundle holds: three.js, and the meshopt decoder three ships (meshoptimizer's).
const meshopt = readFileSync(join(here, 'node_modules', 'three', 'examples', 'jsm', 'libs', 'meshopt_decoder.module.js'), 'utf8')
  .split('\n').filter(l => l.startsWith('//')).slice(0, 2).join('\n');
writeFileSync(join(here, 'dist', 'THIRD-PARTY.txt'),
  `growbench-viewer.js bundles three.js ${version('three')} (with its GLTFLoader, OrbitControls and meshopt decoder):\n\n` +
  readFileSync(join(here, 'node_modules', 'three', 'LICENSE'), 'utf8') + `\nThe meshopt decoder (three/examples/jsm/libs/meshopt_decoder.module.js):\n${meshopt}\n`);
console.log(`build.mjs: ${out[0]} ${out[1].bytes} bytes in ${Math.round(performance.now() - t0)} ms`);
