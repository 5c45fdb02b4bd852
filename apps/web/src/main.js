// The page of `voxbreast view`: reads manifest.json (the output folder's kind and the files it
// may fetch, all relative to the page) and builds a tab per view. window.voxbreastView reports
// what was rendered, for the browser tests and for anyone at the console.
import { showMeshes } from './mesh_view.js';
import { showSlices } from './ct_view.js';
import { showNumbers } from './numbers.js';
import { showLive } from './live_view.js';

const state = (window.voxbreastView = { errors: [], pages: {} });
window.addEventListener('error', (e) => state.errors.push(String(e.message)));
window.addEventListener('unhandledrejection', (e) => state.errors.push(String(e.reason)));

export const status = (text) => { document.getElementById('status').textContent = text; };

async function main() {
  if (location.protocol === 'file:') {
    document.getElementById('pages').innerHTML = `<div class="message"><p>This page reads its files over HTTP, which
      browsers refuse to pages opened from disk. In this folder, run</p><pre>python3 -m http.server 8000</pre>
      <p>and open <a href="http://127.0.0.1:8000/">http://127.0.0.1:8000/</a>.</p></div>`;
    state.fileProtocol = true;
    return;
  }
  const response = await fetch('manifest.json');
  if (!response.ok) throw new Error(`manifest.json: HTTP ${response.status}`);
  const manifest = await response.json();
  state.manifest = manifest;
  const has = (name) => manifest.files.includes(`data/${name}`);
  document.title = `VoxBreast view: ${manifest.title}`;
  document.getElementById('title').textContent = `VoxBreast · ${manifest.title} · ${manifest.kind}`;

  const pages = [];
  if (manifest.live) pages.push(['live', 'Live', showLive]);
  if (manifest.files.some((f) => f.endsWith('.vtp'))) pages.push(['3d', '3D', showMeshes]);
  if (has('warped_ct.nii.gz') || has('ct.nii.gz') || manifest.input_ct) pages.push(['ct', 'CT', showSlices]);
  if (!manifest.live) pages.push(['numbers', 'Numbers', showNumbers]);

  const nav = document.getElementById('tabs');
  const main = document.getElementById('pages');
  const sections = {};
  for (const [id, label] of pages) {
    const a = Object.assign(document.createElement('a'), { href: `#${id}`, textContent: label, id: `tab-${id}` });
    nav.append(a);
    sections[id] = Object.assign(document.createElement('section'), { className: 'page', id: `page-${id}` });
    main.append(sections[id]);
  }
  const started = {};
  const show = () => {
    const id = sections[location.hash.slice(1)] ? location.hash.slice(1) : pages[0][0];
    for (const [pid] of pages) {
      sections[pid].classList.toggle('active', pid === id);
      document.getElementById(`tab-${pid}`).classList.toggle('active', pid === id);
    }
    if (!started[id]) {
      const [, label, build] = pages.find(([pid]) => pid === id);
      state.pages[id] = { ready: false };
      started[id] = build(sections[id], manifest, state.pages[id])
        .then(() => { state.pages[id].ready = true; status(''); })
        .catch((e) => {
          state.errors.push(`${label}: ${e.message}`);
          state.pages[id].error = e.message;
          sections[id].insertAdjacentHTML('afterbegin', `<p class="message note">${label}: ${e.message}</p>`);
        });
    }
    window.dispatchEvent(new Event('resize'));
  };
  window.addEventListener('hashchange', show);
  show();
}

main().catch((e) => {
  state.errors.push(e.message);
  document.getElementById('pages').innerHTML = `<p class="message note">${e.message}</p>`;
});
