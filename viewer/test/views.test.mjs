// views.test.mjs - the optional views of the page `radiosity view` writes, in headless
// chromium (browser.mjs): a view-factor row on a box against Howell's closed forms for
// parallel rectangles (the legend's ends, the row sum, hotter pixels where F is larger),
// patch and triangle edges (the lines' count against the test's own welding of the .glb,
// and a known patch edge on the Cornell box's back wall drawn only when asked), the
// difference of two solutions (zero against itself; two solvers within the solver's
// tolerance, the legend's ends read from the two embedded meshes), and an illuminance grid
// (the legend's ends and a picked point against the `illuminance` table; the colours at
// two points); bad --compare and --grid input refused in one line.
//
//   RADIOSITY=build/radiosity RAD_CHROMIUM=/usr/bin/chromium node --test viewer/test/views.test.mjs
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync, spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import {
  block, canvasShot, defaultCamera, drawn, launch, luma, meanColour, near, open, project, readGlb,
} from './browser.mjs';
import { scaleColour, SCALE_COLOURS } from '../src/false_colour.js';

const here = dirname(fileURLToPath(import.meta.url));
const tool = resolve(process.env.RADIOSITY || join(here, '..', '..', 'build', 'radiosity'));
const tmp = resolve(process.env.RAD_TEST_TMP || join(here, '..', 'dist', 'test-tmp'), 'views');
mkdirSync(tmp, { recursive: true });

// The Cornell box's published camera (the built-in scene's).
const CORNELL = { eye: [278, 273, -800], target: [278, 273, 0], up: [0, 1, 0],
  fov: 2 * Math.atan(0.0125 / 0.035) * 180 / Math.PI };
const CORNELL_POINTS = [[556, 274.4, 279.6], [0, 274.4, 279.6], [500, 0, 100], [420, 420, 559.2]];

// A 1 x 0.5 x 1 box (x, y, z), its six faces turned inward, one OBJ object each.
const BOX = `v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 0 0.5 0\nv 1 0.5 0\nv 1 0.5 1\nv 0 0.5 1
o floor\nf 4 3 2 1\no ceiling\nf 6 7 8 5\no south\nf 2 6 5 1\no north\nf 8 7 3 4
o west\nf 5 8 4 1\no east\nf 3 7 6 2\n`;

// Howell's C-11: two parallel, directly opposed a x b rectangles c apart.
function parallelRectangles(a, b, c) {
  const X = a / c, Y = b / c;
  return (2 / (Math.PI * X * Y)) * (Math.log(Math.sqrt(((1 + X * X) * (1 + Y * Y)) / (1 + X * X + Y * Y)))
    + X * Math.sqrt(1 + Y * Y) * Math.atan(X / Math.sqrt(1 + Y * Y))
    + Y * Math.sqrt(1 + X * X) * Math.atan(Y / Math.sqrt(1 + X * X)) - X * Math.atan(X) - Y * Math.atan(Y));
}

function legendTicks(page) {
  return page.$$eval('#legend-ticks .tick', (es) => es.map((e) => Number(e.dataset.value)));
}

function lum(rgb, v) { return 0.2126 * rgb[3 * v] + 0.7152 * rgb[3 * v + 1] + 0.0722 * rgb[3 * v + 2]; }

let browser;
const boxObj = join(tmp, 'box.obj'), boxPage = join(tmp, 'box.html');
const cornellPage = join(tmp, 'cornell.html');
const directGlb = join(tmp, 'direct.glb'), gatherGlb = join(tmp, 'gather.glb');
const gridCsv = join(tmp, 'grid.csv'), gridPage = join(tmp, 'grid.html');

before(async () => {
  writeFileSync(boxObj, BOX);
  execFileSync(tool, ['view', boxObj, '--emit', 'ceiling=1,1,1', '--viewfactors', '-o', boxPage, '--quiet']);
  execFileSync(tool, ['view', '-o', cornellPage, '--quiet']);
  execFileSync(tool, ['solve', '--solver', 'direct', '-o', directGlb, '--quiet']);
  execFileSync(tool, ['solve', '--solver', 'gather', '-o', gatherGlb, '--quiet']);
  execFileSync(tool, ['illuminance', '--plane', '100', '--spacing', '40', '--gather-rays', '1024',
    '-o', gridCsv, '--quiet']);
  execFileSync(tool, ['view', '--grid', gridCsv, '-o', gridPage, '--quiet']);
  browser = await launch();
});

after(async () => {
  if (browser) await browser.close();
});

test('a view-factor row: the box floor against the closed forms', async () => {
  const html = readFileSync(boxPage, 'utf8');
  const { page, problems, requests } = await open(browser, boxPage);
  assert.deepEqual(requests, [`file://${boxPage}`]);
  await page.select('#mode', 'viewfactors');
  const camera = defaultCamera(readGlb(block(html, 'radiosity-glb')).position);
  const canvas = await (await page.$('#view canvas')).boundingBox();
  const [x, y] = project(camera, [0.5, 0, 0.3], canvas.width, canvas.height);
  await page.mouse.click(canvas.x + x, canvas.y + y);
  await page.waitForFunction(() => document.getElementById('picked').dataset.surface === 'floor');
  await drawn(page);
  const field = (name) => page.$eval(`[data-field="${name}"]`, (e) => e.textContent);
  assert.equal(await field('name'), 'floor');
  near(parseFloat(await field('area')), 1, 1e-9, 'floor area');
  // the floor's row: the ceiling 0.5 above it, the four walls share the rest (closed box)
  const top = parallelRectangles(1, 1, 0.5), wall = (1 - top) / 4;
  near(parseFloat(await field('row-sum')), 1, 1e-4, 'row sum shown');
  // the row sum shown is the embedded row's (6 digits), read here from the block
  const bytes = block(html, 'radiosity-viewfactors');
  const n = bytes.readUInt32LE(0), nonzeros = bytes.readUInt32LE(4);
  const valuesAt = Math.ceil((4 * (2 + n + 1 + nonzeros)) / 8) * 8;
  let sum = 0;
  for (let k = bytes.readUInt32LE(8); k < bytes.readUInt32LE(12); k++) sum += bytes.readDoubleLE(valuesAt + 8 * k);
  near(parseFloat(await field('row-sum')), sum, 5e-6 * sum, 'row sum shown against the block');
  const ticks = await legendTicks(page);
  near(ticks[0], top, 2e-4 * top, 'legend top: F floor -> ceiling (Howell C-11)');
  near(ticks[ticks.length - 1], wall, 2e-4 * wall, 'legend bottom: F floor -> a wall');
  assert.match(await page.$eval('#legend-title', (e) => e.textContent), /dimensionless/);
  const image = await canvasShot(page, join(tmp, 'box_viewfactors.png'));
  const ceiling = meanColour(image, project(camera, [0.5, 0.5, 0.3], image.width, image.height));
  const east = meanColour(image, project(camera, [1, 0.25, 0.2], image.width, image.height));
  const floor = meanColour(image, project(camera, [0.5, 0, 0.3], image.width, image.height));
  const [red, blue] = [SCALE_COLOURS[SCALE_COLOURS.length - 1], SCALE_COLOURS[0]].map((c) => c.map((a) => 255 * a));
  for (const k of [0, 1, 2]) {
    near(ceiling[k], red[k], 6, `the ceiling (largest F) in the scale's top colour, channel ${k}`);
    near(east[k], blue[k], 6, `a wall (smallest F) in the scale's bottom colour, channel ${k}`);
  }
  assert.ok(ceiling[0] > east[0] + 150, `hotter where F is larger: ${ceiling} vs ${east}`);
  assert.ok(floor.every((c) => c > 240), `the picked floor highlighted white: ${floor}`);
  assert.deepEqual(problems, []);
  await page.close();
});

test('units: cd/m² and lux when every light is photometric, else relative', () => {
  const info = (path) => JSON.parse(readFileSync(path, 'utf8').match(
    /<script type="application\/json" id="radiosity-info">([^<]*)<\/script>/)[1]);
  const lit = join(tmp, 'box_point.html');
  execFileSync(tool, ['view', boxObj, '--point', '0.5,0.4,0.5:100', '-o', lit, '--quiet']);
  assert.equal(info(lit).radiance_unit, 'cd/m²');
  assert.equal(info(lit).illuminance_unit, 'lux');
  assert.equal(info(boxPage).radiance_unit, 'relative'); // the ceiling's Ke alone
  assert.equal(info(boxPage).illuminance_unit, 'relative');
});

test('view factors: the page is the same bytes for 1 and 2 threads; a lit mesh has none', () => {
  const one = join(tmp, 'vf1.html'), two = join(tmp, 'vf2.html');
  execFileSync(tool, ['view', boxObj, '--emit', 'ceiling=1,1,1', '--viewfactors', '--threads', '1', '-o', one, '--quiet']);
  execFileSync(tool, ['view', boxObj, '--emit', 'ceiling=1,1,1', '--viewfactors', '--threads', '2', '-o', two, '--quiet']);
  assert.ok(readFileSync(one).equals(readFileSync(two)));
  const run = spawnSync(tool, ['view', directGlb, '--viewfactors', '-o', join(tmp, 'no.html')], { encoding: 'utf8' });
  assert.equal(run.status, 2);
  assert.ok(run.stderr.includes(directGlb) && run.stderr.trim().split('\n').length === 1, run.stderr);
  assert.equal(existsSync(join(tmp, 'no.html')), false);
});

// The test's own edges of the lit mesh: vertices welded by position, each edge with the
// patches of the triangles along it.
function meshEdges(glb, trianglePatch) {
  const id = new Map(), weld = [];
  for (let v = 0; v < glb.position.length / 3; v++) {
    const key = glb.position.slice(3 * v, 3 * v + 3).join(' ');
    if (!id.has(key)) id.set(key, id.size);
    weld.push(id.get(key));
  }
  const edges = new Map();
  for (let t = 0; t < glb.index.length / 3; t++)
    for (let k = 0; k < 3; k++) {
      const a = glb.index[3 * t + k], b = glb.index[3 * t + (k + 1) % 3];
      if (weld[a] === weld[b]) continue;
      const key = `${Math.min(weld[a], weld[b])}-${Math.max(weld[a], weld[b])}`;
      if (!edges.has(key)) edges.set(key, { a, b, patches: new Set() });
      edges.get(key).patches.add(trianglePatch[t]);
      edges.get(key).count = (edges.get(key).count || 0) + 1;
    }
  return [...edges.values()];
}

test('edges: patch and triangle edges on demand, a known patch edge drawn only then', async () => {
  const html = readFileSync(cornellPage, 'utf8');
  const glb = readGlb(block(html, 'radiosity-glb'));
  const patchBytes = block(html, 'radiosity-triangle-patch');
  const trianglePatch = Array.from({ length: patchBytes.length / 4 }, (_, t) => patchBytes.readUInt32LE(4 * t));
  assert.equal(trianglePatch.length, glb.index.length / 3);
  const edges = meshEdges(glb, trianglePatch);
  const patchEdges = edges.filter((e) => e.patches.size > 1 || e.count === 1);
  assert.ok(patchEdges.length > 100 && patchEdges.length < edges.length, `${patchEdges.length} of ${edges.length}`);
  // a patch edge on the back wall (z = 559.2), its middle nearest the upper middle of the view
  const P = (v) => glb.position.slice(3 * v, 3 * v + 3);
  let best = null, bestDistance = Infinity;
  for (const e of patchEdges) {
    if (P(e.a)[2] !== P(e.b)[2] || Math.abs(P(e.a)[2] - 559.2) > 1e-3 || e.patches.size < 2) continue;
    const middle = P(e.a).map((x, k) => (x + P(e.b)[k]) / 2);
    const [x, y] = project(CORNELL, middle, 512, 512);
    const d = Math.hypot(x - 256, y - 130);
    if (d < bestDistance) { best = [x, y]; bestDistance = d; }
  }
  assert.ok(best && bestDistance < 40, `a back-wall patch edge near (256, 130): ${best}`);

  const { page, problems } = await open(browser, cornellPage);
  const darkest = (image) => {
    let least = Infinity;
    for (let dy = -1; dy <= 1; dy++)
      for (let dx = -1; dx <= 1; dx++) least = Math.min(least, luma(image.pixel(best[0] + dx, best[1] + dy)));
    return least;
  };
  const off = darkest(await canvasShot(page, join(tmp, 'edges_off.png')));
  await page.select('#edges', 'patches');
  await drawn(page);
  assert.equal(Number(await page.evaluate(() => document.body.dataset.edges)), patchEdges.length);
  const on = darkest(await canvasShot(page, join(tmp, 'edges_patches.png')));
  assert.ok(off > 100 && on < 0.6 * off, `the back wall at a patch edge: ${off} without lines, ${on} with`);
  await page.select('#edges', 'triangles');
  await drawn(page);
  assert.equal(Number(await page.evaluate(() => document.body.dataset.edges)), edges.length);
  await page.select('#edges', 'none');
  await drawn(page);
  const again = darkest(await canvasShot(page, join(tmp, 'edges_none.png')));
  near(again, off, 1, 'no lines again');
  assert.deepEqual(problems, []);
  await page.close();
});

test('--compare: a solution against itself shows zero difference', async () => {
  const self = join(tmp, 'self.html');
  execFileSync(tool, ['view', directGlb, '--compare', directGlb, '-o', self, '--quiet']);
  const { page, problems } = await open(browser, self);
  await page.select('#mode', 'difference');
  await drawn(page);
  const ticks = await legendTicks(page);
  assert.deepEqual(ticks, [0, 0, 0, 0, 0]);
  const image = await canvasShot(page, join(tmp, 'self_difference.png'));
  const camera = defaultCamera(readGlb(readFileSync(directGlb)).position); // a .glb has none
  for (const point of CORNELL_POINTS) {
    const c = meanColour(image, project(camera, point, image.width, image.height));
    assert.ok(c.every((x) => Math.abs(x - 0.97 * 255) <= 2), `zero is the scale's white middle: ${c}`);
  }
  assert.match(await page.$eval('#compare-summary', (e) => e.textContent), /largest \|A − B\| 0 /);
  assert.deepEqual(problems, []);
  await page.close();
});

test('--compare: Jacobi gathering against the direct LU solve, within the tolerance', async () => {
  const solvers = join(tmp, 'solvers.html');
  execFileSync(tool, ['view', '--solver', 'gather', '--compare', directGlb, '-o', solvers, '--quiet']);
  const html = readFileSync(solvers, 'utf8');
  const a = readGlb(block(html, 'radiosity-glb')), b = readGlb(block(html, 'radiosity-compare-glb'));
  let largest = 0, largestA = 0;
  for (let v = 0; v < a.radiance.length / 3; v++) {
    largest = Math.max(largest, Math.abs(lum(a.radiance, v) - lum(b.radiance, v)));
    largestA = Math.max(largestA, lum(a.radiance, v));
  }
  // the default tolerance, 1e-4 relative residual, bounds the difference
  assert.ok(largest > 0 && largest < 1e-4 * largestA, `largest |A - B| ${largest}, largest A ${largestA}`);
  const { page, problems } = await open(browser, solvers);
  await page.select('#mode', 'difference');
  await drawn(page);
  const ticks = await legendTicks(page);
  assert.equal(ticks.length, 5);
  near(ticks[0], largest, 1e-9 * largestA, 'legend top');
  near(ticks[4], -largest, 1e-9 * largestA, 'legend bottom');
  near(ticks[2], 0, 1e-12, 'legend middle');
  assert.match(await page.$eval('#legend-title', (e) => e.textContent), /A − B, luminance \(relative\)/);
  // B in colour looks as A does (the difference is far below a display level)
  await page.select('#mode', '0');
  await drawn(page);
  const shotA = await canvasShot(page, join(tmp, 'solvers_a.png'));
  await page.select('#mode', 'compare-b');
  await drawn(page);
  const shotB = await canvasShot(page, join(tmp, 'solvers_b.png'));
  for (const point of CORNELL_POINTS) {
    const [pa, pb] = [shotA, shotB].map((s) => meanColour(s, project(CORNELL, point, s.width, s.height)));
    pa.forEach((x, k) => near(pb[k], x, 1, `B against A at ${point}`));
    assert.ok(luma(pa) > 20, `a lit pixel: ${pa}`);
  }
  assert.deepEqual(problems, []);
  await page.close();
});

test('--compare: another geometry is refused in one line, no page', () => {
  const coarse = join(tmp, 'coarse.glb'), out = join(tmp, 'coarse.html');
  execFileSync(tool, ['solve', '--patch-size', '150', '-o', coarse, '--quiet']);
  const run = spawnSync(tool, ['view', directGlb, '--compare', coarse, '-o', out], { encoding: 'utf8' });
  assert.equal(run.status, 1);
  const lines = run.stderr.trim().split('\n');
  assert.equal(lines.length, 1, run.stderr);
  assert.ok(lines[0].includes(coarse), lines[0]);
  assert.equal(existsSync(out), false);
  const notLit = spawnSync(tool, ['view', directGlb, '--compare', boxObj, '-o', out], { encoding: 'utf8' });
  assert.equal(notLit.status, 1);
  assert.ok(notLit.stderr.includes(boxObj) && notLit.stderr.trim().split('\n').length === 1, notLit.stderr);
  assert.equal(existsSync(out), false);
});

test('--grid: the illuminance table in false colour, its legend and a picked point', async () => {
  const rows = readFileSync(gridCsv, 'utf8').trim().split('\n').slice(1).map((l) => l.split(',').map(Number));
  const E = rows.map((r) => r[9]);
  const lo = Math.min(...E), hi = Math.max(...E);
  const { page, problems } = await open(browser, gridPage);
  await page.select('#mode', 'grid');
  await drawn(page);
  const ticks = await legendTicks(page);
  near(ticks[0], hi, 1e-6 * hi, 'legend top: the table\'s largest E');
  near(ticks[ticks.length - 1], lo, 1e-6 * hi, 'legend bottom: the table\'s smallest E');
  // the front row (nearest the camera, nothing in front of it): its brightest and darkest
  const front = Math.min(...rows.map((r) => r[2]));
  const row = rows.filter((r) => r[2] === front);
  const bright = row.reduce((m, r) => (r[9] > m[9] ? r : m)), dark = row.reduce((m, r) => (r[9] < m[9] ? r : m));
  const image = await canvasShot(page, join(tmp, 'grid.png'));
  for (const point of [bright, dark]) {
    const c = meanColour(image, project(CORNELL, point.slice(0, 3), image.width, image.height));
    const expected = scaleColour(SCALE_COLOURS, (point[9] - lo) / (hi - lo)).map((x) => 255 * x);
    expected.forEach((x, k) => near(c[k], x, 12, `grid point ${point.slice(0, 3)} (E ${point[9]}), channel ${k}`));
  }
  const canvas = await (await page.$('#view canvas')).boundingBox();
  const [x, y] = project(CORNELL, bright.slice(0, 3), canvas.width, canvas.height);
  await page.mouse.click(canvas.x + x, canvas.y + y);
  await page.waitForFunction(() => document.querySelector('[data-field="grid-lux"]'));
  const text = await page.$eval('[data-field="grid-lux"]', (e) => e.textContent);
  near(parseFloat(text), bright[9], 5e-3 * bright[9], `picked grid value '${text}'`);
  assert.ok(text.includes(`(${bright[0]}, ${bright[1]}, ${bright[2]})`), text);
  assert.deepEqual(problems, []);
  await page.close();
});

test('--grid: a bad table is refused in one line naming the file and line, no page', () => {
  const table = readFileSync(gridCsv, 'utf8').split('\n');
  const cases = [
    ['nan.csv', [table[0], table[1], table[2].replace(/,[^,]*$/, ',nan'), ...table.slice(3)].join('\n'), ':3:'],
    ['short.csv', [table[0], table[1], '1,2,3', ...table.slice(3)].join('\n'), ':3:'],
    ['normal.csv', [table[0], table[1], table[2].replace(/^([^,]*,[^,]*,[^,]*),[^,]*,[^,]*,[^,]*,/, '$1,0,0,0,'), ...table.slice(3)].join('\n'), ':3:'],
    ['header.csv', ['a,b,c', ...table.slice(1)].join('\n'), ':1:'],
    ['empty.csv', `${table[0]}\n`, 'no points'],
  ];
  for (const [name, text, where] of cases) {
    const input = join(tmp, name), out = join(tmp, `${name}.html`);
    writeFileSync(input, text);
    const run = spawnSync(tool, ['view', directGlb, '--grid', input, '-o', out], { encoding: 'utf8' });
    assert.equal(run.status, 1, `${name}: ${run.stderr}`);
    const lines = run.stderr.trim().split('\n');
    assert.equal(lines.length, 1, `${name}: ${run.stderr}`);
    assert.ok(lines[0].includes(input) && lines[0].includes(where), `${name}: ${lines[0]}`);
    assert.equal(existsSync(out), false, `${name}: no page`);
  }
});
