// viewer.test.mjs - the page `radiosity view` writes, in a real headless browser (Debian's
// chromium driven by puppeteer-core; nothing downloads a browser): it loads with no console
// error and no network request; the Cornell box shows its red wall left, green wall right
// and the light brightest at the pixels where the published geometry projects through the
// published camera; a click on the floor names it with its area (the published floor's
// own area); the false-colour legend's numbers are the data's range, computed here from
// the embedded .glb independently of the viewer; bad input is refused in one line.
//
//   RADIOSITY=build/radiosity RAD_CHROMIUM=/usr/bin/chromium node --test viewer/test/viewer.test.mjs
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync, spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { launch, open as openPage } from './browser.mjs';
import { decodePng } from './png.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const tool = resolve(process.env.RADIOSITY || join(here, '..', '..', 'build', 'radiosity'));
const tmp = resolve(process.env.RAD_TEST_TMP || join(here, '..', 'dist', 'test-tmp'));
mkdirSync(tmp, { recursive: true });

// The Cornell box as published (Cornell University Program of Computer Graphics), mm.
const CAMERA = { eye: [278, 273, -800], target: [278, 273, 0], up: [0, 1, 0],
  fov: 2 * Math.atan(0.0125 / 0.035) * 180 / Math.PI };
const FLOOR = [[552.8, 0, 0], [0, 0, 0], [0, 0, 559.2], [549.6, 0, 559.2]];
const LIGHT_CENTRE = [278, 548.8, 279.5];
const LEFT_WALL_POINT = [556, 274.4, 279.6];  // the red wall (x = 556 is on the left)
const RIGHT_WALL_POINT = [0, 274.4, 279.6];   // the green wall
const FLOOR_POINT = [500, 0, 100];            // in front of both blocks

const sub = (a, b) => a.map((x, k) => x - b[k]);
const dot = (a, b) => a.reduce((s, x, k) => s + x * b[k], 0);
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const unit = (a) => a.map((x) => x / Math.hypot(...a));

// Where a point lands in a width x height view of the camera (pixels from the top left).
function project(point, width, height) {
  const f = unit(sub(CAMERA.target, CAMERA.eye));
  const r = unit(cross(f, CAMERA.up));
  const u = cross(r, f);
  const p = sub(point, CAMERA.eye);
  const t = Math.tan((CAMERA.fov / 2) * Math.PI / 180);
  const x = dot(p, r) / (dot(p, f) * t * (width / height));
  const y = dot(p, u) / (dot(p, f) * t);
  return [((x + 1) / 2) * width, ((1 - y) / 2) * height];
}

// The polygon's area (planar, shoelace on its plane y = const).
function floorArea() {
  let twice = 0;
  for (let k = 0; k < FLOOR.length; k++) {
    const a = FLOOR[k], b = FLOOR[(k + 1) % FLOOR.length];
    twice += a[0] * b[2] - b[0] * a[2];
  }
  return Math.abs(twice) / 2;
}

// The embedded .glb's vertex attribute `name` (float VEC3), read here, not by the viewer.
function embeddedAttribute(html, name) {
  const match = html.match(/<script type="application\/octet-stream" id="radiosity-glb">([^<]*)<\/script>/);
  assert.ok(match, 'the page embeds the lit mesh');
  const glb = Buffer.from(match[1], 'base64');
  const jsonLength = glb.readUInt32LE(12);
  const gltf = JSON.parse(glb.toString('utf8', 20, 20 + jsonLength));
  const bin = 20 + jsonLength + 8;
  const accessor = gltf.accessors[gltf.meshes[0].primitives[0].attributes[name]];
  const view = gltf.bufferViews[accessor.bufferView];
  const values = [];
  for (let k = 0; k < accessor.count * 3; k++) values.push(glb.readFloatLE(bin + (view.byteOffset || 0) + 4 * k));
  return values;
}

function luminanceRange(values) {
  let lo = Infinity, hi = -Infinity;
  for (let v = 0; v < values.length; v += 3) {
    const y = 0.2126 * values[v] + 0.7152 * values[v + 1] + 0.0722 * values[v + 2];
    lo = Math.min(lo, y);
    hi = Math.max(hi, y);
  }
  return { lo, hi };
}

function near(actual, expected, relative, what) {
  assert.ok(Math.abs(actual - expected) <= relative * Math.abs(expected) + 1e-12,
    `${what}: ${actual}, expected ${expected} within ${relative * 100} %`);
}

let browser;
const cornellPage = join(tmp, 'cornell.html');
const cornellGlb = join(tmp, 'cornell.glb');
const glbPage = join(tmp, 'cornell_glb.html');

before(async () => {
  execFileSync(tool, ['view', '-o', cornellPage, '--quiet']);
  execFileSync(tool, ['solve', '-o', cornellGlb, '--quiet']);
  execFileSync(tool, ['view', cornellGlb, '-o', glbPage, '--quiet']);
  browser = await launch();
});

after(async () => {
  if (browser) await browser.close();
});

// Opens a page and waits for its first frame; records console errors and every request.
const open = (path) => openPage(browser, path);

async function canvasShot(page, file) {
  const canvas = await page.$('#view canvas');
  const box = await canvas.boundingBox();
  const png = await canvas.screenshot({ path: file });
  return { image: decodePng(Buffer.from(png)), box };
}

// The mean colour of the 3 x 3 pixels around (x, y).
function meanColour(image, [x, y]) {
  const sum = [0, 0, 0];
  for (let dy = -1; dy <= 1; dy++)
    for (let dx = -1; dx <= 1; dx++) image.pixel(x + dx, y + dy).forEach((c, k) => { sum[k] += c / 9; });
  return sum;
}

test('the Cornell box page loads with no console error and no network request', async () => {
  const { page, problems, requests } = await open(cornellPage);
  assert.deepEqual(problems, []);
  assert.deepEqual(requests, [`file://${cornellPage}`]);
  await page.close();
});

test('the screenshot shows the red wall left, the green wall right, the light brightest', async () => {
  const { page } = await open(cornellPage);
  const { image } = await canvasShot(page, join(tmp, 'cornell_viewer.png'));
  assert.equal(image.width, 512);
  assert.equal(image.height, 512);
  const left = meanColour(image, project(LEFT_WALL_POINT, image.width, image.height));
  const right = meanColour(image, project(RIGHT_WALL_POINT, image.width, image.height));
  const light = meanColour(image, project(LIGHT_CENTRE, image.width, image.height));
  const floor = meanColour(image, project(FLOOR_POINT, image.width, image.height));
  assert.ok(left[0] > 100 && left[0] > 2 * left[1] && left[0] > 2 * left[2], `left wall ${left}`);
  assert.ok(right[1] > 100 && right[1] > 1.3 * right[0] && right[1] > 2 * right[2], `right wall ${right}`);
  const luma = (c) => 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
  assert.ok(light.every((c) => c >= 250), `the light is white (clamped): ${light}`);
  for (const other of [left, right, floor]) assert.ok(luma(light) > luma(other) + 50, `light ${light} vs ${other}`);
  await page.close();
});

test('a click on the floor shows "floor" and its area', async () => {
  const { page, problems } = await open(cornellPage);
  const canvas = await page.$('#view canvas');
  const box = await canvas.boundingBox();
  const [x, y] = project(FLOOR_POINT, box.width, box.height);
  await page.mouse.click(box.x + x, box.y + y);
  await page.waitForFunction(() => document.getElementById('picked').dataset.surface !== undefined);
  const name = await page.$eval('[data-field="name"]', (e) => e.textContent);
  const area = await page.$eval('[data-field="area"]', (e) => e.textContent);
  const material = await page.$eval('[data-field="material"]', (e) => e.textContent);
  assert.equal(name, 'floor');
  assert.equal(material, 'white');
  near(parseFloat(area), floorArea(), 1e-5, 'floor area (mm^2)');
  const radiance = await page.$eval('[data-field="radiance"]', (e) => e.textContent);
  assert.match(radiance, /relative$/);
  assert.deepEqual(problems, []);
  await page.close();
});

// the box's light is an emitting surface, in no known unit: the legend says "relative"
test('the false-colour legend spans the data, radiance and illuminance, relative units', async () => {
  const html = readFileSync(cornellPage, 'utf8');
  const { page, problems } = await open(cornellPage);
  for (const [mode, attribute, unit] of [['1', '_RADIANCE', 'luminance (relative)'], ['2', '_ILLUMINANCE', 'illuminance (relative)']]) {
    await page.select('#mode', mode);
    const title = await page.$eval('#legend-title', (e) => e.textContent);
    assert.ok(title.includes(unit), `legend title '${title}' names ${unit}`);
    const ticks = await page.$$eval('#legend-ticks .tick', (es) => es.map((e) => [e.textContent, Number(e.dataset.value)]));
    assert.equal(ticks.length, 6);
    const { lo, hi } = luminanceRange(embeddedAttribute(html, attribute));
    const [top, bottom] = [ticks[0], ticks[ticks.length - 1]];
    near(top[1], hi, 1e-6, `${attribute} legend top value`);
    near(bottom[1], lo, 1e-6, `${attribute} legend bottom value`);
    near(parseFloat(top[0]), hi, 5e-3, `${attribute} legend top text`);
    near(parseFloat(bottom[0]), lo, 5e-3, `${attribute} legend bottom text`);
  }
  // in false colour the light, the brightest, is the scale's top colour (red)
  await page.select('#mode', '1');
  await page.evaluate(() => new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done))));
  const { image } = await canvasShot(page, join(tmp, 'cornell_false_colour.png'));
  const light = meanColour(image, project(LIGHT_CENTRE, image.width, image.height));
  assert.ok(light[0] > 200 && light[1] < 40 && light[2] < 40, `the light in false colour: ${light}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('the exposure slider scales the shown radiance by 2^EV', async () => {
  const { page, problems } = await open(cornellPage);
  const linear = (v) => { const c = v / 255; return c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4); };
  const shot = async (ev, name) => {
    await page.evaluate((value) => {
      const slider = document.getElementById('exposure');
      slider.value = String(value);
      slider.dispatchEvent(new Event('input'));
    }, ev);
    await page.evaluate(() => new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done))));
    return (await canvasShot(page, join(tmp, name))).image;
  };
  const backWall = [420, 420, 559.2]; // the back wall, left of both blocks as the camera sees it
  const at = (image) => meanColour(image, project(backWall, image.width, image.height));
  // from -1 EV: at 0 EV the back wall's green there sits at the top of the mid-tone
  // window (240.1 of 255 once the vertices' second gather moved the lit mesh's values by
  // tenths of a percent; the automatic scale went 5.777 -> 5.771), too near clipping
  const base = at(await shot(-1, 'exposure_minus_1.png'));
  const darker = at(await shot(-2, 'exposure_minus_2.png'));
  const darkest = at(await shot(-4, 'exposure_minus_4.png'));
  assert.ok(base[1] > 60 && base[1] < 240, `a mid-tone pixel: ${base}`);
  near(linear(darker[1]) / linear(base[1]), 0.5, 0.04, 'green at -2 EV over -1 EV');
  near(linear(darkest[1]) / linear(base[1]), 0.125, 0.08, 'green at -4 EV over -1 EV');
  assert.equal(await page.$eval('#exposure-value', (e) => e.textContent), '-4.0 EV');
  assert.deepEqual(problems, []);
  await page.close();
});

test('walking: W moves the eye forward by 2 % of the bounding radius a press', async () => {
  const html = readFileSync(cornellPage, 'utf8');
  const { page, problems } = await open(cornellPage);
  // the bounding sphere as the viewer takes it: the box's centre, the farthest vertex
  const p = embeddedAttribute(html, 'POSITION');
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let k = 0; k < p.length; k++) { lo[k % 3] = Math.min(lo[k % 3], p[k]); hi[k % 3] = Math.max(hi[k % 3], p[k]); }
  const centre = lo.map((x, k) => (x + hi[k]) / 2);
  let radius = 0;
  for (let k = 0; k < p.length; k += 3) radius = Math.max(radius, Math.hypot(p[k] - centre[0], p[k + 1] - centre[1], p[k + 2] - centre[2]));
  const presses = 10;
  await page.click('#view canvas', { offset: { x: 5, y: 5 } });
  for (let k = 0; k < presses; k++) await page.keyboard.press('w');
  await page.evaluate(() => new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done))));
  const { image } = await canvasShot(page, join(tmp, 'walked.png'));
  const step = presses * 0.02 * radius; // along +z, the view's horizontal forward
  const moved = { ...CAMERA, eye: [CAMERA.eye[0], CAMERA.eye[1], CAMERA.eye[2] + step],
    target: [CAMERA.target[0], CAMERA.target[1], CAMERA.target[2] + step] };
  const saved = { ...CAMERA };
  Object.assign(CAMERA, moved);
  const lightNow = meanColour(image, project(LIGHT_CENTRE, image.width, image.height));
  const leftNow = meanColour(image, project(LEFT_WALL_POINT, image.width, image.height));
  Object.assign(CAMERA, saved);
  const lightBefore = meanColour(image, project(LIGHT_CENTRE, image.width, image.height));
  assert.ok(lightNow.every((c) => c >= 250), `the light where it projects after the walk: ${lightNow}`);
  assert.ok(!lightBefore.every((c) => c >= 250), `not where it was before: ${lightBefore}`);
  assert.ok(leftNow[0] > 2 * leftNow[1], `the red wall where it projects after the walk: ${leftNow}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('a lit mesh from `solve -o X.glb` opens as it is, picking shows the value there', async () => {
  const { page, problems, requests } = await open(glbPage);
  assert.deepEqual(requests, [`file://${glbPage}`]);
  const canvas = await page.$('#view canvas');
  const box = await canvas.boundingBox();
  await page.mouse.click(box.x + box.width / 2, box.y + box.height / 2);
  await page.waitForFunction(() => document.getElementById('picked').dataset.surface !== undefined);
  const value = await page.$eval('[data-field="point-radiance"]', (e) => e.textContent);
  assert.ok(parseFloat(value) > 0, `value at the point: ${value}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('the page is the same bytes for 1 and 2 threads', () => {
  const one = join(tmp, 'threads1.html'), two = join(tmp, 'threads2.html');
  execFileSync(tool, ['view', '--threads', '1', '-o', one, '--quiet']);
  execFileSync(tool, ['view', '--threads', '2', '-o', two, '--quiet']);
  assert.ok(readFileSync(one).equals(readFileSync(two)));
});

test('bad input: one line naming the file, non-zero exit, no page written', () => {
  const glb = readFileSync(cornellGlb);
  const cases = [
    ['truncated.glb', glb.subarray(0, glb.length - 100)],
    ['bad_index.glb', (() => { const b = Buffer.from(glb); b.writeUInt32LE(0xfffffff0, b.length - 4); return b; })()],
    ['empty.glb', Buffer.alloc(0)],
    ['nan_radiance.glb', (() => {
      const b = Buffer.from(glb);
      const jsonLength = b.readUInt32LE(12);
      const gltf = JSON.parse(b.toString('utf8', 20, 20 + jsonLength));
      const accessor = gltf.accessors[gltf.meshes[0].primitives[0].attributes._RADIANCE];
      b.writeFloatLE(NaN, 20 + jsonLength + 8 + gltf.bufferViews[accessor.bufferView].byteOffset + 12 * 5);
      return b;
    })()],
  ];
  for (const [name, bytes] of cases) {
    const input = join(tmp, name);
    const output = join(tmp, `${name}.html`);
    writeFileSync(input, bytes);
    const run = spawnSync(tool, ['view', input, '-o', output], { encoding: 'utf8' });
    assert.notEqual(run.status, 0, `${name}: exit status`);
    assert.equal(run.signal, null, `${name}: no crash`);
    const lines = run.stderr.trim().split('\n');
    assert.equal(lines.length, 1, `${name}: one line: ${run.stderr}`);
    assert.ok(lines[0].includes(input), `${name}: names the file: ${lines[0]}`);
    assert.equal(existsSync(output), false, `${name}: no page`);
  }
  const clobber = spawnSync(tool, ['view', cornellGlb, '-o', cornellGlb], { encoding: 'utf8' });
  assert.equal(clobber.status, 2, 'an output that is not .html is a usage error');
  assert.ok(readFileSync(cornellGlb).equals(glb), 'the input is left as it was');
  const missing = spawnSync(tool, ['view', join(tmp, 'missing.glb'), '-o', join(tmp, 'm.html')], { encoding: 'utf8' });
  assert.notEqual(missing.status, 0);
  assert.ok(missing.stderr.includes('missing.glb'));
});
