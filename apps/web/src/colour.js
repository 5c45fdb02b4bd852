// A perceptually ordered colour map (viridis, 9 stops, linear between them) for the mesh fields
// and the colour bar that explains it.
const STOPS = [
  [0.267, 0.005, 0.329], [0.283, 0.141, 0.458], [0.254, 0.265, 0.53], [0.207, 0.372, 0.553],
  [0.164, 0.471, 0.558], [0.128, 0.567, 0.551], [0.135, 0.659, 0.518], [0.478, 0.821, 0.318],
  [0.993, 0.906, 0.144],
];

/// The colour of t in [0, 1] (clamped) as [r, g, b] in [0, 1].
export function viridis(t) {
  const x = Math.min(1, Math.max(0, Number.isFinite(t) ? t : 0)) * (STOPS.length - 1);
  const i = Math.min(STOPS.length - 2, Math.floor(x));
  const f = x - i;
  return STOPS[i].map((c, k) => c + f * (STOPS[i + 1][k] - c));
}

export function rampCss() {
  return `linear-gradient(to right, ${STOPS.map((s) => `rgb(${s.map((c) => Math.round(255 * c)).join(',')})`).join(', ')})`;
}

/// A number for a label: 3 significant digits, no exponent between 1e-3 and 1e5.
export function fmt(v) {
  if (v === null || v === undefined) return '—';
  if (typeof v !== 'number') return String(v);
  if (v === 0 || !Number.isFinite(v)) return String(v);
  const a = Math.abs(v);
  return a >= 1e-3 && a < 1e5 ? String(Number(v.toPrecision(4))) : v.toExponential(2);
}

/// The unit a name's suffix states (docs/OUTPUTS.md: names end in their unit).
export function unitOf(name) {
  const units = [['_mm2', 'mm²'], ['_mm', 'mm'], ['_pa', 'Pa'], ['_m_s', 'm/s'], ['_m', 'm'], ['_s', 's'],
    ['_n_per_mm', 'N/mm'], ['_n', 'N'], ['_kg_m3', 'kg/m³'], ['_kg', 'kg'], ['_m3', 'm³'], ['_deg', '°'], ['_hz', 'Hz']];
  for (const [suffix, unit] of units) if (name.endsWith(suffix)) return unit;
  return '';
}
