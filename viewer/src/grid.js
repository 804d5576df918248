// grid.js - an illuminance grid (`radiosity view SCENE --grid grid.csv`, the table
// `radiosity illuminance` writes): a square around each calculation point, across its
// normal, in false colour of lux from the grid's smallest to its largest value, over the
// lit mesh in colour; a click on a square gives its point and lux. The square's side is
// the smallest distance between consecutive points (the grid's spacing). Not the
// computation of the illuminance (the `illuminance` command).

import { BufferAttribute, BufferGeometry, Mesh, Vector3 } from 'three';
import { formatValue, SCALE_COLOURS } from './false_colour.js';
import { valueMaterial } from './value_material.js';

export const MODE_GRID = 'grid';

// The smallest positive distance between consecutive points (x, y, z triples).
export function gridSpacing(points) {
  let spacing = Infinity;
  for (let k = 3; k < points.length; k += 3) {
    const d = Math.hypot(points[k] - points[k - 3], points[k + 1] - points[k - 2], points[k + 2] - points[k - 1]);
    if (d > 0) spacing = Math.min(spacing, d);
  }
  return spacing;
}

// context: { info, scene, geometry (the lit mesh's, for a lone point's size) }.
export function createGrid(context) {
  const grid = context.info.grid;
  if (!grid) return null;
  const count = grid.lux.length;
  if (grid.points.length !== 3 * count || grid.normals.length !== 3 * count)
    throw new Error('the grid has another number of points, normals and values');
  let spacing = gridSpacing(grid.points);
  if (!Number.isFinite(spacing)) spacing = context.geometry.boundingSphere.radius * 0.05;
  const half = 0.5 * spacing;
  const position = new Float32Array(18 * count), value = new Float32Array(6 * count);
  let lo = Infinity, hi = -Infinity;
  const n = new Vector3(), u = new Vector3(), v = new Vector3(), p = new Vector3();
  for (let i = 0; i < count; i++) {
    n.fromArray(grid.normals, 3 * i).normalize();
    u.set(Math.abs(n.y) < 0.9 ? 0 : 1, Math.abs(n.y) < 0.9 ? 1 : 0, 0).cross(n).normalize();
    v.crossVectors(n, u);
    p.fromArray(grid.points, 3 * i);
    const corner = (su, sv) => p.clone().addScaledVector(u, su * half).addScaledVector(v, sv * half);
    const quad = [corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, -1), corner(1, 1), corner(-1, 1)];
    quad.forEach((c, k) => c.toArray(position, 18 * i + 3 * k));
    value.fill(grid.lux[i], 6 * i, 6 * i + 6);
    lo = Math.min(lo, grid.lux[i]);
    hi = Math.max(hi, grid.lux[i]);
  }
  const geometry = new BufferGeometry();
  geometry.setAttribute('position', new BufferAttribute(position, 3));
  geometry.setAttribute('value', new BufferAttribute(value, 1));
  const material = valueMaterial({ twoSided: true });
  material.uniforms.lo.value = lo;
  material.uniforms.hi.value = hi;
  const object = new Mesh(geometry, material);
  object.visible = false;
  context.scene.add(object);
  const unit = context.info.illuminance_unit || 'lux';

  return {
    modes: [{ value: MODE_GRID, label: `illuminance grid (${count} points)` }],
    show(mode) {
      object.visible = mode === MODE_GRID;
      if (!object.visible) return null;
      return { colour: true, legend: { title: `illuminance on the grid (${unit})`, lo, hi, colours: SCALE_COLOURS } };
    },
    pick(mode, hit, line, raycaster) {
      if (mode !== MODE_GRID) return false;
      const onGrid = raycaster.intersectObject(object, false)[0];
      if (!onGrid) return false;
      const i = Math.floor(onGrid.faceIndex / 2);
      const at = grid.points.slice(3 * i, 3 * i + 3).map((x) => formatValue(x)).join(', ');
      line('grid point', `${formatValue(grid.lux[i])} ${unit} at (${at})`, 'grid-lux');
      return false;
    },
  };
}
