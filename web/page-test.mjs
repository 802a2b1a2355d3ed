// The proxy page in a real browser (Debian's chromium, headless, driven by playwright-core):
// loads it from the file system, waits for it to be drawn, moves what a person moves (a blend
// slider and a click on the body for a blended proxy; two targets' sliders for a morph-target
// body's; the clip's scrubber and play for a skinned one), checks the readout follows, takes screenshots and fails on any console error or page
// exception. What the page computed at each step (the runtime's inputs and its spheres) goes to
// OUT/NAME.page.json, which tests/page_check compares with the runtime header.
//   node page-test.mjs PAGE.html OUT_DIR NAME
import { writeFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { chromium } from 'playwright-core';

const [pagePath, outDir, name] = process.argv.slice(2);
const browserPath = process.env.SPX_CHROMIUM || '/usr/bin/chromium';
const failures = [];
const check = (ok, what) => {
  if (!ok) failures.push(what);
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}: ${what}`);
};

const browser = await chromium.launch({
  executablePath: browserPath,
  args: ['--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader'],
});
const page = await browser.newPage({ viewport: { width: 1280, height: 760 } });
const errors = [];
page.on('console', (m) => m.type() === 'error' && errors.push(`console: ${m.text()}`));
page.on('pageerror', (e) => errors.push(`exception: ${e.message}`));
page.on('requestfailed', (r) => errors.push(`request failed: ${r.url()}`));
page.on('request', (r) => !r.url().startsWith('file:') && !r.url().startsWith('data:') && errors.push(`network: ${r.url()}`));

const dataset = () => page.evaluate(() => ({ ...document.body.dataset }));
const state = () => page.evaluate(() => window.spxPage.state());
const shot = (suffix) => page.screenshot({ path: resolve(outDir, `${name}${suffix}.png`) });
const samples = [];

// Opened in a smaller window first: the body's box is in view beside the panel (330 px).
await page.setViewportSize({ width: 1000, height: 640 });
await page.goto(pathToFileURL(resolve(pagePath)).href);
await page.waitForSelector('body[data-spx-ready="1"]', { timeout: 60000 });
const corners = await page.evaluate(() => window.spxPage.cornersOnPage());
check(corners.every(([x, y]) => x >= 330 && x <= 1000 && y >= 0 && y <= 640),
  `the body's box is in view beside the panel (${corners.map((c) => c.map(Math.round).join(',')).join(' ')})`);
await page.setViewportSize({ width: 1280, height: 760 });
await page.goto(pathToFileURL(resolve(pagePath)).href);
await page.waitForSelector('body[data-spx-ready="1"]', { timeout: 60000 });
const first = await dataset();
samples.push({ what: 'as opened', ...(await state()) });
await shot('');

if (first.mode === 'blend' && Number(first.poses) > 1) {
  // The last example's slider all the way: the spheres and the error move.
  const last = Number(first.poses) - 1;
  await page.locator(`input[data-pose="${last}"]`).fill('1');
  const moved = await dataset();
  const s = await state();
  check(s.weights[last] === 1 && s.weights[0] === 1, `the slider of pose ${last} sets its weight`);
  check(moved.maxError !== first.maxError || first.maxError === 'none', `the readout moves with the slider (${first.maxError} -> ${moved.maxError} %)`);
  samples.push({ what: `pose 0 and ${last} at 1`, ...s });
  await shot('-blend');
  if (first.maxError !== 'none') {
    // A click on the body paints the local blend: site weights appear, the body dents there.
    await page.locator('#spx-local').check();
    await page.selectOption('#spx-paint-pose', String(last));
    await page.locator('#spx-paint-strength').fill('1');
    await page.locator('#spx-paint-radius').fill('30');
    const [x, y] = await page.evaluate(() => window.spxPage.centreOnPage());
    const before = await state();
    await page.mouse.click(x, y);
    const painted = await state();
    check(Array.isArray(painted.siteWeights), 'a click on the body paints site weights (local blend)');
    check(JSON.stringify(painted.xyzr) !== JSON.stringify(before.xyzr), 'the painted spheres move');
    samples.push({ what: 'painted', ...painted });
    await shot('-local');
  }
} else if (first.mode === 'morph') {
  // Two targets all the way, as a host adds them: the spheres and the error move.
  await page.locator('input[data-pose="1"]').fill('1');
  await page.locator('input[data-pose="2"]').fill('1');
  const moved = await dataset();
  const s = await state();
  check(s.morphWeights[0] === 1 && s.morphWeights[1] === 1 && s.morphWeights.slice(2).every((w) => w === 0),
    `the sliders set the morph weights (${s.morphWeights})`);
  check(moved.maxError !== first.maxError, `the readout moves with the sliders (${first.maxError} -> ${moved.maxError} %)`);
  samples.push({ what: 'targets 1 and 2 at 1', ...s });
  await shot('-morph');
} else if (first.mode === 'clip') {
  // Half-way through the first clip by the scrubber, then played for a while.
  const max = Number(await page.locator('#spx-scrubber').getAttribute('max'));
  check(max > 0, `the first clip has frames (${max + 1})`);
  await page.locator('#spx-scrubber').fill(String(Math.floor(max / 2)));
  const mid = await dataset();
  check(Number(mid.frame) === Math.floor(max / 2), `the scrubber sets the frame (${mid.frame})`);
  check(mid.maxError !== first.maxError, `the readout moves with the frame (${first.maxError} -> ${mid.maxError} %)`);
  samples.push({ what: `frame ${mid.frame}`, ...(await state()) });
  await shot('-clip');
  await page.locator('#spx-scrubber').fill(String(max));
  samples.push({ what: `frame ${max}`, ...(await state()) });
  await page.locator('#spx-play').click();
  await page.waitForFunction((f) => document.body.dataset.frame !== f, String(max), { timeout: 10000 }).catch(() => {});
  await page.locator('#spx-play').click();
  check((await dataset()).frame !== String(max), 'play moves the frame');
}

check(errors.length === 0, `no console error, exception or network request${errors.length ? `: ${errors.join('; ')}` : ''}`);
writeFileSync(resolve(outDir, `${name}.page.json`), JSON.stringify({ dataset: first, samples }));
await browser.close();
process.exit(failures.length ? 1 : 0);
