// Bundles the page of `voxbreast view` into one folder: node build.mjs OUT_DIR
// (CMake runs it into build/apps/web, next to the voxbreast executable). No CDN: everything the
// page loads is in OUT_DIR.
import * as esbuild from 'esbuild';
import { copyFileSync, mkdirSync } from 'node:fs';
import { join } from 'node:path';

const out = process.argv[2];
if (!out) {
  console.error('usage: node build.mjs OUT_DIR');
  process.exit(2);
}
mkdirSync(out, { recursive: true });
await esbuild.build({
  entryPoints: ['src/main.js'],
  bundle: true,
  format: 'esm',
  minify: true,
  sourcemap: false,
  target: 'es2022',
  outfile: join(out, 'view.js'),
  logLevel: 'warning',
  legalComments: 'linked',
});
for (const f of ['index.html', 'style.css']) copyFileSync(join('src', f), join(out, f));
