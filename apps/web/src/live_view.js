// Live: the surface of a `voxbreast serve` run as it steps, streamed over a WebSocket (the mesh
// once as JSON, then frames of float32 vertex positions), coloured by displacement from rest,
// with controls for gravity (a posture or any vector), pause and reset.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import GUI from 'lil-gui';
import { viridis, rampCss, fmt } from './colour.js';

export async function showLive(section, manifest, report) {
  const canvas = Object.assign(document.createElement('canvas'), { className: 'view' });
  section.append(canvas);
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x15171c);
  const camera = new THREE.PerspectiveCamera(35, 1, 0.1, 1e5);
  camera.up.set(0, 0, 1);
  const controls = new OrbitControls(camera, canvas);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  camera.add(sun);
  scene.add(camera);
  const legend = Object.assign(document.createElement('div'), { className: 'legend' });
  const bar = Object.assign(document.createElement('div'), { className: 'colourbar' });
  bar.innerHTML = `<div>displacement (mm)</div><div class="ramp" style="background:${rampCss()}"></div><div class="labels"><span>0</span><span class="hi"></span></div>`;
  section.append(legend, bar);

  const url = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/${manifest.live}`;
  const socket = new WebSocket(url);
  socket.binaryType = 'arraybuffer';
  let mesh = null, rest = null;
  report.frames = 0;
  const ready = new Promise((resolve, reject) => {
    socket.onerror = () => reject(new Error(`cannot connect to ${url}`));
    socket.onmessage = (event) => {
      if (typeof event.data === 'string') {
        const message = JSON.parse(event.data);
        if (message.error) { report.lastError = message.error; legend.insertAdjacentHTML('beforeend', `<div class="note">refused: ${message.error}</div>`); return; }
        if (message.type !== 'mesh') return;
        rest = Float32Array.from(message.rest_mm);
        const g = new THREE.BufferGeometry();
        g.setAttribute('position', new THREE.BufferAttribute(Float32Array.from(rest), 3));
        g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(rest.length), 3));
        g.setIndex(message.triangles);
        g.computeVertexNormals();
        mesh = new THREE.Mesh(g, new THREE.MeshStandardMaterial({ vertexColors: true, roughness: 0.7, side: THREE.DoubleSide }));
        scene.add(mesh);
        g.computeBoundingBox();
        const centre = g.boundingBox.getCenter(new THREE.Vector3()), size = g.boundingBox.getSize(new THREE.Vector3()).length();
        controls.target.copy(centre);
        camera.position.copy(centre).add(new THREE.Vector3(-1.0, -0.6, 0.35).normalize().multiplyScalar(1.8 * size));
        camera.near = size / 100; camera.far = size * 100; camera.updateProjectionMatrix();
        [params.gx, params.gy, params.gz] = message.gravity_m_s2;  // the scene's gravity at start
        params.posture = message.posture;
        addControls(message.postures);
        report.vertexCount = rest.length / 3;
        resolve();
        return;
      }
      if (!mesh) return;
      const header = new Float64Array(event.data, 0, 4);
      const x = new Float32Array(event.data, 32);
      const position = mesh.geometry.attributes.position, colour = mesh.geometry.attributes.color;
      position.array.set(x);
      const d = new Float32Array(x.length / 3);
      let hi = 0;
      for (let i = 0; i < d.length; ++i) {
        d[i] = Math.hypot(x[3 * i] - rest[3 * i], x[3 * i + 1] - rest[3 * i + 1], x[3 * i + 2] - rest[3 * i + 2]);
        hi = Math.max(hi, d[i]);
      }
      d.forEach((v, i) => colour.array.set(viridis(v / (hi || 1)), 3 * i));
      position.needsUpdate = colour.needsUpdate = true;
      mesh.geometry.computeVertexNormals();
      bar.querySelector('.hi').textContent = fmt(hi);
      report.frames += 1;
      report.step = header[1];
      report.maxDisplacementMm = hi;
      legend.firstChild.textContent = `step ${header[1]}, t = ${fmt(header[2])} s${header[3] ? ' (paused)' : ''} · frames shown ${report.frames}`;
    };
  });
  legend.append(document.createElement('div'));
  const send = (control) => socket.send(JSON.stringify(control));
  const params = { posture: '', gx: 0, gy: 0, gz: -9.81, pause: false, reset: () => send({ reset: true }) };
  function addControls(postures) {
    const gui = new GUI({ container: section, title: 'Live' });
    gui.domElement.style.cssText = 'position:absolute;top:0.5em;right:0.5em';
    gui.add(params, 'posture', ['', ...postures]).onChange((v) => v && send({ posture: v }));
    const folder = gui.addFolder('gravity vector (m/s², LPS)');
    for (const k of ['gx', 'gy', 'gz']) folder.add(params, k, -9.81, 9.81, 0.01);
    folder.add({ apply: () => send({ gravity: [params.gx, params.gy, params.gz] }) }, 'apply');
    gui.add(params, 'pause').onChange((v) => send({ pause: v }));
    gui.add(params, 'reset');
  }
  const resize = () => {
    const { clientWidth: w, clientHeight: h } = section;
    if (!w || !h) return;
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  };
  window.addEventListener('resize', resize);
  resize();
  renderer.setAnimationLoop(() => { controls.update(); renderer.render(scene, camera); });
  await ready;
}
