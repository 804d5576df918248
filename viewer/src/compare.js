// compare.js - two solutions of the same geometry (`radiosity view A --compare B.glb`):
// the difference of their luminance, A - B per vertex, in the signed false colour (blue
// where B is brighter, white where they agree, red where A is) with a legend from
// -max|A - B| to +max|A - B| in cd/m²; and B itself in colour, with the page's exposure
// and tone mapping, to flip between the two. Not the check that the geometries match
// (tools/cmd_view.c refuses two meshes whose vertices or triangles differ).

import { BufferAttribute, BufferGeometry, Mesh } from 'three';
import { decodeBase64 } from './base64.js';
import { DIVERGING_COLOURS, formatValue, luminanceAt } from './false_colour.js';
import { parseLitMesh } from './glb.js';
import { valueMaterial } from './value_material.js';

export const MODE_DIFFERENCE = 'difference';
export const MODE_B = 'compare-b';

// Luminance of A minus that of B at each vertex, and the largest |A - B| and luminance of A.
export function luminanceDifference(radianceA, radianceB) {
  const vertices = radianceA.length / 3;
  const difference = new Float32Array(vertices);
  let largest = 0, largestA = 0;
  for (let v = 0; v < vertices; v++) {
    const a = luminanceAt(radianceA, v);
    difference[v] = a - luminanceAt(radianceB, v);
    largest = Math.max(largest, Math.abs(difference[v]));
    largestA = Math.max(largestA, a);
  }
  return { difference, largest, largestA };
}

// context: { info, mesh, geometry, material, scene, panel, element, embedded }.
export function createCompare(context) {
  const text = context.embedded('radiosity-compare-glb');
  if (!text) return null;
  const { mesh, geometry, info } = context;
  const other = parseLitMesh(decodeBase64(text));
  if (other.position.length !== mesh.position.length || other.index.length !== mesh.index.length)
    throw new Error('the compared lit mesh has another vertex or triangle count');
  const { difference, largest, largestA } = luminanceDifference(mesh.radiance, other.radiance);
  const unit = info.radiance_unit || 'cd/m²';

  const differenceGeometry = new BufferGeometry();
  differenceGeometry.setAttribute('position', geometry.getAttribute('position'));
  differenceGeometry.setAttribute('value', new BufferAttribute(difference, 1));
  differenceGeometry.setIndex(geometry.getIndex());
  const differenceMaterial = valueMaterial({ diverging: true });
  differenceMaterial.uniforms.lo.value = -largest;
  differenceMaterial.uniforms.hi.value = largest;
  const differenceObject = new Mesh(differenceGeometry, differenceMaterial);

  const otherGeometry = new BufferGeometry();
  otherGeometry.setAttribute('position', geometry.getAttribute('position'));
  otherGeometry.setAttribute('radiance', new BufferAttribute(other.radiance, 3));
  otherGeometry.setAttribute('illuminance',
    new BufferAttribute(other.illuminance || new Float32Array(other.position.length), 3));
  otherGeometry.setIndex(geometry.getIndex());
  const otherObject = new Mesh(otherGeometry, context.material); // the page's exposure and tone
  for (const object of [differenceObject, otherObject]) {
    object.visible = false;
    context.scene.add(object);
  }

  context.panel.appendChild(context.element('div', { class: 'summary', id: 'compare-summary' },
    `compared with ${info.compare_source || 'B'}: largest |A − B| ${formatValue(largest)} ${unit}` +
    (largestA > 0 ? ` (${formatValue((100 * largest) / largestA)} % of A's largest luminance)` : '')));

  return {
    modes: [
      { value: MODE_DIFFERENCE, label: 'difference A − B, luminance' },
      { value: MODE_B, label: 'B (colour): the compared solution' },
    ],
    show(mode) {
      differenceObject.visible = mode === MODE_DIFFERENCE;
      otherObject.visible = mode === MODE_B;
      if (mode === MODE_B) return { hideMesh: true, colour: true };
      if (mode !== MODE_DIFFERENCE) return null;
      return {
        hideMesh: true,
        legend: { title: `A − B, luminance (${unit})`, lo: -largest, hi: largest, colours: DIVERGING_COLOURS, ticks: 5 },
      };
    },
    pick(mode, hit, line) {
      if ((mode !== MODE_DIFFERENCE && mode !== MODE_B) || !hit) return false;
      const corner = [0, 1, 2].map((k) => mesh.index[3 * hit.faceIndex + k]);
      const w = hit.barycoord ? [hit.barycoord.x, hit.barycoord.y, hit.barycoord.z] : [1 / 3, 1 / 3, 1 / 3];
      const at = (rgb) => corner.reduce((sum, v, k) => sum + w[k] * luminanceAt(rgb, v), 0);
      line('here: B luminance', `${formatValue(at(other.radiance))} ${unit}`, 'point-radiance-b');
      line('here: A − B', `${formatValue(at(mesh.radiance) - at(other.radiance))} ${unit}`, 'point-difference');
      return false;
    },
  };
}
