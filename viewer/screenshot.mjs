// screenshot.mjs - opens a page `radiosity view` wrote in headless chromium, waits for its
// first frame, prints how long that took and how much memory the page holds, and writes a
// screenshot: for the README's images and the load-time figures. Not a test.
//
//   node screenshot.mjs PAGE.html OUT.png [--mode M] [--pick X,Y] [--edges E] [--size WxH]
//     --mode   0 colour, 1 radiance in false colour, 2 illuminance in false colour,
//              viewfactors, difference, compare-b, grid (when the page has them)
//     --pick   click the canvas at X,Y (pixels from its top left) first
//     --edges  patches or triangles: draw those edges
//     --drag DX,DY   orbit first: drag the canvas DX,DY pixels from its centre
//     --keys KEYS    then press these keys (w a s d q e: walk)
import puppeteer from 'puppeteer-core';
import { readFileSync, readdirSync } from 'node:fs';
import { resolve } from 'node:path';

// The resident memory of the process tree under `root` (Linux /proc), bytes.
function treeResidentBytes(root) {
  const parent = new Map(), rss = new Map();
  for (const name of readdirSync('/proc')) {
    if (!/^[0-9]+$/.test(name)) continue;
    try {
      const status = readFileSync(`/proc/${name}/status`, 'utf8');
      parent.set(Number(name), Number(status.match(/^PPid:\s+(\d+)/m)[1]));
      const match = status.match(/^VmRSS:\s+(\d+) kB/m);
      rss.set(Number(name), match ? Number(match[1]) * 1024 : 0);
    } catch { /* the process ended meanwhile */ }
  }
  let total = 0;
  for (const [pid, bytes] of rss) {
    for (let p = pid; p; p = parent.get(p)) if (p === root) { total += bytes; break; }
  }
  return total;
}

const args = process.argv.slice(2);
const option = (name) => {
  const k = args.indexOf(name);
  return k >= 0 ? args[k + 1] : null;
};
const [pagePath, out] = args;
if (!pagePath || !out) {
  console.error('usage: node screenshot.mjs PAGE.html OUT.png [--mode M] [--pick X,Y] [--edges E] [--size WxH]');
  process.exit(2);
}
const [width, height] = (option('--size') || '812x512').split('x').map(Number);
const browser = await puppeteer.launch({
  executablePath: process.env.RAD_CHROMIUM || '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
try {
  const page = await browser.newPage();
  await page.setViewport({ width, height, deviceScaleFactor: 1 });
  page.on('pageerror', (e) => console.error(`page error: ${e.message}`));
  const t0 = Date.now();
  await page.goto(`file://${resolve(pagePath)}`, { timeout: 600000 });
  await page.waitForFunction(() => document.body.dataset.ready && Number(document.body.dataset.frames || 0) > 0,
    { timeout: 600000, polling: 100 });
  const seconds = (Date.now() - t0) / 1000;
  const pageMs = await page.evaluate(() => Number(document.body.dataset.firstFrameMs));
  console.log(`${pagePath}: the page's own clock: first frame ${(pageMs / 1000).toFixed(2)} s after navigation began`);
  const metrics = await page.metrics();
  const rss = treeResidentBytes(browser.process().pid);
  console.log(`${pagePath}: first frame after ${seconds.toFixed(2)} s (navigation to first frame), ` +
    `JS heap ${(metrics.JSHeapUsedSize / 1e6).toFixed(0)} MB used, ` +
    `chromium's processes ${(rss / 1e6).toFixed(0)} MB resident`);
  const drag = option('--drag');
  if (drag) {
    const box = await (await page.$('#view canvas')).boundingBox();
    const [dx, dy] = drag.split(',').map(Number);
    const [cx, cy] = [box.x + box.width / 2, box.y + box.height / 2];
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    for (let k = 1; k <= 10; k++) await page.mouse.move(cx + (dx * k) / 10, cy + (dy * k) / 10);
    await page.mouse.up();
  }
  const keys = option('--keys');
  if (keys) {
    if (!drag) await page.mouse.click(5, 5); // the page takes the keys
    for (const key of keys) await page.keyboard.press(key);
  }
  // a control's change, timed to the second frame after it
  const timed = async (what, change) => {
    const t = Date.now();
    await change();
    await page.evaluate(() => new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done))));
    console.log(`${what} drawn after ${((Date.now() - t) / 1000).toFixed(2)} s`);
  };
  const mode = option('--mode');
  if (mode) await timed(`mode ${mode}`, () => page.select('#mode', mode));
  const edges = option('--edges');
  if (edges) await timed(`${edges} edges`, () => page.select('#edges', edges));
  const pick = option('--pick');
  if (pick) {
    const box = await (await page.$('#view canvas')).boundingBox();
    const [x, y] = pick.split(',').map(Number);
    const t1 = Date.now();
    await page.mouse.click(box.x + x, box.y + y);
    await page.waitForFunction(() => document.getElementById('picked').dataset.surface !== undefined,
      { polling: 10 });
    console.log(`picked '${await page.$eval('#picked', (e) => e.dataset.surface)}' after ` +
      `${((Date.now() - t1) / 1000).toFixed(2)} s`);
  }
  await page.evaluate(() => new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done))));
  await page.screenshot({ path: out });
  console.log(`${pagePath}: chromium's processes ${(treeResidentBytes(browser.process().pid) / 1e6).toFixed(0)} MB resident at the end`);
} finally {
  await browser.close();
}
