// edges.js - element and patch edges on demand: black lines along every display triangle's
// edges ("triangles", the elements the lit mesh is drawn with) or only where the patch
// changes across an edge, and along open borders ("patches", the solver's unknowns; needs
// the patch of each triangle that `radiosity view SCENE` embeds). Vertices are welded by
// exact position first, as the lit mesh repeats them across creases. Not the surfaces'
// colours: the materials draw their faces a little behind (polygon offset) so that the
// lines win the depth test.

import { BufferAttribute, BufferGeometry, LineBasicMaterial, LineSegments } from 'three';

export const EDGES_NONE = 'none';
export const EDGES_PATCHES = 'patches';
export const EDGES_TRIANGLES = 'triangles';

// An open-addressing table's slots (-1: empty) for up to `count` keys, half full at most.
function slots(count) {
  let capacity = 1024;
  while (capacity < 2 * count) capacity *= 2;
  return new Int32Array(capacity).fill(-1);
}

// Each vertex's welded id: vertices at bit-identical positions get the same one.
export function weldByPosition(position) {
  const bits = new Uint32Array(position.buffer, position.byteOffset, position.length);
  const vertices = position.length / 3;
  const weld = new Uint32Array(vertices);
  const table = slots(vertices), mask = table.length - 1;
  let welded = 0;
  for (let v = 0; v < vertices; v++) {
    const x = bits[3 * v], y = bits[3 * v + 1], z = bits[3 * v + 2];
    let i = (Math.imul(x, 0x9e3779b1) ^ Math.imul(y, 0x85ebca77) ^ Math.imul(z, 0xc2b2ae3d)) & mask;
    for (;;) {
      const r = table[i];
      if (r < 0) {
        table[i] = v;
        weld[v] = welded++;
        break;
      }
      if (bits[3 * r] === x && bits[3 * r + 1] === y && bits[3 * r + 2] === z) {
        weld[v] = weld[r];
        break;
      }
      i = (i + 1) & mask;
    }
  }
  return weld;
}

// The segments (pairs of vertex indices) of the chosen kind: every edge for "triangles";
// for "patches" the edges whose triangles are not all of one patch, and the edges of one
// triangle only (open borders). `trianglePatch` may be null for the "triangles" kind.
export function edgeSegments(position, index, trianglePatch, kind) {
  const weld = weldByPosition(position);
  const triangles = index.length / 3, most = 3 * triangles;
  const table = slots(most), mask = table.length - 1;
  // per edge: its welded ends (the key), a corner pair to draw, its first triangle's
  // patch, how many triangles share it, and whether two of them differ in patch
  const lo = new Uint32Array(most), hi = new Uint32Array(most);
  const endA = new Uint32Array(most), endB = new Uint32Array(most);
  const patchOf = new Uint32Array(most), count = new Uint32Array(most), differs = new Uint8Array(most);
  let edges = 0;
  for (let t = 0; t < triangles; t++) {
    const patch = trianglePatch ? trianglePatch[t] : 0;
    for (let k = 0; k < 3; k++) {
      const a = index[3 * t + k], b = index[3 * t + ((k + 1) % 3)];
      const wa = Math.min(weld[a], weld[b]), wb = Math.max(weld[a], weld[b]);
      if (wa === wb) continue;
      let i = (Math.imul(wa, 0x9e3779b1) ^ Math.imul(wb, 0x85ebca77)) & mask;
      for (;;) {
        const e = table[i];
        if (e < 0) {
          table[i] = edges;
          lo[edges] = wa;
          hi[edges] = wb;
          endA[edges] = a;
          endB[edges] = b;
          patchOf[edges] = patch;
          count[edges] = 1;
          edges++;
          break;
        }
        if (lo[e] === wa && hi[e] === wb) {
          count[e]++;
          if (patchOf[e] !== patch) differs[e] = 1;
          break;
        }
        i = (i + 1) & mask;
      }
    }
  }
  let drawn = 0;
  const keep = (e) => kind === EDGES_TRIANGLES || differs[e] || count[e] === 1;
  for (let e = 0; e < edges; e++) if (keep(e)) drawn++;
  const segments = new Uint32Array(2 * drawn);
  for (let e = 0, s = 0; e < edges; e++)
    if (keep(e)) {
      segments[s++] = endA[e];
      segments[s++] = endB[e];
    }
  return segments;
}

// context: { mesh, trianglePatch, scene, element, row }. Adds the "edges" control.
export function createEdges(context, onChange) {
  const { mesh, trianglePatch } = context;
  const select = context.element('select', { id: 'edges' });
  select.append(context.element('option', { value: EDGES_NONE }, 'none'));
  if (trianglePatch) select.append(context.element('option', { value: EDGES_PATCHES }, 'patches'));
  select.append(context.element('option', { value: EDGES_TRIANGLES }, 'triangles (elements)'));
  context.row('edges', select);
  const material = new LineBasicMaterial({ color: 0x000000 });
  const built = {};
  select.addEventListener('input', () => {
    for (const object of Object.values(built)) object.visible = false;
    const kind = select.value;
    if (kind !== EDGES_NONE) {
      if (!built[kind]) {
        const geometry = new BufferGeometry();
        geometry.setAttribute('position', new BufferAttribute(mesh.position, 3));
        geometry.setIndex(new BufferAttribute(edgeSegments(mesh.position, mesh.index, trianglePatch, kind), 1));
        built[kind] = new LineSegments(geometry, material);
        context.scene.add(built[kind]);
      }
      built[kind].visible = true;
      document.body.dataset.edges = String(built[kind].geometry.index.count / 2);
    }
    onChange();
  });
}
