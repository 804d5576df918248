// playback.js - plays back a solve recorded by `radiosity view SCENE --record FILE` (the
// page's "radiosity-record" block, the JSON `solve --record` writes, and the patch of each
// triangle, "radiosity-triangle-patch"): a step slider and a play button; each triangle
// is coloured by its patch's radiance B / pi at that step (flat per patch, through the
// viewer's own material, so exposure, tone mapping and false colour apply), the patch of
// the last shot is outlined, and the step, unshot energy and residual are shown. Not the
// record's maker (src/solution/solve_record.c) and not the viewer's other controls
// (main.js).

import { BufferAttribute, BufferGeometry, Mesh, MeshBasicMaterial } from 'three';
import { decodeBase64 } from './base64.js';

// play: the whole record in about PLAY_MS, but no snapshot shorter than STEP_MS_MIN
const PLAY_MS = 6000, STEP_MS_MIN = 40;

const PLAYBACK_STYLE = `
#playback { margin: 10px 0; padding: 6px; background: #262626; }
#playback .row button { min-width: 56px; }
#playback .numbers div { font-variant-numeric: tabular-nums; }
`;

function element(tag, attributes = {}, text = '') {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attributes)) e.setAttribute(k, v);
  if (text) e.textContent = text;
  return e;
}

function formatNumber(v) {
  if (v === null || v === undefined) return '–';
  if (v === 0) return '0';
  return Math.abs(v) < 1e-3 || Math.abs(v) >= 1e5 ? v.toExponential(2) : String(Number(v.toPrecision(3)));
}

// The record's snapshots, checked against the mesh: each radiosity block holds 3 float32
// per patch.
function readRecord(text, triangles, trianglePatch) {
  const record = JSON.parse(text);
  if (record.format !== 'radiosity-record' || record.version !== 1)
    throw new Error('the embedded record is not a radiosity-record, version 1');
  const n = record.patches;
  if (!(n > 0) || !Array.isArray(record.snapshots) || record.snapshots.length === 0)
    throw new Error('the embedded record has no patches or no snapshots');
  if (trianglePatch.length !== triangles)
    throw new Error(`the triangle patch table has ${trianglePatch.length} triangles, the mesh ${triangles}`);
  for (const p of trianglePatch)
    if (p >= n) throw new Error(`a triangle's patch ${p} is past the record's ${n} patches`);
  return record;
}

// Patch radiosity of one snapshot, decoded (little-endian float32, n x 3).
function snapshotRadiosity(snapshot, n) {
  const bytes = decodeBase64(snapshot.radiosity);
  if (bytes.length !== 12 * n) throw new Error(`snapshot ${snapshot.step}: ${bytes.length} bytes, expected ${12 * n}`);
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const out = new Float32Array(3 * n);
  for (let k = 0; k < 3 * n; k++) out[k] = view.getFloat32(4 * k, true);
  return out;
}

// Sets up playback; returns nothing. `host` holds what main.js shares: the parsed lit mesh,
// the three.js scene, the lit mesh's object and material, the side panel and render().
export function startPlayback(host) {
  const { recordText, trianglePatchText, mesh, scene, object, material, panel, render } = host;
  const triangles = mesh.index.length / 3;
  const trianglePatch = new Uint32Array(decodeBase64(trianglePatchText || '').buffer);
  const record = readRecord(recordText, triangles, trianglePatch);
  const n = record.patches, snapshots = record.snapshots;

  const style = element('style');
  style.textContent = PLAYBACK_STYLE;
  document.head.appendChild(style);

  // the mesh without shared vertices: each triangle takes its patch's value whole
  const position = new Float32Array(9 * triangles);
  for (let t = 0; t < triangles; t++)
    for (let c = 0; c < 3; c++) {
      const v = mesh.index[3 * t + c];
      position.set(mesh.position.subarray(3 * v, 3 * v + 3), 9 * t + 3 * c);
    }
  const radiance = new Float32Array(9 * triangles);
  const geometry = new BufferGeometry();
  geometry.setAttribute('position', new BufferAttribute(position, 3));
  geometry.setAttribute('radiance', new BufferAttribute(radiance, 3));
  geometry.setAttribute('illuminance', new BufferAttribute(new Float32Array(9 * triangles), 3));
  const flat = new Mesh(geometry, material);
  scene.add(flat);

  // the shooting patch's outline, drawn over everything
  const outlineGeometry = new BufferGeometry();
  const outline = new Mesh(outlineGeometry,
    new MeshBasicMaterial({ color: 0xff00ff, wireframe: true, depthTest: false, transparent: true }));
  outline.renderOrder = 1;
  scene.add(outline);
  const trianglesOf = new Map(); // patch -> its triangles, built when first outlined
  function outlinePatch(p) {
    outline.visible = on.checked && p !== null && p !== undefined;
    if (!outline.visible) return;
    if (!trianglesOf.has(p)) {
      const list = [];
      for (let t = 0; t < triangles; t++) if (trianglePatch[t] === p) list.push(t);
      trianglesOf.set(p, list);
    }
    const list = trianglesOf.get(p);
    const points = new Float32Array(9 * list.length);
    list.forEach((t, k) => points.set(position.subarray(9 * t, 9 * t + 9), 9 * k));
    outlineGeometry.setAttribute('position', new BufferAttribute(points, 3));
    outlineGeometry.computeBoundingSphere();
  }

  // the controls
  const box = element('div', { id: 'playback' });
  const unit = record.solver === 'shoot' ? 'shots' : record.solver === 'direct' ? 'solves' : 'sweeps';
  box.appendChild(element('div', { class: 'title' }, `playback: ${record.solver || 'solver'}, ${snapshots.length} snapshots`));
  const on = element('input', { id: 'playback-on', type: 'checkbox' });
  on.checked = true;
  const slider = element('input', { id: 'playback-step', type: 'range', min: '0',
    max: String(snapshots.length - 1), step: '1', value: '0' });
  const play = element('button', { id: 'playback-play', type: 'button' }, 'play');
  const row = (label, ...children) => {
    const r = element('div', { class: 'row' });
    r.append(element('label', {}, label), ...children);
    box.appendChild(r);
  };
  row('show steps', on);
  row('snapshot', slider);
  row('', play);
  const numbers = element('div', { class: 'numbers' });
  box.appendChild(numbers);
  panel.insertBefore(box, panel.querySelector('#legend') || null);

  const field = (name, label, value) => {
    const d = element('div', { class: 'field' });
    d.append(element('span', { class: 'label' }, label), element('span', { 'data-field': name }, value));
    return d;
  };

  let current = -1;
  function show(index) {
    const s = snapshots[index];
    const B = snapshotRadiosity(s, n);
    for (let t = 0; t < triangles; t++) {
      const p = trianglePatch[t];
      const r = B[3 * p] / Math.PI, g = B[3 * p + 1] / Math.PI, b = B[3 * p + 2] / Math.PI;
      for (let c = 0; c < 3; c++) radiance.set([r, g, b], 9 * t + 3 * c);
    }
    geometry.attributes.radiance.needsUpdate = true;
    outlinePatch(s.shooting_patch);
    numbers.replaceChildren(
      field('step', 'step', `${s.step} ${unit}${s.final ? ' (the answer)' : ''}`),
      field('phase', 'phase', s.phase || ''),
      field('seconds', 'time', `${formatNumber(s.seconds)} s`),
      field('unshot', 'unshot energy', formatNumber(s.unshot)),
      field('residual', 'residual', formatNumber(s.residual)),
      field('shooting-patch', 'shooting patch', s.shooting_patch === null ? '–' : String(s.shooting_patch)));
    box.dataset.index = String(index);
    current = index;
    render();
  }

  function setVisible() {
    flat.visible = on.checked;
    outline.visible = on.checked && snapshots[current] && snapshots[current].shooting_patch !== null;
    object.visible = !on.checked;
    render();
  }

  let timer = null;
  function stop() {
    if (timer !== null) clearInterval(timer);
    timer = null;
    play.textContent = 'play';
  }
  play.addEventListener('click', () => {
    if (timer !== null) return stop();
    if (current >= snapshots.length - 1) slider.value = '0';
    on.checked = true;
    setVisible();
    play.textContent = 'pause';
    show(Number(slider.value));
    timer = setInterval(() => {
      if (current >= snapshots.length - 1) return stop();
      slider.value = String(current + 1);
      show(current + 1);
      if (current >= snapshots.length - 1) stop();
    }, Math.max(STEP_MS_MIN, PLAY_MS / snapshots.length));
  });
  slider.addEventListener('input', () => { stop(); show(Number(slider.value)); });
  on.addEventListener('input', setVisible);
  show(0);
  setVisible();
}
