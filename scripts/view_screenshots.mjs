// Screenshots of each tab of a running `voxbreast view` page, for the docs (docs/img/view_*.png):
//   build/apps/voxbreast view out/phantom --port 8642 &
//   node scripts/view_screenshots.mjs http://127.0.0.1:8642/ docs/img [SUFFIX]
// Uses Debian's chromium (CHROMIUM overrides the path) through the page's puppeteer-core.
import { createRequire } from 'node:module';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

const puppeteer = createRequire(new URL('../apps/web/package.json', import.meta.url))('puppeteer-core');
const [url, dest, suffix = ''] = process.argv.slice(2);
if (!url || !dest) {
  console.error('usage: node scripts/view_screenshots.mjs URL DEST_DIR [SUFFIX]');
  process.exit(2);
}
const profile = mkdtempSync(join(tmpdir(), 'voxbreast-chromium-'));
const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  // Without --disable-gpu: with it, headless chromium composites a black rectangle over WebGL
  // canvases next to an absolutely placed panel (SwiftShader renders WebGL either way).
  args: ['--no-sandbox', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
    `--user-data-dir=${profile}`],
});
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1000, height: 620 });
  await page.goto(url, { waitUntil: 'load' });
  const tabs = await page.$$eval('nav a', (as) => as.map((a) => a.id.replace('tab-', '')));
  for (const id of tabs) {
    await page.goto('about:blank');  // each tab from a fresh load, the way a link to it opens
    await page.goto(`${url.split('#')[0]}#${id}`, { waitUntil: 'load' });
    await page.waitForFunction((t) => window.voxbreastView?.pages?.[t]?.ready, { timeout: 60000 }, id);
    await new Promise((r) => setTimeout(r, 1000));
    const file = join(dest, `view_${id}${suffix}.png`);
    await page.screenshot({ path: file });
    console.log(`wrote ${file}`);
  }
} finally {
  await browser.close();
  rmSync(profile, { recursive: true, force: true });
}
