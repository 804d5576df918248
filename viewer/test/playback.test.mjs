// playback.test.mjs - playback of a recorded shooting solve (`radiosity view --solver shoot
// --record FILE`) in a real headless browser (Debian's chromium, puppeteer-core): the page
// loads with no console error and no request but itself; the slider steps through every
// snapshot of the record, and at each step checked the panel shows that snapshot's step,
// unshot energy and residual (read here from the record file the same run wrote) and
// outlines its shooting patch; the floor is black at step 0 (B = E: only the light glows)
// and lit at the last step; play runs to the last snapshot.
//
//   RADIOSITY=build/radiosity RAD_CHROMIUM=/usr/bin/chromium node --test viewer/test/playback.test.mjs
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { launch, open } from './browser.mjs';
import { decodePng } from './png.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const tool = resolve(process.env.RADIOSITY || join(here, '..', '..', 'build', 'radiosity'));
const tmp = resolve(process.env.RAD_TEST_TMP || join(here, '..', 'dist', 'test-tmp'));
mkdirSync(tmp, { recursive: true });

// The published Cornell box camera (mm) and a floor point in front of both blocks.
const EYE = [278, 273, -800], FOV = 2 * Math.atan(0.0125 / 0.035) * 180 / Math.PI;
const FLOOR_POINT = [500, 0, 100];

// Where a point lands in a width x height view of that camera (it looks along +z, up +y,
// so +x is on the left).
function project(p, width, height) {
  const t = Math.tan((FOV / 2) * Math.PI / 180);
  const depth = p[2] - EYE[2];
  const x = -(p[0] - EYE[0]) / (depth * t * (width / height));
  const y = (p[1] - EYE[1]) / (depth * t);
  return [Math.round(((x + 1) / 2) * width), Math.round(((1 - y) / 2) * height)];
}

// The panel's formatting of a number (playback.js shows three significant digits).
function shown(v) {
  if (v === null) return '–';
  if (v === 0) return '0';
  return Math.abs(v) < 1e-3 || Math.abs(v) >= 1e5 ? v.toExponential(2) : String(Number(v.toPrecision(3)));
}

let browser;
const pagePath = join(tmp, 'playback.html');
const recordPath = join(tmp, 'playback.json');

before(async () => {
  execFileSync(tool, ['view', '--solver', 'shoot', '--patch-size', '60', '--threads', '2',
    '-o', pagePath, '--record', recordPath, '--quiet']);
  browser = await launch();
});

after(async () => {
  if (browser) await browser.close();
});

// Moves the slider to snapshot `index` and waits for the frame that shows it.
async function setStep(page, index) {
  const frames = await page.$eval('#playback-step', (e, v) => {
    const before = Number(document.body.dataset.frames || 0);
    e.value = String(v);
    e.dispatchEvent(new Event('input'));
    return before;
  }, index);
  await page.waitForFunction((n) => Number(document.body.dataset.frames || 0) > n, { timeout: 30000 }, frames);
}

const field = (page, name) => page.$eval(`#playback [data-field="${name}"]`, (e) => e.textContent);

async function canvasImage(page) {
  const canvas = await page.$('#view canvas');
  return decodePng(Buffer.from(await canvas.screenshot()));
}

// How many pixels are the outline's magenta.
function magentaPixels(image) {
  let count = 0;
  for (let y = 0; y < image.height; y++)
    for (let x = 0; x < image.width; x++) {
      const [r, g, b] = image.pixel(x, y);
      if (r > 200 && g < 60 && b > 200) count++;
    }
  return count;
}

test('playback steps through the recorded shooting solve', async () => {
  const record = JSON.parse(readFileSync(recordPath, 'utf8'));
  const snapshots = record.snapshots;
  assert.equal(record.solver, 'shoot');
  assert.ok(snapshots.length >= 50 && snapshots.length <= 200, `${snapshots.length} snapshots`);

  const { page, problems, requests } = await open(browser, pagePath);
  assert.equal(await page.$eval('#playback-step', (e) => e.max), String(snapshots.length - 1));

  // every snapshot, in order: its numbers in the panel
  for (let k = 0; k < snapshots.length; k++) {
    await setStep(page, k);
    const s = snapshots[k];
    assert.equal(await page.$eval('#playback', (e) => e.dataset.index), String(k));
    assert.ok((await field(page, 'step')).startsWith(`${s.step} shots`), `snapshot ${k}`);
    assert.equal(await field(page, 'unshot'), shown(s.unshot), `snapshot ${k} unshot`);
    assert.equal(await field(page, 'residual'), shown(s.residual), `snapshot ${k} residual`);
    assert.equal(await field(page, 'shooting-patch'), s.shooting_patch === null ? '–' : String(s.shooting_patch));
  }

  // the picture follows: at step 0 only the light glows, the floor is black; later the
  // floor is lit and the shooting patch is outlined
  await setStep(page, 0);
  let image = await canvasImage(page);
  const [fx, fy] = project(FLOOR_POINT, image.width, image.height);
  const floorAtStart = image.pixel(fx, fy);
  assert.ok(floorAtStart.slice(0, 3).every((c) => c < 8), `floor at step 0: ${floorAtStart}`);
  assert.equal(magentaPixels(image), 0, 'no shooting patch before the first shot');
  const middle = Math.floor(snapshots.length / 2);
  await setStep(page, middle);
  image = await canvasImage(page);
  assert.ok(magentaPixels(image) > 0, `the shooting patch ${snapshots[middle].shooting_patch} is outlined`);
  await setStep(page, snapshots.length - 1);
  image = await canvasImage(page);
  const floorAtEnd = image.pixel(fx, fy);
  assert.ok(floorAtEnd[0] > 60 && floorAtEnd[1] > 60, `floor at the last step: ${floorAtEnd}`);

  // play from the start runs to the last snapshot
  await setStep(page, 0);
  await page.click('#playback-play');
  await page.waitForFunction((last) => document.getElementById('playback').dataset.index === String(last),
    { timeout: 60000 }, snapshots.length - 1);
  assert.equal(await page.$eval('#playback-play', (e) => e.textContent), 'play');

  assert.deepEqual(problems, []);
  assert.deepEqual(requests, [`file://${pagePath}`]);
  await page.close();
});
