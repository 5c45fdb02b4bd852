// Numbers: summary.json as a table, and per folder kind its tables and plots: a sweep's
// metrics.csv and plots/*.png, a probe's force–depth curves and force profile, a fit's regions
// and convergence, a bench's tables and plots. Any other CSV is shown as a table.
import { fmt, unitOf } from './colour.js';

const MAX_ROWS = 200;

export function parseCsv(text) {
  const lines = text.trim().split(/\r?\n/).filter((l) => !l.startsWith('#'));
  const split = (line) => {
    const out = [];
    let cell = '', quoted = false;
    for (const c of line) {
      if (c === '"') quoted = !quoted;
      else if (c === ',' && !quoted) { out.push(cell); cell = ''; } else cell += c;
    }
    out.push(cell);
    return out;
  };
  const header = split(lines[0] ?? '');
  const rows = lines.slice(1).map(split);
  return { header, rows, column: (name) => rows.map((r) => Number(r[header.indexOf(name)])) };
}

function el(tag, props = {}, children = []) {
  const e = Object.assign(document.createElement(tag), props);
  e.append(...children);
  return e;
}

/// Leaves of a JSON object as [dotted key, value]; long arrays shown by their length.
function flatten(value, prefix = '', out = []) {
  if (Array.isArray(value) && value.length > 6) out.push([prefix, `[${value.length} entries]`]);
  else if (Array.isArray(value) && value.every((v) => typeof v !== 'object' || v === null)) out.push([prefix, value.map(fmt).join(', ')]);
  else if (value && typeof value === 'object') {
    for (const [k, v] of Object.entries(value)) flatten(v, prefix ? `${prefix}.${k}` : k, out);
  } else out.push([prefix, value]);
  return out;
}

function keyValueTable(entries) {
  return el('table', { className: 'summary' }, entries.map(([k, v]) => el('tr', {}, [
    el('td', { textContent: k }), el('td', { className: typeof v === 'number' ? 'num' : '', textContent: fmt(v) }),
    el('td', { textContent: unitOf(k.split('.').at(-1)) })])));
}

function csvTable({ header, rows }) {
  const body = rows.slice(0, MAX_ROWS).map((r) => el('tr', {}, r.map((c) => el('td', { className: c !== '' && !Number.isNaN(Number(c)) ? 'num' : '', textContent: c !== '' && !Number.isNaN(Number(c)) ? fmt(Number(c)) : c }))));
  const table = el('table', {}, [el('tr', {}, header.map((h) => el('th', { textContent: h }))), ...body]);
  const wrap = el('div', { style: 'overflow-x:auto' }, [table]);
  if (rows.length > MAX_ROWS) wrap.append(el('p', { textContent: `first ${MAX_ROWS} of ${rows.length} rows` }));
  return wrap;
}

const COLOURS = ['#4cc9f0', '#f72585', '#b5e48c', '#ffb703', '#9d4edd', '#ff6b35', '#2ec4b6', '#e9ecef'];

/// An SVG line plot of series [{ name, x, y }] with labelled axes.
export function linePlot(series, xLabel, yLabel, { width = 520, height = 320 } = {}) {
  const m = { l: 74, r: 12, t: 12, b: 42 };
  const xs = series.flatMap((s) => s.x).filter(Number.isFinite), ys = series.flatMap((s) => s.y).filter(Number.isFinite);
  const [x0, x1] = [Math.min(...xs), Math.max(...xs)], [y0, y1] = [Math.min(0, ...ys), Math.max(...ys)];
  const sx = (x) => m.l + ((x - x0) / (x1 - x0 || 1)) * (width - m.l - m.r);
  const sy = (y) => height - m.b - ((y - y0) / (y1 - y0 || 1)) * (height - m.t - m.b);
  const ticks = (a, b) => [0, 0.25, 0.5, 0.75, 1].map((f) => a + f * (b - a));
  const svg = [`<svg class="plot" width="${width}" height="${height}" xmlns="http://www.w3.org/2000/svg">`,
    `<line x1="${m.l}" y1="${height - m.b}" x2="${width - m.r}" y2="${height - m.b}" stroke="#777"/>`,
    `<line x1="${m.l}" y1="${m.t}" x2="${m.l}" y2="${height - m.b}" stroke="#777"/>`,
    ...ticks(x0, x1).map((x) => `<text x="${sx(x)}" y="${height - m.b + 15}" text-anchor="middle">${fmt(x)}</text>`),
    ...ticks(y0, y1).map((y) => `<text x="${m.l - 5}" y="${sy(y) + 4}" text-anchor="end">${fmt(y)}</text>`),
    `<text x="${(m.l + width - m.r) / 2}" y="${height - 6}" text-anchor="middle">${xLabel}</text>`,
    `<text transform="translate(12 ${(m.t + height - m.b) / 2}) rotate(-90)" text-anchor="middle">${yLabel}</text>`];
  series.forEach((s, i) => {
    const pts = s.x.map((x, k) => [x, s.y[k]]).filter(([x, y]) => Number.isFinite(x) && Number.isFinite(y));
    svg.push(`<polyline fill="none" stroke="${COLOURS[i % COLOURS.length]}" stroke-width="1.6" points="${pts.map(([x, y]) => `${sx(x).toFixed(1)},${sy(y).toFixed(1)}`).join(' ')}"/>`);
    if (series.length > 1 && i < 12) svg.push(`<text x="${width - m.r - 4}" y="${m.t + 12 + 13 * i}" text-anchor="end" fill="${COLOURS[i % COLOURS.length]}" style="fill:${COLOURS[i % COLOURS.length]}">${s.name}</text>`);
  });
  svg.push('</svg>');
  const div = el('div');
  div.innerHTML = svg.join('');
  return div;
}

async function text(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
  return r.text();
}

function probePlots(curves, profile) {
  const plots = el('div', { className: 'plots' });
  if (curves) {
    const press = curves.column('press');
    const series = [...new Set(press)].map((p) => ({
      name: `press ${p}`,
      x: curves.column('depth_mm').filter((_, i) => press[i] === p),
      y: curves.column('press_force_n').filter((_, i) => press[i] === p),
    }));
    plots.append(linePlot(series, 'depth (mm)', 'press force (N)'));
  }
  if (profile) plots.append(linePlot([{ name: 'peak force', x: profile.column('position_mm'), y: profile.column('peak_force_n') }], 'position along the line (mm)', 'peak force (N)'));
  return plots;
}

export async function showNumbers(section, manifest, report) {
  const root = el('div', { className: 'numbers' });
  section.append(root);
  const files = manifest.files.map((f) => f.slice(5));
  const has = (name) => files.includes(name);
  const csvs = {};
  for (const f of files.filter((f) => f.endsWith('.csv') && !f.includes('/'))) csvs[f] = parseCsv(await text(`data/${f}`));
  report.tables = [];

  const section2 = (title, ...content) => { root.append(el('h2', { textContent: title }), ...content); report.tables.push(title); };
  if (manifest.kind === 'probe') section2('Force–depth curves and force profile', probePlots(csvs['probe_curves.csv'], csvs['probe_profile.csv']));
  if (manifest.kind === 'fit' && csvs['history.csv']) {
    const h = csvs['history.csv'];
    const x = h.rows.map((_, i) => i);
    section2('Convergence', el('div', { className: 'plots' }, [linePlot([{ name: 'RMS', x, y: h.column(h.header.find((c) => c.startsWith('rms')) ?? 'rms_mm') }], 'iteration', 'RMS (mm)')]));
  }
  if (manifest.kind === 'sweep' && csvs['metrics.csv']) {
    // The swept keys are the columns between `case` and `status` (docs/SWEEP.md); the metrics
    // that vary over the cases are plotted against the first numeric one.
    const t = csvs['metrics.csv'];
    const numeric = (h) => t.rows.length > 0 && t.column(h).every(Number.isFinite);
    const keys = t.header.slice(1, Math.max(1, t.header.indexOf('status')));
    const parameter = keys.find(numeric);
    const rank = (h) => ['displacement', 'force', 'stress', 'strain', 'steps'].findIndex((w) => h.includes(w));
    const shown = t.header.slice(t.header.indexOf('status') + 1)
      .filter((h) => numeric(h) && new Set(t.column(h)).size > 1 && rank(h) >= 0 && !h.includes('wall_time'))
      .sort((a, b) => rank(a) - rank(b)).slice(0, 8);
    if (parameter && shown.length)
      section2(`Metrics against ${parameter}`, el('div', { className: 'plots' }, shown.map((h) => linePlot([{ name: h, x: t.column(parameter), y: t.column(h) }], parameter, h, { width: 380, height: 260 }))));
  }
  const pngs = files.filter((f) => f.endsWith('.png'));
  if (pngs.length) section2('Plots', el('div', { className: 'plots' }, pngs.map((f) => el('figure', {}, [el('img', { src: `data/${f}`, alt: f }), el('figcaption', { textContent: f })]))));
  for (const json of ['summary.json', 'probe_summary.json', 'haptic_summary.json', 'fit_curve.json', 'bench.json']) {
    if (!has(json)) continue;
    const value = JSON.parse(await text(`data/${json}`));
    section2(json, keyValueTable(flatten(value)));
  }
  for (const [name, table] of Object.entries(csvs)) section2(name, csvTable(table));
  if (!report.tables.length) root.append(el('p', { textContent: 'No numbers in this folder.' }));
}
