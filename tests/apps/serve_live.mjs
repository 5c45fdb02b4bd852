// A WebSocket client of `voxbreast serve` (run with --pause-at-step N) that checks the stream:
//   node serve_live.mjs URL OUT.json
// Waits for the frame paused at step N and writes its positions (mm) to OUT.json; then sends a
// malformed, an unknown, an oversized and a valid control (gravity along +x, resume) and checks
// that the first three are refused with an error while the run goes on, and that the surface
// moves towards +x. Prints one "ok"/"FAIL" line per check; exit status 1 when any failed.
import { createRequire } from 'node:module';
import { writeFileSync } from 'node:fs';

const WebSocket = createRequire(new URL('../../apps/web/package.json', import.meta.url))('ws');
const [url, out] = process.argv.slice(2);
let failures = 0;
const check = (ok, what, detail = '') => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}${ok || !detail ? '' : `: ${detail}`}`);
  if (!ok) failures += 1;
};
const base = url.replace(/^http/, 'ws').replace(/\/?(\?.*)?$/, '');
const ws = new WebSocket(`${base}/live`);
const errors = [];
let mesh = null, paused = null, last = null, frames = 0;
const meanX = (x) => { let s = 0; for (let i = 0; i < x.length; i += 3) s += x[i]; return s / (x.length / 3); };
const done = new Promise((resolve) => {
  ws.on('message', (data, binary) => {
    if (!binary) {
      const m = JSON.parse(data.toString());
      if (m.type === 'mesh') mesh = m;
      if (m.error) errors.push(m.error);
      return;
    }
    const b = Buffer.from(data);
    const header = new Float64Array(b.buffer.slice(b.byteOffset, b.byteOffset + 32));
    const x = new Float32Array(b.buffer.slice(b.byteOffset + 32, b.byteOffset + b.length));
    frames += 1;
    last = { step: header[1], paused: header[3], x };
    if (!paused && header[3]) {
      paused = last;
      writeFileSync(out, JSON.stringify({ step: header[1], positions_mm: Array.from(x) }));
      ws.send('{"gravity": [1, 2');
      ws.send(JSON.stringify({ tilt: 3 }));
      ws.send(JSON.stringify({ gravity: [0, 0, -9.81], padding: 'x'.repeat(5000) }));
      ws.send(JSON.stringify({ gravity: [9.81, 0, 0], pause: false }));
    }
    if (paused && header[1] >= paused.step + 4000) resolve();
  });
  ws.on('error', (e) => { check(false, 'WebSocket connection', e.message); resolve(); });
  setTimeout(resolve, 60000);
});
await done;
ws.close();
check(mesh && mesh.triangles.length > 0 && mesh.rest_mm.length > 0, 'mesh message first: triangles and rest positions');
check(paused !== null, 'a frame paused at --pause-at-step', JSON.stringify(last && { step: last.step, paused: last.paused }));
check(errors.length === 3 && errors.some((e) => e.includes('4096')) && errors.some((e) => e.includes('unknown control')),
  'malformed, unknown and oversized controls refused with an error', JSON.stringify(errors));
check(last && paused && last.step >= paused.step + 4000, 'the run went on after the refused controls', JSON.stringify(last && last.step));
const moved = last && paused ? meanX(last.x) - meanX(paused.x) : NaN;
check(moved > 0.05, `gravity along +x moves the surface towards +x (mean x +${moved.toFixed(3)} mm)`);
console.log(`${frames} frames received`);
process.exit(failures ? 1 : 0);
