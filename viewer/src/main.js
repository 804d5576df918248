// main.js - the viewer `radiosity view` embeds in its HTML page: reads the lit mesh and the
// surface table from the page's data blocks, shows the mesh with three.js (orbit, and a
// walk with the keyboard), an exposure slider, tone mapping, false colour of radiance or
// illuminance with its legend, and what a click picks; the optional views are modules of
// their own (viewfactor_row.js, compare.js, grid.js: more choices of what to show; edges.js:
// lines on demand). Not a glTF viewer for other files: glb.js reads only radiosity's lit mesh.

import {
  BufferAttribute, BufferGeometry, Color, Mesh, PerspectiveCamera, Raycaster, Scene,
  Vector2, Vector3, WebGLRenderer, LinearSRGBColorSpace,
} from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { decodeBase64 } from './base64.js';
import { parseLitMesh } from './glb.js';
import { formatValue, luminanceAt, luminanceRange, scaleColour, SCALE_COLOURS, tickValues } from './false_colour.js';
import { createViewFactorRow } from './viewfactor_row.js';
import { createCompare } from './compare.js';
import { createGrid } from './grid.js';
import { createEdges } from './edges.js';
import {
  litMeshMaterial, MODE_COLOUR, MODE_FALSE_ILLUMINANCE, MODE_FALSE_RADIANCE, TONE_ACES,
  TONE_CLAMP, TONE_REINHARD,
} from './shader.js';
import { STYLE } from './style.js';
import { startPlayback } from './playback.js';

function element(tag, attributes = {}, text = '') {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attributes)) e.setAttribute(k, v);
  if (text) e.textContent = text;
  return e;
}

function embedded(id) {
  const block = document.getElementById(id);
  return block ? block.textContent : null;
}

function showError(message) {
  const box = element('div', { id: 'error' }, `radiosity view: ${message}`);
  document.body.appendChild(box);
}

// The area in the scene's units (and in m^2 when the unit is known).
function formatArea(area, unitMetres) {
  const text = `${Number(area.toPrecision(6))} units²`;
  return unitMetres > 0 ? `${Number((area * unitMetres * unitMetres).toPrecision(6))} m² (${text})` : text;
}

function formatRgb(rgb) {
  return rgb.map((x) => formatValue(x)).join(', ');
}

function defaultCamera(info, geometry) {
  geometry.computeBoundingSphere();
  const sphere = geometry.boundingSphere;
  if (info.camera) {
    const c = info.camera;
    return { eye: new Vector3(...c.eye), target: new Vector3(...c.target), up: new Vector3(...c.up), fov: c.fov };
  }
  const fov = 40;
  const distance = sphere.radius / Math.sin((fov / 2) * Math.PI / 180);
  return {
    eye: sphere.center.clone().add(new Vector3(0, 0, -distance)),
    target: sphere.center.clone(),
    up: new Vector3(0, 1, 0),
    fov,
  };
}

function start() {
  const style = element('style');
  style.textContent = STYLE;
  document.head.appendChild(style);

  const info = JSON.parse(embedded('radiosity-info') || '{}');
  const mesh = parseLitMesh(decodeBase64(embedded('radiosity-glb') || ''));
  const surfaceText = embedded('radiosity-triangle-surface');
  const triangleSurface = surfaceText ? new Uint32Array(decodeBase64(surfaceText).buffer) : null;
  const triangles = mesh.index.length / 3;
  if (triangleSurface && triangleSurface.length !== triangles)
    throw new Error(`the surface table has ${triangleSurface.length} triangles, the mesh ${triangles}`);
  const patchText = embedded('radiosity-triangle-patch');
  const trianglePatch = patchText ? new Uint32Array(decodeBase64(patchText).buffer) : null;
  if (trianglePatch && trianglePatch.length !== triangles)
    throw new Error(`the patch table has ${trianglePatch.length} triangles, the mesh ${triangles}`);

  const geometry = new BufferGeometry();
  geometry.setAttribute('position', new BufferAttribute(mesh.position, 3));
  geometry.setAttribute('radiance', new BufferAttribute(mesh.radiance, 3));
  geometry.setAttribute('illuminance',
    new BufferAttribute(mesh.illuminance || new Float32Array(mesh.position.length), 3));
  geometry.setIndex(new BufferAttribute(mesh.index, 1));
  const material = litMeshMaterial();
  const object = new Mesh(geometry, material);
  const scene = new Scene();
  scene.background = new Color(0x000000);
  scene.add(object);

  const ranges = {
    [MODE_FALSE_RADIANCE]: luminanceRange(mesh.radiance),
    [MODE_FALSE_ILLUMINANCE]: mesh.illuminance ? luminanceRange(mesh.illuminance) : null,
  };
  const autoScale = Number(mesh.extras.exposure_scale) > 0 ? Number(mesh.extras.exposure_scale) : 1;

  // the page: the canvas, and the panel on its right
  const view = element('div', { id: 'view' });
  const panel = element('div', { id: 'panel' });
  document.body.append(view, panel);
  const renderer = new WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.outputColorSpace = LinearSRGBColorSpace; // the shader encodes sRGB itself
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  view.appendChild(renderer.domElement);

  const initial = defaultCamera(info, geometry);
  // near and far bound the depth buffer's resolution: at 1 % of the scene's radius the
  // Cornell box's light, 0.1 mm below its ceiling, does not fight it at 1 m
  const camera = new PerspectiveCamera(initial.fov, 1, geometry.boundingSphere.radius * 0.01,
    geometry.boundingSphere.radius * 20);
  camera.position.copy(initial.eye);
  camera.up.copy(initial.up);
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.copy(initial.target);
  controls.update();

  panel.appendChild(element('h1', {}, 'radiosity'));
  panel.appendChild(element('div', { class: 'source' }, info.source || 'lit mesh'));
  panel.appendChild(element('div', { class: 'stats' },
    `${triangles} triangles, ${mesh.position.length / 3} vertices`));

  const modeSelect = element('select', { id: 'mode' });
  modeSelect.append(element('option', { value: MODE_COLOUR }, 'radiance (colour)'),
    element('option', { value: MODE_FALSE_RADIANCE }, 'radiance, false colour'));
  if (mesh.illuminance)
    modeSelect.append(element('option', { value: MODE_FALSE_ILLUMINANCE }, 'illuminance, false colour'));
  const toneSelect = element('select', { id: 'tone' });
  toneSelect.append(element('option', { value: TONE_CLAMP }, 'clamp (as PNG)'),
    element('option', { value: TONE_REINHARD }, 'Reinhard'),
    element('option', { value: TONE_ACES }, 'ACES filmic'));
  const exposure = element('input', { id: 'exposure', type: 'range', min: '-8', max: '8', step: '0.1', value: '0' });
  const exposureText = element('span', { id: 'exposure-value' }, '0.0 EV');
  const logBox = element('input', { id: 'log', type: 'checkbox' });
  const row = (label, ...controlsOf) => {
    const r = element('div', { class: 'row' });
    r.append(element('label', {}, label), ...controlsOf);
    panel.appendChild(r);
    return r;
  };
  row('show', modeSelect);
  const toneRow = row('tone mapping', toneSelect);
  const exposureRow = row('exposure', exposure, exposureText);
  const logRow = row('log scale', logBox);

  // the optional views: each adds its choices to "show", its objects to the scene
  const context = { info, mesh, geometry, material, triangleSurface, trianglePatch, scene, panel, element, embedded, row };
  const features = [createViewFactorRow(context), createCompare(context), createGrid(context)].filter(Boolean);
  for (const feature of features)
    for (const choice of feature.modes) modeSelect.append(element('option', { value: choice.value }, choice.label));
  createEdges(context, () => render());

  const legend = element('div', { id: 'legend' });
  const legendTitle = element('div', { id: 'legend-title' });
  const legendBody = element('div', { class: 'legend-body' });
  const bar = element('canvas', { id: 'legend-bar', width: '24', height: '200' });
  const ticks = element('div', { id: 'legend-ticks' });
  legendBody.append(bar, ticks);
  legend.append(legendTitle, legendBody);
  panel.appendChild(legend);
  const barContext = bar.getContext('2d');
  // the legend: its title, the bar of the scale's colours, and ticks from lo to hi
  function drawLegend({ title, lo, hi, log = false, colours = SCALE_COLOURS, ticks: count }) {
    for (let y = 0; y < 200; y++) {
      const c = scaleColour(colours, 1 - y / 199).map((a) => Math.round(255 * a));
      barContext.fillStyle = `rgb(${c.join(',')})`;
      barContext.fillRect(0, y, 24, 1);
    }
    legendTitle.textContent = title;
    ticks.replaceChildren(...tickValues(lo, hi, log, count).reverse().map((v) =>
      element('div', { class: 'tick', 'data-value': String(v) }, formatValue(v))));
  }

  const picked = element('div', { id: 'picked' }, 'click a surface to see what it is');
  panel.appendChild(picked);
  panel.appendChild(element('div', { class: 'help' },
    'drag: orbit · right-drag: pan · wheel: zoom · W A S D / arrows: walk · Q E: down, up'));

  function update() {
    // a feature's view: its objects shown, maybe the lit mesh hidden, its legend
    let shown = null;
    for (const feature of features) shown = feature.show(modeSelect.value) || shown;
    object.visible = !(shown && shown.hideMesh);
    const mode = shown ? (shown.colour ? MODE_COLOUR : -1) : Number(modeSelect.value);
    material.uniforms.mode.value = mode;
    material.uniforms.tone.value = Number(toneSelect.value);
    material.uniforms.scale.value = autoScale * Math.pow(2, Number(exposure.value));
    exposureText.textContent = `${Number(exposure.value).toFixed(1)} EV`;
    const falseColour = mode !== MODE_COLOUR;
    toneRow.hidden = exposureRow.hidden = falseColour;
    logRow.hidden = !falseColour || Boolean(shown);
    legend.hidden = !falseColour && !(shown && shown.legend);
    if (shown && shown.legend) {
      drawLegend(shown.legend);
    } else if (falseColour) {
      const range = ranges[mode];
      const log = logBox.checked && range.hi > 0;
      const lo = log ? range.positive : range.lo;
      material.uniforms.lo.value = lo;
      material.uniforms.hi.value = range.hi;
      material.uniforms.logScale.value = log;
      drawLegend({
        title: mode === MODE_FALSE_ILLUMINANCE
          ? `illuminance (${info.illuminance_unit || 'lux'})`
          : `radiance, luminance (${info.radiance_unit || 'cd/m²'})`,
        lo, hi: range.hi, log,
      });
    }
    render();
  }

  function resize() {
    const width = Math.max(1, view.clientWidth), height = Math.max(1, view.clientHeight);
    renderer.setSize(width, height);
    camera.aspect = width / height;
    camera.updateProjectionMatrix();
    render();
  }

  let pending = false;
  function render() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      renderer.render(scene, camera);
      if (!document.body.dataset.firstFrameMs) // since navigation began: the load time
        document.body.dataset.firstFrameMs = performance.now().toFixed(0);
      document.body.dataset.frames = String(Number(document.body.dataset.frames || 0) + 1);
    });
  }

  // picking: the surface of the triangle under the pointer
  const raycaster = new Raycaster();
  let down = null;
  renderer.domElement.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
  renderer.domElement.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return; // a drag
    const rect = renderer.domElement.getBoundingClientRect();
    const ndc = new Vector2(((e.clientX - rect.left) / rect.width) * 2 - 1,
      -((e.clientY - rect.top) / rect.height) * 2 + 1);
    raycaster.setFromCamera(ndc, camera);
    const hit = raycaster.intersectObject(object, false)[0];
    showPicked(hit);
  });

  function showPicked(hit) {
    picked.replaceChildren();
    const line = (label, value, field) => {
      const r = element('div', { class: 'field' });
      r.append(element('span', { class: 'label' }, label), element('span', { 'data-field': field }, value));
      picked.appendChild(r);
    };
    // the features' own lines (a grid square above the mesh, a view-factor row), after the
    // surface's: a grid square is picked even with nothing behind it
    const extra = [];
    let changed = false;
    for (const feature of features)
      changed = feature.pick(modeSelect.value, hit, (...a) => extra.push(a), raycaster) || changed;
    if (changed) update();
    if (!hit) {
      for (const a of extra) line(...a);
      if (!extra.length) picked.textContent = 'nothing there';
      picked.dataset.surface = '';
      return;
    }
    const face = hit.faceIndex;
    const corner = [0, 1, 2].map((k) => mesh.index[3 * face + k]);
    const here = (rgb) => {
      // the value at the hit point: the vertices' values by barycentric weights
      const w = [hit.barycoord ? hit.barycoord.x : 1 / 3, hit.barycoord ? hit.barycoord.y : 1 / 3,
        hit.barycoord ? hit.barycoord.z : 1 / 3];
      return corner.reduce((sum, v, k) => sum + w[k] * luminanceAt(rgb, v), 0);
    };
    const surface = triangleSurface && info.surfaces ? info.surfaces[triangleSurface[face]] : null;
    if (surface) {
      line('surface', surface.name, 'name');
      line('area', formatArea(surface.area, info.unit_metres || 0), 'area');
      line('material', surface.material, 'material');
      line('mean radiance', `${formatRgb(surface.radiance)} (luminance ${formatValue(
        luminanceAt(surface.radiance, 0))}) ${info.radiance_unit || 'cd/m²'}`, 'radiance');
    } else {
      line('surface', 'no surface names in a lit mesh file: `radiosity view SCENE` embeds them', 'name');
    }
    line('here: luminance', `${formatValue(here(mesh.radiance))} ${info.radiance_unit || 'cd/m²'}`, 'point-radiance');
    if (mesh.illuminance)
      line('here: illuminance', `${formatValue(here(mesh.illuminance))} ${info.illuminance_unit || 'lux'}`, 'point-illuminance');
    for (const a of extra) line(...a);
    picked.dataset.surface = surface ? surface.name : '';
  }

  // walking: the keys move the eye and the orbit's centre together, in the view's plane
  const walkStep = geometry.boundingSphere.radius * 0.02;
  window.addEventListener('keydown', (e) => {
    if (e.target instanceof HTMLInputElement || e.target instanceof HTMLSelectElement) return;
    const forward = new Vector3().subVectors(controls.target, camera.position);
    forward.sub(camera.up.clone().multiplyScalar(forward.dot(camera.up))).normalize();
    const right = new Vector3().crossVectors(forward, camera.up).normalize();
    const move = new Vector3();
    const key = e.key.toLowerCase();
    if (key === 'w' || key === 'arrowup') move.copy(forward);
    else if (key === 's' || key === 'arrowdown') move.copy(forward).negate();
    else if (key === 'd' || key === 'arrowright') move.copy(right);
    else if (key === 'a' || key === 'arrowleft') move.copy(right).negate();
    else if (key === 'e') move.copy(camera.up);
    else if (key === 'q') move.copy(camera.up).negate();
    else return;
    move.multiplyScalar(walkStep);
    camera.position.add(move);
    controls.target.add(move);
    controls.update();
    render();
  });

  const recordText = embedded('radiosity-record'); // `view SCENE --record FILE`: playback.js
  if (recordText) startPlayback({ recordText, trianglePatchText: embedded('radiosity-triangle-patch'),
    mesh, scene, object, material, panel, render });
  for (const control of [modeSelect, toneSelect, exposure, logBox])
    control.addEventListener('input', update);
  controls.addEventListener('change', render);
  window.addEventListener('resize', resize);
  resize();
  update();
  document.body.dataset.ready = 'true';
}

try {
  start();
} catch (error) {
  showError(error.message);
  document.body.dataset.ready = 'error';
}
