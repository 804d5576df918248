// shader.js - the material that shows the lit mesh: each vertex's linear radiance times the
// exposure, tone-mapped and sRGB-encoded, or the luminance of radiance or illuminance in
// false colour. Unlit (the radiosity solution is the light) and front faces only, as the
// lit mesh's triangles face their radiating side. Not the colour scale's values (those
// are false_colour.js's).

import { ShaderMaterial, FrontSide } from 'three';
import { SCALE_COLOURS } from './false_colour.js';

export const MODE_COLOUR = 0;
export const MODE_FALSE_RADIANCE = 1;
export const MODE_FALSE_ILLUMINANCE = 2;
export const TONE_CLAMP = 0;
export const TONE_REINHARD = 1;
export const TONE_ACES = 2;

const vertexShader = `
attribute vec3 radiance;
attribute vec3 illuminance;
varying vec3 vRadiance;
varying vec3 vIlluminance;
void main() {
  vRadiance = radiance;
  vIlluminance = illuminance;
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}`;

const stops = SCALE_COLOURS.map((c) => `vec3(${c.map((x) => x.toFixed(3)).join(', ')})`);

const fragmentShader = `
precision highp float;
uniform int mode;
uniform int tone;
uniform float scale;
uniform float lo;
uniform float hi;
uniform bool logScale;
varying vec3 vRadiance;
varying vec3 vIlluminance;

const vec3 STOPS[${stops.length}] = vec3[](${stops.join(', ')});

float lum709(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

vec3 encodeSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

vec3 aces(vec3 x) { // Narkowicz's fit of the ACES filmic curve
  return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 falseColour(float y) {
  float t = logScale ? (log(max(y, lo)) - log(lo)) / max(log(hi) - log(lo), 1e-30)
                     : (y - lo) / max(hi - lo, 1e-30);
  t = clamp(t, 0.0, 1.0) * float(${stops.length - 1});
  int i = int(min(floor(t), float(${stops.length - 2})));
  return mix(STOPS[i], STOPS[i + 1], t - float(i)); // already sRGB
}

void main() {
  if (mode == ${MODE_FALSE_RADIANCE}) { gl_FragColor = vec4(falseColour(lum709(vRadiance)), 1.0); return; }
  if (mode == ${MODE_FALSE_ILLUMINANCE}) { gl_FragColor = vec4(falseColour(lum709(vIlluminance)), 1.0); return; }
  vec3 c = max(vRadiance * scale, 0.0);
  if (tone == ${TONE_REINHARD}) c = c / (1.0 + lum709(c));
  else if (tone == ${TONE_ACES}) c = aces(c);
  gl_FragColor = vec4(encodeSrgb(c), 1.0);
}`;

export function litMeshMaterial() {
  return new ShaderMaterial({
    glslVersion: null,
    vertexShader,
    fragmentShader,
    side: FrontSide,
    polygonOffset: true, // behind the edge lines (edges.js) at the same depth
    polygonOffsetFactor: 1,
    polygonOffsetUnits: 1,
    uniforms: {
      mode: { value: MODE_COLOUR },
      tone: { value: TONE_CLAMP },
      scale: { value: 1 },
      lo: { value: 0 },
      hi: { value: 1 },
      logScale: { value: false },
    },
  });
}
