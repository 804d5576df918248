// false_colour.js - the false-colour scale (the one `render --false-colour` draws: blue
// through cyan, green and yellow to red, as sRGB control colours) and the legend's tick
// values. Not the drawing: shader.js colours the mesh, main.js draws the legend.

export const SCALE_COLOURS = [
  [0.05, 0.05, 0.55], [0.0, 0.45, 1.0], [0.0, 0.85, 0.85], [0.1, 0.8, 0.1],
  [1.0, 0.9, 0.0], [1.0, 0.45, 0.0], [0.85, 0.0, 0.0],
];

export const TICKS = 6;

// The legend's values, low to high: `count` evenly spaced from lo to hi, or evenly in
// log10 when `log` (lo > 0 then).
export function tickValues(lo, hi, log, count = TICKS) {
  const values = [];
  for (let k = 0; k < count; k++) {
    const t = k / (count - 1);
    values.push(log ? Math.exp(Math.log(lo) + t * (Math.log(hi) - Math.log(lo))) : lo + t * (hi - lo));
  }
  values[0] = lo;
  values[count - 1] = hi;
  return values;
}

// Three significant digits, as the legend writes a value.
export function formatValue(v) {
  if (v === 0) return '0';
  const a = Math.abs(v);
  return a >= 1e5 || a < 1e-3 ? v.toExponential(2) : String(Number(v.toPrecision(3)));
}

// The luminance (Rec. 709 weights, the library's) of the RGB triple at vertex v.
export function luminanceAt(rgb, v) {
  return 0.2126 * rgb[3 * v] + 0.7152 * rgb[3 * v + 1] + 0.0722 * rgb[3 * v + 2];
}

// The smallest and largest luminance over the vertices, and the smallest above zero.
export function luminanceRange(rgb) {
  let lo = Infinity, hi = -Infinity, positive = Infinity;
  for (let v = 0; v < rgb.length / 3; v++) {
    const y = luminanceAt(rgb, v);
    if (y < lo) lo = y;
    if (y > hi) hi = y;
    if (y > 0 && y < positive) positive = y;
  }
  return { lo, hi, positive: positive === Infinity ? hi : positive };
}

// The signed scale of a difference: blue below zero, white at zero, red above (sRGB
// control colours, an odd count so that zero is the middle one).
export const DIVERGING_COLOURS = [
  [0.13, 0.25, 0.75], [0.45, 0.62, 0.95], [0.97, 0.97, 0.97], [0.95, 0.55, 0.45],
  [0.75, 0.08, 0.12],
];

// The colour of t in [0, 1] on a scale of control colours (as the shader interpolates).
export function scaleColour(colours, t) {
  const x = Math.min(Math.max(t, 0), 1) * (colours.length - 1);
  const i = Math.min(Math.floor(x), colours.length - 2);
  const f = x - i;
  return colours[i].map((a, k) => (1 - f) * a + f * colours[i + 1][k]);
}
