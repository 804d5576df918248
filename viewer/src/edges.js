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

// The segments (pairs of vertex indices) of the chosen kind. `trianglePatch` may be null
// for the "triangles" kind.
export function edgeSegments(position, index, trianglePatch, kind) {
  const weld = new Uint32Array(position.length / 3);
  const seen = new Map();
  for (let v = 0; v < weld.length; v++) {
    const key = `${position[3 * v]},${position[3 * v + 1]},${position[3 * v + 2]}`;
    let id = seen.get(key);
    if (id === undefined) {
      id = seen.size;
      seen.set(key, id);
    }
    weld[v] = id;
  }
  const welded = seen.size;
  // per edge: its first corner pair, its first triangle's patch, and whether it is drawn
  const edges = new Map();
  const first = [], drawn = [];
  const triangles = index.length / 3;
  for (let t = 0; t < triangles; t++) {
    for (let k = 0; k < 3; k++) {
      const a = index[3 * t + k], b = index[3 * t + ((k + 1) % 3)];
      const wa = weld[a], wb = weld[b];
      if (wa === wb) continue;
      const key = Math.min(wa, wb) * welded + Math.max(wa, wb);
      const e = edges.get(key);
      const patch = trianglePatch ? trianglePatch[t] : 0;
      if (e === undefined) {
        edges.set(key, drawn.length);
        first.push(a, b, patch, 1);
        drawn.push(kind === EDGES_TRIANGLES);
      } else {
        first[4 * e + 3]++;
        if (first[4 * e + 2] !== patch) drawn[e] = true;
      }
    }
  }
  const segments = [];
  for (let e = 0; e < drawn.length; e++)
    if (drawn[e] || first[4 * e + 3] === 1) segments.push(first[4 * e], first[4 * e + 1]);
  return new Uint32Array(segments);
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
