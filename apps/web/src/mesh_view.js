// 3D: the rest, deformed and unloaded surfaces and the device tori, in DICOM LPS millimetres, the
// deformed surface coloured by a per-vertex field, tracked points and the tumour centroid with
// their displacement arrows, and the stored frames as a slider.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import GUI from 'lil-gui';
import { parseVtp, parsePvd } from './vtp.js';
import { viridis, rampCss, fmt, unitOf } from './colour.js';

async function fetchText(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
  return r.text();
}

function geometryOf(vtp) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(vtp.positions, 3));
  g.setIndex(new THREE.BufferAttribute(vtp.indices, 1));
  if (vtp.arrays.Normals) g.setAttribute('normal', new THREE.BufferAttribute(Float32Array.from(vtp.arrays.Normals.values), 3));
  else g.computeVertexNormals();
  return g;
}

/// Per-vertex scalar of a point array: its value, or the length of a vector.
function scalarOf(array) {
  const n = array.values.length / array.components;
  const out = new Float32Array(n);
  for (let i = 0; i < n; ++i) {
    let s = 0;
    for (let c = 0; c < array.components; ++c) s += array.values[i * array.components + c] ** 2;
    out[i] = array.components === 1 ? array.values[i] : Math.sqrt(s);
  }
  return out;
}

const FIELD_LABELS = {
  displacement_mm: 'displacement (mm)', equivalent_strain: 'equivalent strain', von_mises_stress_pa: 'von Mises stress (Pa)',
  volumetric_strain: 'volumetric strain',
};

export async function showMeshes(section, manifest, report) {
  const data = (name) => `data/${name}`;
  const has = (name) => manifest.files.includes(data(name));
  const canvas = Object.assign(document.createElement('canvas'), { className: 'view' });
  section.append(canvas);
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x15171c);
  const camera = new THREE.PerspectiveCamera(35, 1, 0.1, 1e5);
  camera.up.set(0, 0, 1);  // LPS: z points superior
  const controls = new OrbitControls(camera, canvas);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  camera.add(sun);
  scene.add(camera);

  const meshes = {};
  const surfaces = [['rest', 'surface_rest.vtp', 0x8890a0, 0.25], ['unloaded', 'surface_unloaded.vtp', 0x5a8fd8, 0.35],
    ['deformed', 'surface.vtp', 0xffffff, 1]];
  let deformed = null;
  for (const [role, file, colour, opacity] of surfaces) {
    if (!has(file)) continue;
    const vtp = parseVtp(await fetchText(data(file)));
    const material = new THREE.MeshStandardMaterial({ color: colour, roughness: 0.7, metalness: 0.0, side: THREE.DoubleSide,
      transparent: opacity < 1, opacity, depthWrite: opacity === 1, vertexColors: role === 'deformed' });
    const mesh = new THREE.Mesh(geometryOf(vtp), material);
    mesh.userData = { vtp, file };
    scene.add(mesh);
    meshes[role] = mesh;
    if (role === 'deformed') deformed = mesh;
  }
  for (const file of manifest.files.filter((f) => /^data\/device_[^/]+\.vtp$/.test(f))) {
    const vtp = parseVtp(await fetchText(file));
    const mesh = new THREE.Mesh(geometryOf(vtp), new THREE.MeshStandardMaterial({ color: 0xd98f3a, roughness: 0.4, metalness: 0.2 }));
    mesh.userData = { vtp, file };
    scene.add(mesh);
    meshes[file.slice(5, -4)] = mesh;
  }
  const main = deformed ?? Object.values(meshes)[0];
  if (!main) throw new Error('no surface mesh in this folder (scene [output] surfaces = true writes them)');

  // The view frames the main surface's bounding box.
  main.geometry.computeBoundingBox();
  const box = main.geometry.boundingBox;
  const centre = box.getCenter(new THREE.Vector3());
  const size = box.getSize(new THREE.Vector3()).length();
  controls.target.copy(centre);
  camera.position.copy(centre).add(new THREE.Vector3(-1.0, -0.6, 0.35).normalize().multiplyScalar(1.8 * size));
  camera.near = size / 100;
  camera.far = size * 100;

  // Colour bar.
  const bar = document.createElement('div');
  bar.className = 'colourbar';
  bar.innerHTML = `<div class="name"></div><div class="ramp" style="background:${rampCss()}"></div><div class="labels"><span class="lo"></span><span class="hi"></span></div>`;
  section.append(bar);
  const legend = Object.assign(document.createElement('div'), { className: 'legend' });
  section.append(legend);

  const params = { field: '', frame: 0, play: false, rest: true, unloaded: true, devices: true, arrows: true };
  const fieldNames = deformed ? Object.keys(deformed.userData.vtp.arrays).filter((n) => n !== 'Normals' && n !== 'element') : [];
  params.field = fieldNames.includes('displacement_mm') ? 'displacement_mm' : fieldNames[0] ?? '';

  const colourBy = (mesh, arrays, name) => {
    const array = arrays[name] ?? arrays.displacement_mm;
    if (!array) return;
    const s = scalarOf(array);
    let lo = Infinity, hi = -Infinity;
    for (const v of s) if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    if (!(hi > lo)) hi = lo + 1;
    const colours = new Float32Array(3 * s.length);
    s.forEach((v, i) => colours.set(viridis((v - lo) / (hi - lo)), 3 * i));
    mesh.geometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
    const shown = arrays[name] ? name : 'displacement_mm';
    bar.querySelector('.name').textContent = FIELD_LABELS[shown] ?? `${shown}${unitOf(shown) ? ` (${unitOf(shown)})` : ''}`;
    bar.querySelector('.lo').textContent = fmt(lo);
    bar.querySelector('.hi').textContent = fmt(hi);
    report.field = { name: shown, min: lo, max: hi };
  };
  if (deformed) colourBy(deformed, deformed.userData.vtp.arrays, params.field);
  else bar.style.display = 'none';

  // Tracked points and the tumour centroid: a sphere at rest, an arrow to the final position.
  const arrows = new THREE.Group();
  scene.add(arrows);
  const mm = (v) => new THREE.Vector3(...v.map((x) => 1000 * x));
  const addArrow = (from, to, colour) => {
    const d = to.clone().sub(from);
    const dot = new THREE.Mesh(new THREE.SphereGeometry(size / 150), new THREE.MeshBasicMaterial({ color: colour }));
    dot.position.copy(from);
    arrows.add(dot);
    if (d.length() > 1e-9) arrows.add(new THREE.ArrowHelper(d.clone().normalize(), from, d.length(), colour, Math.min(d.length() / 3, size / 40), size / 100));
  };
  const lines = [];
  if (has('summary.json')) {
    const summary = await (await fetch(data('summary.json'))).json();
    for (const [name, t] of Object.entries(summary.tracked ?? {})) {
      if (!t.rest_position_m || !t.displacement_m) continue;
      const from = mm(t.rest_position_m);
      addArrow(from, from.clone().add(mm(t.displacement_m)), 0x40e0ff);
      lines.push(`<span style="color:#40e0ff">●</span> ${name}: ${fmt(1000 * t.displacement_norm_m)} mm`);
    }
    const tumour = summary.positioning?.tumour;
    if (tumour?.rest_centroid_m && tumour?.final_centroid_m) {
      addArrow(mm(tumour.rest_centroid_m), mm(tumour.final_centroid_m), 0xff4060);
      lines.push(`<span style="color:#ff4060">●</span> tumour centroid: ${fmt(1000 * tumour.displacement_norm_m)} mm`);
    }
  }
  legend.innerHTML = [`${Object.keys(meshes).join(', ')}`, ...lines].join('<br>') + '<br><small>LPS, mm · drag to turn, wheel to zoom</small>';
  report.arrows = arrows.children.length;

  // Frames: the deformed surface (and the tori) at each stored frame.
  let frames = [];
  if (deformed && has('surface.pvd')) frames = parsePvd(await fetchText(data('surface.pvd')));
  const deviceFrames = {};
  for (const key of Object.keys(meshes).filter((k) => k.startsWith('device_')))
    if (has(`${key}.pvd`)) deviceFrames[key] = parsePvd(await fetchText(data(`${key}.pvd`)));
  const cache = new Map();
  const loadFrame = async (file) => {
    if (!cache.has(file)) cache.set(file, fetchText(data(file)).then(parseVtp));
    return cache.get(file);
  };
  const showFrame = async (i) => {
    const f = frames[i];
    if (!f) return;
    const vtp = await loadFrame(f.file);
    deformed.geometry.attributes.position.array.set(vtp.positions);
    deformed.geometry.attributes.position.needsUpdate = true;
    deformed.geometry.computeVertexNormals();
    colourBy(deformed, vtp.arrays, params.field);
    for (const [key, list] of Object.entries(deviceFrames)) {
      if (!list[i]) continue;
      const dv = await loadFrame(list[i].file);
      meshes[key].geometry.attributes.position.array.set(dv.positions);
      meshes[key].geometry.attributes.position.needsUpdate = true;
    }
    report.frame = i;
    frameLabel.textContent = `frame ${i + 1}/${frames.length}, t = ${fmt(f.time)} s`;
  };
  const frameLabel = document.createElement('div');
  if (frames.length) legend.append(frameLabel);

  const gui = new GUI({ container: section, title: 'View' });
  gui.domElement.style.cssText = 'position:absolute;top:0.5em;right:0.5em';
  if (fieldNames.length) gui.add(params, 'field', fieldNames).name('colour by').onChange((v) => colourBy(deformed, deformed.userData.vtp.arrays, v));
  if (meshes.rest) gui.add(params, 'rest').name('rest surface').onChange((v) => { meshes.rest.visible = v; });
  if (meshes.unloaded) gui.add(params, 'unloaded').name('unloaded surface').onChange((v) => { meshes.unloaded.visible = v; });
  if (Object.keys(deviceFrames).length || Object.keys(meshes).some((k) => k.startsWith('device_')))
    gui.add(params, 'devices').name('device').onChange((v) => { for (const k in meshes) if (k.startsWith('device_')) meshes[k].visible = v; });
  if (arrows.children.length) gui.add(params, 'arrows').name('displacements').onChange((v) => { arrows.visible = v; });
  if (frames.length) {
    params.frame = frames.length - 1;
    gui.add(params, 'frame', 0, frames.length - 1, 1).name('frame').onChange((v) => showFrame(v));
    gui.add(params, 'play').name('play');
    frameLabel.textContent = `frame ${frames.length}/${frames.length} (final), t = ${fmt(frames.at(-1).time)} s`;
  }
  report.frames = frames.length;

  const resize = () => {
    const { clientWidth: w, clientHeight: h } = section;
    if (!w || !h) return;
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  };
  window.addEventListener('resize', resize);
  resize();
  let last = 0;
  renderer.setAnimationLoop((t) => {
    if (!section.classList.contains('active')) return;  // a hidden tab draws nothing
    if (params.play && frames.length && t - last > 250) {
      last = t;
      params.frame = (params.frame + 1) % frames.length;
      gui.controllersRecursive().forEach((c) => c.updateDisplay());
      showFrame(params.frame);
    }
    controls.update();
    renderer.render(scene, camera);
  });

  // What the test compares with the file: the rendered geometry of the main surface.
  const g = main.geometry;
  g.computeBoundingBox();
  report.surface = {
    file: main.userData.file, vertexCount: g.attributes.position.count, triangleCount: g.index.count / 3,
    bboxMin: g.boundingBox.min.toArray(), bboxMax: g.boundingBox.max.toArray(),
  };
  report.meshes = Object.keys(meshes);
}
