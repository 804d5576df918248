// value_material.js - the material that shows one number per vertex (the attribute
// `value`) in false colour: a view factor, a difference of two solutions, a grid's lux.
// The sequential scale of false_colour.js from lo to hi, or the signed (diverging) one
// with zero in its middle; a value below HIGHLIGHT_BELOW is drawn in the highlight
// colour (the picked surface of a view-factor row). Not the lit mesh's own colours
// (shader.js) and not the legend (main.js).

import { DoubleSide, FrontSide, ShaderMaterial } from 'three';
import { DIVERGING_COLOURS, SCALE_COLOURS } from './false_colour.js';

export const HIGHLIGHT = -1e30;       // the value that marks a highlighted triangle
const HIGHLIGHT_BELOW = -1e29;
export const HIGHLIGHT_COLOUR = [1, 1, 1];

const glslArray = (colours) => `vec3[](${colours.map((c) => `vec3(${c.map((x) => x.toFixed(3)).join(', ')})`).join(', ')})`;

const vertexShader = `
attribute float value;
varying float vValue;
void main() {
  vValue = value;
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}`;

const fragmentShader = `
precision highp float;
uniform float lo;
uniform float hi;
uniform bool diverging;
uniform bool logScale;
varying float vValue;

const vec3 SEQUENTIAL[${SCALE_COLOURS.length}] = ${glslArray(SCALE_COLOURS)};
const vec3 DIVERGING[${DIVERGING_COLOURS.length}] = ${glslArray(DIVERGING_COLOURS)};

void main() {
  if (vValue < ${HIGHLIGHT_BELOW.toExponential()}) {
    gl_FragColor = vec4(${HIGHLIGHT_COLOUR.map((x) => x.toFixed(3)).join(', ')}, 1.0);
    return;
  }
  float t;
  if (hi <= lo) t = 0.5;
  else if (logScale) t = (log(max(vValue, lo)) - log(lo)) / (log(hi) - log(lo));
  else t = (vValue - lo) / (hi - lo);
  t = clamp(t, 0.0, 1.0);
  vec3 c;
  if (diverging) {
    float x = t * float(${DIVERGING_COLOURS.length - 1});
    int i = int(min(floor(x), float(${DIVERGING_COLOURS.length - 2})));
    c = mix(DIVERGING[i], DIVERGING[i + 1], x - float(i));
  } else {
    float x = t * float(${SCALE_COLOURS.length - 1});
    int i = int(min(floor(x), float(${SCALE_COLOURS.length - 2})));
    c = mix(SEQUENTIAL[i], SEQUENTIAL[i + 1], x - float(i));
  }
  gl_FragColor = vec4(c, 1.0); // the control colours are sRGB already
}`;

// `twoSided`: both faces drawn (a grid's squares); the lit mesh's faces are one-sided.
export function valueMaterial({ diverging = false, twoSided = false } = {}) {
  return new ShaderMaterial({
    glslVersion: null,
    vertexShader,
    fragmentShader,
    side: twoSided ? DoubleSide : FrontSide,
    polygonOffset: true, // behind the edge lines (edges.js) at the same depth
    polygonOffsetFactor: 1,
    polygonOffsetUnits: 1,
    uniforms: {
      lo: { value: 0 },
      hi: { value: 1 },
      diverging: { value: diverging },
      logScale: { value: false },
    },
  });
}
