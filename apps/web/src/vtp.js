// Reads the VTK XML PolyData (.vtp) files VoxBreast writes: points, triangles (polygons are
// fanned) and point arrays, from inline "binary" (base64, uncompressed, UInt32 or UInt64 length
// header) or "ascii" DataArrays. Appended and compressed data are refused with an error.

const TYPES = {
  Float32: Float32Array, Float64: Float64Array, Int8: Int8Array, UInt8: Uint8Array,
  Int16: Int16Array, UInt16: Uint16Array, Int32: Int32Array, UInt32: Uint32Array,
  Int64: BigInt64Array, UInt64: BigUint64Array,
};

function decodeArray(node, headerBytes) {
  const type = node.getAttribute('type');
  const format = node.getAttribute('format') || 'ascii';
  const Ctor = TYPES[type];
  if (!Ctor) throw new Error(`vtp: unsupported DataArray type ${type}`);
  let values;
  if (format === 'binary') {
    const bin = Uint8Array.from(atob(node.textContent.trim()), (c) => c.charCodeAt(0));
    const view = new DataView(bin.buffer);
    const bytes = headerBytes === 8 ? Number(view.getBigUint64(0, true)) : view.getUint32(0, true);
    values = new Ctor(bin.buffer.slice(headerBytes, headerBytes + bytes));
  } else if (format === 'ascii') {
    const words = node.textContent.trim().split(/\s+/).filter(Boolean);
    values = Ctor === BigInt64Array || Ctor === BigUint64Array
      ? new Ctor(words.map((w) => BigInt(w)))
      : new Ctor(words.map(Number));
  } else {
    throw new Error(`vtp: DataArray format "${format}" is not supported (inline binary or ascii only)`);
  }
  // Indices as plain numbers: 64-bit ints are only ever connectivity and offsets here.
  if (values instanceof BigInt64Array || values instanceof BigUint64Array) values = Float64Array.from(values, Number);
  return { name: node.getAttribute('Name') || '', components: Number(node.getAttribute('NumberOfComponents') || 1), values };
}

/// Parses the text of a .vtp file into { positions (Float32Array, 3 per point, file units),
/// indices (Uint32Array, 3 per triangle), arrays: { name: { components, values } } }.
export function parseVtp(text) {
  const doc = new DOMParser().parseFromString(text, 'application/xml');
  const root = doc.querySelector('VTKFile');
  if (!root || root.getAttribute('type') !== 'PolyData') throw new Error('vtp: not a VTK PolyData file');
  if (root.getAttribute('compressor')) throw new Error('vtp: compressed files are not supported');
  if ((root.getAttribute('byte_order') || 'LittleEndian') !== 'LittleEndian') throw new Error('vtp: big-endian data');
  const headerBytes = root.getAttribute('header_type') === 'UInt64' ? 8 : 4;
  const piece = root.querySelector('Piece');
  const points = decodeArray(piece.querySelector('Points > DataArray'), headerBytes);
  const polys = {};
  for (const a of piece.querySelectorAll('Polys > DataArray')) polys[a.getAttribute('Name')] = decodeArray(a, headerBytes).values;
  const tri = [];
  if (polys.connectivity && polys.offsets) {
    let start = 0;
    for (const end of polys.offsets) {
      for (let k = start + 1; k + 1 < end; ++k) tri.push(polys.connectivity[start], polys.connectivity[k], polys.connectivity[k + 1]);
      start = end;
    }
  }
  const arrays = {};
  for (const a of piece.querySelectorAll('PointData > DataArray')) {
    const d = decodeArray(a, headerBytes);
    arrays[d.name] = d;
  }
  return { positions: Float32Array.from(points.values), indices: Uint32Array.from(tri), arrays };
}

/// The datasets of a .pvd time series: [{ time, file }] in file order.
export function parsePvd(text) {
  const doc = new DOMParser().parseFromString(text, 'application/xml');
  return [...doc.querySelectorAll('DataSet')].map((d) => ({ time: Number(d.getAttribute('timestep')), file: d.getAttribute('file') }));
}
