// CT: the warped CT (and the input CT when the server could find it) in axial, coronal, sagittal
// or all three planes, with window presets, the tissue map and the displacement, strain or stress
// maps as overlays, and a readout of every shown image's value at the cursor. The maps lie on
// the undeformed CT grid, so they match the input CT; over the warped CT they show where the
// tissue was, not where it went.
import { Niivue, SLICE_TYPE, SHOW_RENDER } from '@niivue/niivue';
import GUI from 'lil-gui';
import { fmt } from './colour.js';

const WINDOWS = { 'soft tissue (W400 L40)': [40, 400], 'breast (W600 L-50)': [-50, 600], 'fat (W200 L-100)': [-100, 200],
  'lung (W1500 L-600)': [-600, 1500], 'bone (W2000 L300)': [300, 2000] };
const OVERLAYS = [
  ['tissue', 'model_labels.nii.gz', 'tissue', 'hsv'],
  ['displacement', 'displacement_mm.nii.gz', 'displacement (mm)', 'warm'],
  ['equivalent strain', 'equivalent_strain.nii.gz', 'equivalent strain', 'plasma'],
  ['von Mises stress', 'von_mises_stress_pa.nii.gz', 'von Mises stress (Pa)', 'hot'],
];

export async function showSlices(section, manifest, report) {
  const has = (name) => manifest.files.includes(`data/${name}`);
  const canvas = Object.assign(document.createElement('canvas'), { className: 'view' });
  section.append(canvas);
  const readout = Object.assign(document.createElement('div'), { className: 'readout' });
  section.append(readout);

  // Backgrounds, first the one shown at start: the warped CT of a simulation, the CT of a phantom.
  const backgrounds = [];
  if (has('warped_ct.nii.gz')) backgrounds.push(['warped CT', 'data/warped_ct.nii.gz']);
  if (manifest.input_ct) backgrounds.push(['input CT', manifest.input_ct]);
  if (has('ct.nii.gz')) backgrounds.push(['CT', 'data/ct.nii.gz']);
  if (!backgrounds.length) throw new Error('no CT image in this folder');
  const overlays = OVERLAYS.filter(([, file]) => has(file));
  if (has('labels.nii.gz') && !has('model_labels.nii.gz')) overlays.unshift(['tissue', 'labels.nii.gz', 'tissue', 'hsv']);

  const nv = new Niivue({ backColor: [0.08, 0.09, 0.11, 1], show3Dcrosshair: false, isColorbar: false, showLegend: false,
    crosshairColor: [1, 0.8, 0.2, 0.6], crosshairWidth: 0.4, crosshairWidthUnit: 'mm', multiplanarShowRender: SHOW_RENDER.NEVER });
  await nv.attachToCanvas(canvas);
  const volumes = [
    ...backgrounds.map(([name, url], i) => ({ url, name: `${name}.nii.gz`, colormap: 'gray', opacity: i === 0 ? 1 : 0, cal_min: -160, cal_max: 240 })),
    ...overlays.map(([, file], i) => ({ url: `data/${file}`, colormap: overlays[i][3], opacity: 0, name: file })),
  ];
  await nv.loadVolumes(volumes);
  nv.setSliceType(SLICE_TYPE.AXIAL);

  let tissueNames = {};
  if (has('summary.json')) {
    const summary = await (await fetch('data/summary.json')).json();
    tissueNames = summary.image_outputs?.model_labels?.values ?? {};
  }
  const params = { image: backgrounds[0][0], view: 'axial', window: Object.keys(WINDOWS)[1], overlay: 'none', opacity: 0.5 };
  const applyWindow = () => {
    const [level, width] = WINDOWS[params.window];
    for (let i = 0; i < backgrounds.length; ++i) {
      nv.volumes[i].cal_min = level - width / 2;
      nv.volumes[i].cal_max = level + width / 2;
    }
    nv.updateGLVolume();
  };
  const applyLayers = () => {
    backgrounds.forEach(([name], i) => nv.setOpacity(i, name === params.image ? 1 : 0));
    overlays.forEach(([name], i) => nv.setOpacity(backgrounds.length + i, name === params.overlay ? params.opacity : 0));
    report.background = params.image;
    report.overlay = params.overlay;
  };
  const views = { axial: SLICE_TYPE.AXIAL, coronal: SLICE_TYPE.CORONAL, sagittal: SLICE_TYPE.SAGITTAL, 'all three': SLICE_TYPE.MULTIPLANAR };
  const gui = new GUI({ container: section, title: 'CT' });
  gui.domElement.style.cssText = 'position:absolute;top:0.5em;right:0.5em';
  gui.add(params, 'image', backgrounds.map(([n]) => n)).onChange(applyLayers);
  gui.add(params, 'view', Object.keys(views)).onChange((v) => nv.setSliceType(views[v]));
  gui.add(params, 'window', Object.keys(WINDOWS)).onChange(applyWindow);
  if (overlays.length) {
    gui.add(params, 'overlay', ['none', ...overlays.map(([n]) => n)]).onChange(applyLayers);
    gui.add(params, 'opacity', 0, 1, 0.05).name('overlay opacity').onChange(applyLayers);
  }
  applyWindow();
  applyLayers();

  nv.onLocationChange = (data) => {
    const mm = data.mm ? `${[...data.mm].slice(0, 3).map((v) => v.toFixed(1)).join(', ')} mm (RAS)` : '';
    const parts = (data.values ?? []).map((v, i) => {
      const value = v.value ?? v;
      if (i < backgrounds.length) return `${backgrounds[i][0]}: ${fmt(Math.round(value))} HU`;
      const [name, file] = overlays[i - backgrounds.length];
      if (file.includes('labels')) return `${name}: ${tissueNames[String(Math.round(value))] ?? Math.round(value)}`;
      return `${name}: ${fmt(value)}`;
    });
    readout.innerHTML = [mm, ...parts].filter(Boolean).join('<br>');
    report.readout = readout.textContent;
  };
  readout.textContent = 'click a slice for values';
  if (manifest.input_ct_note) readout.insertAdjacentHTML('beforeend', `<br><span class="note">${manifest.input_ct_note}</span>`);
  // The canvas is sized by its section, visible only once this tab is shown: size it again now
  // and whenever the window changes.
  nv.resizeListener();
  window.addEventListener('resize', () => nv.resizeListener());
  report.volumes = nv.volumes.map((v) => ({ name: v.name, dims: Array.from(v.hdr.dims.slice(1, 4)) }));
}
