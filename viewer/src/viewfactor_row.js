// viewfactor_row.js - an engineer's view-factor row: with the matrix `radiosity view
// --viewfactors` embeds (the scene's surfaces, sparse rows of F_ij), a click on surface i
// colours every surface j by F_ij in false colour (dimensionless, from the row's smallest
// to its largest factor over j != i) and draws surface i in the highlight colour; the pick
// panel gives i's name, area and row sum. Not the matrix's computation (the library's
// rad_viewfactor_matrix_compute) and not the lit mesh's colours.

import { BufferAttribute, BufferGeometry, Mesh } from 'three';
import { decodeBase64 } from './base64.js';
import { formatValue, SCALE_COLOURS } from './false_colour.js';
import { HIGHLIGHT, valueMaterial } from './value_material.js';

export const MODE_VIEWFACTORS = 'viewfactors';

// The block: uint32 n, nonzeros, row_start[n + 1], column[nonzeros], padding to 8 bytes,
// float64 value[nonzeros], little-endian (tools/cmd_view.c writes it).
export function parseViewFactors(bytes) {
  const data = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (bytes.byteLength < 8) throw new Error('the view-factor block is too short');
  const n = data.getUint32(0, true), nonzeros = data.getUint32(4, true);
  const valuesAt = Math.ceil((4 * (2 + n + 1 + nonzeros)) / 8) * 8;
  if (valuesAt + 8 * nonzeros !== bytes.byteLength)
    throw new Error(`the view-factor block has ${bytes.byteLength} bytes, not the ${valuesAt + 8 * nonzeros} of ${n} surfaces and ${nonzeros} factors`);
  const rowStart = new Uint32Array(n + 1), column = new Uint32Array(nonzeros);
  const value = new Float64Array(nonzeros);
  for (let i = 0; i <= n; i++) rowStart[i] = data.getUint32(8 + 4 * i, true);
  for (let k = 0; k < nonzeros; k++) {
    column[k] = data.getUint32(8 + 4 * (n + 1) + 4 * k, true);
    value[k] = data.getFloat64(valuesAt + 8 * k, true);
    if (column[k] >= n) throw new Error(`view factor ${k} names surface ${column[k]} of ${n}`);
  }
  for (let i = 0; i < n; i++)
    if (rowStart[i] > rowStart[i + 1] || rowStart[i + 1] > nonzeros)
      throw new Error(`the view-factor row ${i} is out of order`);
  return { n, rowStart, column, value };
}

// Row i as a dense array, its range over j != i and its sum over every j.
export function viewFactorRow(matrix, i) {
  const row = new Float64Array(matrix.n);
  for (let k = matrix.rowStart[i]; k < matrix.rowStart[i + 1]; k++) row[matrix.column[k]] = matrix.value[k];
  let lo = Infinity, hi = -Infinity, sum = 0;
  for (let j = 0; j < matrix.n; j++) {
    sum += row[j];
    if (j === i) continue;
    lo = Math.min(lo, row[j]);
    hi = Math.max(hi, row[j]);
  }
  if (lo > hi) lo = hi = 0; // one surface only
  return { row, lo, hi, sum };
}

// context: { info, mesh, triangleSurface, scene, panel, element }. Null without the block.
export function createViewFactorRow(context) {
  const text = context.embedded('radiosity-viewfactors');
  if (!text || !context.triangleSurface || !context.info.surfaces) return null;
  const matrix = parseViewFactors(decodeBase64(text));
  if (matrix.n !== context.info.surfaces.length)
    throw new Error(`the view factors have ${matrix.n} surfaces, the scene ${context.info.surfaces.length}`);
  const { mesh, triangleSurface, info } = context;
  const triangles = mesh.index.length / 3;
  // one vertex per triangle corner, so that each triangle takes its surface's value
  const position = new Float32Array(9 * triangles);
  for (let c = 0; c < 3 * triangles; c++)
    for (let k = 0; k < 3; k++) position[3 * c + k] = mesh.position[3 * mesh.index[c] + k];
  const values = new Float32Array(3 * triangles);
  const geometry = new BufferGeometry();
  geometry.setAttribute('position', new BufferAttribute(position, 3));
  geometry.setAttribute('value', new BufferAttribute(values, 1));
  const material = valueMaterial();
  const object = new Mesh(geometry, material);
  object.visible = false;
  context.scene.add(object);

  let picked = 0, current = null;
  function choose(i) {
    picked = i;
    current = viewFactorRow(matrix, i);
    for (let t = 0; t < triangles; t++) {
      const s = triangleSurface[t];
      const v = s === i ? HIGHLIGHT : current.row[s];
      values[3 * t] = values[3 * t + 1] = values[3 * t + 2] = v;
    }
    geometry.getAttribute('value').needsUpdate = true;
    material.uniforms.lo.value = current.lo;
    material.uniforms.hi.value = current.hi;
  }
  choose(0);

  return {
    modes: [{ value: MODE_VIEWFACTORS, label: 'view factors F_ij (click surface i)' }],
    show(mode) {
      object.visible = mode === MODE_VIEWFACTORS;
      if (!object.visible) return null;
      return {
        hideMesh: true,
        legend: {
          title: `view factor F_ij from ${info.surfaces[picked].name} (dimensionless; white: i)`,
          lo: current.lo, hi: current.hi, colours: SCALE_COLOURS,
        },
      };
    },
    // a click in this mode makes the surface picked row i
    pick(mode, hit, line) {
      if (mode !== MODE_VIEWFACTORS || !hit) return false;
      const i = triangleSurface[hit.faceIndex];
      choose(i);
      line('row sum Σj F_ij', String(Number(current.sum.toPrecision(6))), 'row-sum');
      if (current.row[i] > 0) line('F_ii (sees itself)', formatValue(current.row[i]), 'self');
      let best = -1;
      for (let j = 0; j < matrix.n; j++) if (j !== i && (best < 0 || current.row[j] > current.row[best])) best = j;
      if (best >= 0) line('largest F_ij', `${formatValue(current.row[best])} to ${info.surfaces[best].name}`, 'largest');
      return true; // the legend changed
    },
  };
}
