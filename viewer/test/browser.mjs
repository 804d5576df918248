// browser.mjs - what the browser tests (viewer, playback, views) need from chromium: launch
// Debian's chromium with software WebGL, open a page `radiosity view` wrote and wait for
// its first frame (recording console errors and requests), take the canvas's screenshot,
// and read the page's embedded blocks the way the test's own references do. A test helper.
import assert from 'node:assert/strict';
import puppeteer from 'puppeteer-core';
import { decodePng } from './png.mjs';

export async function launch() {
  return puppeteer.launch({
    executablePath: process.env.RAD_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
      '--disable-gpu-sandbox', '--no-first-run'],
  });
}

// Opens `path` in an 812 x 512 window (a 512 x 512 canvas) and waits for the first frame.
export async function open(browser, path) {
  const page = await browser.newPage();
  await page.setViewport({ width: 812, height: 512, deviceScaleFactor: 1 });
  const problems = [], requests = [];
  page.on('console', (m) => { if (m.type() === 'error' || m.type() === 'warn') problems.push(`${m.type()}: ${m.text()}`); });
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('request', (r) => requests.push(r.url()));
  await page.goto(`file://${path}`);
  await page.waitForFunction(() => document.body.dataset.ready && Number(document.body.dataset.frames || 0) > 0,
    { timeout: 60000 });
  assert.equal(await page.evaluate(() => document.body.dataset.ready), 'true',
    await page.evaluate(() => document.getElementById('error')?.textContent || ''));
  return { page, problems, requests };
}

// Two animation frames: whatever a control changed has been drawn.
export async function drawn(page) {
  await page.evaluate(() => new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done))));
}

export async function canvasShot(page, file) {
  const canvas = await page.$('#view canvas');
  const png = await canvas.screenshot({ path: file });
  return decodePng(Buffer.from(png));
}

// The mean colour of the 3 x 3 pixels around (x, y).
export function meanColour(image, [x, y]) {
  const sum = [0, 0, 0];
  for (let dy = -1; dy <= 1; dy++)
    for (let dx = -1; dx <= 1; dx++) image.pixel(x + dx, y + dy).forEach((c, k) => { sum[k] += c / 9; });
  return sum;
}

export const luma = (c) => 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];

// The bytes of the page's block `id` (base64), or null.
export function block(html, id) {
  const match = html.match(new RegExp(`<script type="application/octet-stream" id="${id}">([^<]*)</script>`));
  return match ? Buffer.from(match[1], 'base64') : null;
}

// The .glb's positions, radiance and triangle indices, read here, not by the viewer.
export function readGlb(glb) {
  const jsonLength = glb.readUInt32LE(12);
  const gltf = JSON.parse(glb.toString('utf8', 20, 20 + jsonLength));
  const bin = 20 + jsonLength + 8;
  const primitive = gltf.meshes[0].primitives[0];
  const read = (accessorIndex, components, float) => {
    const accessor = gltf.accessors[accessorIndex];
    const at = bin + (gltf.bufferViews[accessor.bufferView].byteOffset || 0);
    const values = [];
    for (let k = 0; k < accessor.count * components; k++)
      values.push(float ? glb.readFloatLE(at + 4 * k) : glb.readUInt32LE(at + 4 * k));
    return values;
  };
  return {
    position: read(primitive.attributes.POSITION, 3, true),
    radiance: read(primitive.attributes._RADIANCE, 3, true),
    index: read(primitive.indices, 1, false),
  };
}

// Where a point lands in a width x height view of camera { eye, target, up, fov }.
export function project(camera, point, width, height) {
  const sub = (a, b) => a.map((x, k) => x - b[k]);
  const dot = (a, b) => a.reduce((s, x, k) => s + x * b[k], 0);
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const unit = (a) => a.map((x) => x / Math.hypot(...a));
  const f = unit(sub(camera.target, camera.eye));
  const r = unit(cross(f, camera.up));
  const u = cross(r, f);
  const p = sub(point, camera.eye);
  const t = Math.tan((camera.fov / 2) * Math.PI / 180);
  const x = dot(p, r) / (dot(p, f) * t * (width / height));
  const y = dot(p, u) / (dot(p, f) * t);
  return [((x + 1) / 2) * width, ((1 - y) / 2) * height];
}

// The viewer's default camera for a scene without one: from -z, 40 degrees, at the
// distance where the bounding sphere (box centre, farthest vertex) fills the view.
export function defaultCamera(position) {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let k = 0; k < position.length; k++) {
    lo[k % 3] = Math.min(lo[k % 3], position[k]);
    hi[k % 3] = Math.max(hi[k % 3], position[k]);
  }
  const centre = lo.map((x, k) => (x + hi[k]) / 2);
  let radius = 0;
  for (let k = 0; k < position.length; k += 3)
    radius = Math.max(radius, Math.hypot(position[k] - centre[0], position[k + 1] - centre[1], position[k + 2] - centre[2]));
  const distance = radius / Math.sin((20 * Math.PI) / 180);
  return { eye: [centre[0], centre[1], centre[2] - distance], target: centre, up: [0, 1, 0], fov: 40 };
}

export function near(actual, expected, tolerance, what) {
  assert.ok(Math.abs(actual - expected) <= tolerance, `${what}: ${actual}, expected ${expected} within ${tolerance}`);
}
