// Drives Debian's chromium (headless, through puppeteer-core) over the page of `voxbreast view`
// and checks what it rendered against expectations computed from the files by another reader.
//   node view_browser.mjs URL EXPECTED.json [SCREENSHOT_DIR]
// EXPECTED.json: { "surface": { "vertices", "triangles", "bbox_min", "bbox_max" } | null,
//                  "ct": { "dims" } | null, "tables": [titles the Numbers page must show],
//                  "live": true for a `voxbreast serve` page }
// Prints one "ok"/"FAIL" line per check; exit status 1 when any failed.
import { createRequire } from 'node:module';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

// puppeteer-core is one of the page's npm packages (apps/web/node_modules, pinned by its lock file).
const puppeteer = createRequire(new URL('../../apps/web/package.json', import.meta.url))('puppeteer-core');
const [url, expectedFile, shots] = process.argv.slice(2);
const expected = JSON.parse(readFileSync(expectedFile, 'utf8'));
let failures = 0;
const check = (ok, what, detail = '') => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}${ok || !detail ? '' : `: ${detail}`}`);
  if (!ok) failures += 1;
};

const profile = mkdtempSync(join(tmpdir(), 'voxbreast-chromium-'));
const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
    `--user-data-dir=${profile}`],
});
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1000, height: 640 });
  const consoleErrors = [];
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => consoleErrors.push(String(e)));
  const failedRequests = [];
  page.on('requestfailed', (r) => failedRequests.push(r.url()));
  page.on('response', (r) => { if (r.status() >= 400) failedRequests.push(`${r.status()} ${r.url()}`); });

  /// Mean and standard deviation of the grey levels of a screenshot of an element, and how many
  /// distinct levels it has (a blank canvas has one). A screenshot, not a read of the canvas:
  /// WebGL canvases without preserveDrawingBuffer read back empty after compositing.
  const pixelSpread = async (selector) => {
    const png = await (await page.$(selector)).screenshot({ encoding: 'base64' });
    return page.evaluate(async (data) => {
      const img = new Image();
      img.src = `data:image/png;base64,${data}`;
      await img.decode();
      const copy = document.createElement('canvas');
      copy.width = img.width; copy.height = img.height;
      const ctx = copy.getContext('2d');
      ctx.drawImage(img, 0, 0);
      const d = ctx.getImageData(0, 0, copy.width, copy.height).data;
      let s = 0, s2 = 0; const n = d.length / 4; const grey = new Set();
      for (let i = 0; i < d.length; i += 4) { const g = (d[i] + d[i + 1] + d[i + 2]) / 3; s += g; s2 += g * g; grey.add(Math.round(g)); }
      const mean = s / n;
      return { mean, std: Math.sqrt(Math.max(0, s2 / n - mean * mean)), levels: grey.size };
    }, png);
  };
  const open = async (hash) => {
    await page.goto(`${url.split('#')[0]}#${hash}`, { waitUntil: 'load', timeout: 60000 });
    await page.waitForFunction((id) => window.voxbreastView?.pages?.[id]?.ready || window.voxbreastView?.pages?.[id]?.error
      || window.voxbreastView?.errors?.length, { timeout: 60000 }, hash);
    await new Promise((r) => setTimeout(r, 800));  // a few animation frames
    return page.evaluate((id) => ({ report: window.voxbreastView.pages[id], errors: window.voxbreastView.errors }), hash);
  };
  const near = (a, b, tol) => a.length === b.length && a.every((v, i) => Math.abs(v - b[i]) <= tol);

  if (expected.surface) {
    const { report, errors } = await open('3d');
    check(report?.ready && errors.length === 0, '3D page loads', JSON.stringify({ report, errors }));
    const s = report?.surface ?? {};
    check(s.vertexCount === expected.surface.vertices && s.triangleCount === expected.surface.triangles,
      `rendered surface has the .vtp's ${expected.surface.vertices} vertices and ${expected.surface.triangles} triangles`, JSON.stringify(s));
    check(near(s.bboxMin ?? [], expected.surface.bbox_min, 1e-3) && near(s.bboxMax ?? [], expected.surface.bbox_max, 1e-3),
      "rendered surface's bounding box equals the .vtp's", JSON.stringify([s.bboxMin, s.bboxMax, expected.surface]));
    if (expected.surface.arrows) check(report?.arrows >= expected.surface.arrows, 'tracked points and tumour centroid drawn', report?.arrows);
    if (expected.surface.frames) check(report?.frames === expected.surface.frames, `frame slider has the .pvd's ${expected.surface.frames} frames`, report?.frames);
    const px = await pixelSpread('#page-3d canvas');
    check(px.std > 8 && px.levels > 20, '3D canvas is not blank', JSON.stringify(px));
    if (shots) await page.screenshot({ path: join(shots, 'view_3d.png') });
  }
  if (expected.ct) {
    const { report, errors } = await open('ct');
    check(report?.ready && errors.length === 0, 'CT page loads', JSON.stringify({ report, errors }));
    const first = report?.volumes?.[0];
    check(first?.name?.startsWith('warped CT') && report?.background === 'warped CT', 'CT page shows the warped CT first', JSON.stringify(report));
    check(first && near(first.dims, expected.ct.dims, 0), `warped CT has the file's dimensions ${expected.ct.dims}`, JSON.stringify(first));
    const px = await pixelSpread('#page-ct canvas');
    check(px.std > 8 && px.levels > 20, 'CT canvas is not blank', JSON.stringify(px));
    // A click on the slices fills the readout with the HU under the cursor.
    const box = await (await page.$('#page-ct canvas')).boundingBox();
    await page.mouse.click(box.x + box.width * 0.25, box.y + box.height * 0.3);
    await new Promise((r) => setTimeout(r, 300));
    const readout = await page.evaluate(() => window.voxbreastView.pages.ct.readout ?? '');
    check(/warped CT: -?\d+ HU/.test(readout), 'cursor readout shows HU', readout);
    if (shots) await page.screenshot({ path: join(shots, 'view_ct.png') });
  }
  if (expected.live) {
    const { report, errors } = await open('live');
    check(report?.ready && errors.length === 0, 'Live page connects', JSON.stringify({ report, errors }));
    await new Promise((r) => setTimeout(r, 1500));
    const later = await page.evaluate(() => window.voxbreastView.pages.live);
    check(later.frames > 1 && later.vertexCount > 0, `Live page shows streamed frames (${later.frames} frames, step ${later.step})`, JSON.stringify(later));
    const px = await pixelSpread('#page-live canvas');
    check(px.std > 8 && px.levels > 20, 'Live canvas is not blank', JSON.stringify(px));
    if (shots) await page.screenshot({ path: join(shots, 'view_live.png') });
  } else {
    const { report, errors } = await open('numbers');
    check(report?.ready && errors.length === 0, 'Numbers page loads', JSON.stringify({ report, errors }));
    for (const t of expected.tables ?? []) check(report?.tables?.includes(t), `Numbers page shows ${t}`, JSON.stringify(report?.tables));
    if (shots) await page.screenshot({ path: join(shots, `view_numbers${expected.shot_suffix ?? ''}.png`), fullPage: false });
  }
  check(consoleErrors.length === 0, 'no console errors', consoleErrors.join(' | '));
  check(failedRequests.length === 0, 'no failed requests', failedRequests.join(' | '));
} finally {
  await browser.close();
  rmSync(profile, { recursive: true, force: true });
}
process.exit(failures ? 1 : 0);
