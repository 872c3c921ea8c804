// The report's 3-D view in a real headless Chromium (docs/report.md), driven by playwright-core (web/package.json).
// Usage: node tests/report_view_test.mjs SEAM_BINARY MODEL OUT_DIR [--all-faces-shaded]
//        (CTest: report_view_browser; report_view_browser_brep on a STEP file with trimmed faces)
// Writes OUT_DIR/report.html with `seam report`, opens it from file:// and checks: no console error or page error,
// the WebGL canvas is not blank (pixel variance of a screenshot), zebra stripes change the picture, a click on a
// seam opens its three plots in the side panel, value labels name the worst gaps and kinks; without WebGL
// (getContext refused) the 2-D drawing is the view.
// Exit 0 on success, 1 with the failures on stderr.
import { spawnSync } from 'node:child_process';
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.join(here, '..', 'web', 'package.json'));
const { chromium } = require('playwright-core');

const [seam, model, outDir, option] = process.argv.slice(2);
// --all-faces-shaded: every face (patch) of the model is a mesh of the view; for a STEP/IGES file with trimmed faces,
// those are OpenCASCADE's triangulations (issue 17 §4). The count comes from `seam check MODEL --json`.
const allFacesShaded = option === '--all-faces-shaded';
if (!seam || !model || !outDir) {
  console.error('usage: node report_view_test.mjs SEAM_BINARY MODEL OUT_DIR');
  process.exit(2);
}
const failures = [];
const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures.push(what);
};
const t0 = Date.now();

fs.mkdirSync(outDir, { recursive: true });
const html = path.join(outDir, 'report.html');
fs.rmSync(html, { force: true });
const gen = spawnSync(seam, ['report', model, '-o', html], { encoding: 'utf8' });
if (gen.status !== 0) {
  console.error(`seam report failed (${gen.status}): ${gen.stderr}`);
  process.exit(1);
}
const size = fs.statSync(html).size;
console.log(`report: ${html} (${(size / 1024).toFixed(0)} KiB)`);

const browser = await chromium.launch({
  executablePath: process.env.SEAM_CHROMIUM || '/usr/bin/chromium',
  // --no-sandbox: Chromium refuses to run as root otherwise; SwiftShader: WebGL without a GPU.
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
  const errors = [];
  const requests = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  page.on('request', (r) => { if (!r.url().startsWith('file:') && !r.url().startsWith('data:')) requests.push(r.url()); });
  await page.goto(pathToFileURL(html).href);
  await page.waitForFunction(() => window.seamView && window.seamView.ready, null, { timeout: 60000 });
  const info = await page.evaluate(() => ({ seams: window.seamView.seams, meshes: window.seamView.meshes }));
  check(info.seams > 0 && info.meshes > 0, `view holds ${info.meshes} meshes and ${info.seams} seams`);
  const checked = JSON.parse(spawnSync(seam, ['check', model, '--json'], { encoding: 'utf8', maxBuffer: 1 << 28 }).stdout);
  if (allFacesShaded) {
    const faces = checked.model.patches;
    check(info.meshes === faces, `every face is shaded: ${info.meshes} meshes for ${faces} faces`);
  }
  // Free (naked) edges have their own colour and legend entry (issue 38 §9): as many as `seam check` finds.
  const naked = await page.evaluate(() => ({
    n: window.seamView.nakedEdges,
    legend: [...document.querySelectorAll('#view3d-ui .legend span')].some((e) => /free \(naked\) edge/.test(e.textContent)),
  }));
  check(naked.n === checked.free_edges.length && naked.legend,
        `free edges drawn: ${naked.n} (seam check: ${checked.free_edges.length}), legend entry: ${naked.legend}`);

  // Pixel statistics of a PNG screenshot, decoded by the browser itself.
  const stats = async (png) => page.evaluate(async (b64) => {
    const img = new Image();
    img.src = 'data:image/png;base64,' + b64;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width; c.height = img.height;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    let s = 0, s2 = 0, nonWhite = 0;
    const n = d.length / 4;
    for (let i = 0; i < d.length; i += 4) {
      const y = 0.299 * d[i] + 0.587 * d[i + 1] + 0.114 * d[i + 2];
      s += y; s2 += y * y;
      if (y < 245) ++nonWhite;
    }
    const mean = s / n;
    return { variance: s2 / n - mean * mean, nonWhite: nonWhite / n };
  }, png.toString('base64'));
  const canvas = page.locator('#view3d-canvas canvas');
  const shot = await canvas.screenshot({ path: path.join(outDir, 'view.png') });
  const st = await stats(shot);
  check(st.variance > 50 && st.nonWhite > 0.05,
        `canvas is not blank (luminance variance ${st.variance.toFixed(1)}, ${(100 * st.nonWhite).toFixed(1)} % not white)`);
  // The blank test itself must be able to fail: an empty white canvas of the same size.
  const blank = await page.evaluate(() => {
    const c = document.createElement('canvas');
    c.width = 200; c.height = 100;
    const g = c.getContext('2d');
    g.fillStyle = '#fff'; g.fillRect(0, 0, 200, 100);
    return c.toDataURL('image/png').split(',')[1];
  });
  const bst = await stats(Buffer.from(blank, 'base64'));
  check(!(bst.variance > 50 && bst.nonWhite > 0.05), 'the blank check rejects a white canvas');

  // Zebra stripes change the picture.
  await page.check('#view3d-zebra');
  const zshot = await canvas.screenshot({ path: path.join(outDir, 'zebra.png') });
  check(!zshot.equals(shot) && (await stats(zshot)).variance > 50, 'zebra stripes change the picture');
  await page.uncheck('#view3d-zebra');
  await page.selectOption('#view3d-spikes', 'g1');
  await canvas.screenshot({ path: path.join(outDir, 'spikes.png') });
  // The spikes' noise floor: none below the angle tolerance (or the curvature tolerance), which `seam check` states;
  // the scale line says so.
  for (const m of ['g1', 'g2']) {
    const sp = await page.evaluate((mm) => window.seamView.spikes(mm), m);
    const want = m === 'g1' ? checked.tolerances.angle_deg : checked.tolerances.curvature_rel;
    check(sp.tol === want && (sp.drawn === 0 || sp.minDrawn >= want),
          `${m} spikes: ${sp.drawn} drawn, smallest ${sp.minDrawn}, tolerance ${sp.tol} (seam check: ${want})`);
  }
  const scaleText = await page.evaluate(() => document.getElementById('view3d-spike-scale').textContent);
  check(/tolerance/.test(scaleText), `the spike scale names the noise floor: "${scaleText}"`);
  await page.selectOption('#view3d-spikes', 'none');

  // Value labels (issue 38 §11): the worst gaps and kinks by `seam check --json` (its verdicts and numbers, not the
  // report's), at most 12, kinks before gaps, the largest values first; each label's number is the check's value to
  // its 4 digits; the checkbox hides them.
  {
    const labels = await page.evaluate(() => window.seamView.labels());
    const seams = [];   // by the seam's index (the report's #k)
    checked.seams.forEach((s, i) => { seams[s.index ?? i] = s; });
    const value = (s) => (s.verdict === 'kink' ? s.g1_max_deg : s.g0_max);
    const problem = (s) => !!s && (s.verdict === 'kink' || s.verdict === 'gap');
    const nProblems = seams.filter(problem).length;
    check(labels.length === Math.min(12, nProblems),
          `value labels: ${labels.length} (gaps and kinks by seam check: ${nProblems}, at most 12)`);
    const bad = labels.filter((l) => {
      const s = seams[l.k];
      const m = /^#(\d+) (kink|gap) ([-+0-9.e]+)/.exec(l.text);
      if (!s || !problem(s) || !m || Number(m[1]) !== l.k || m[2] !== s.verdict) return true;
      // The report's table values are `seam check`'s, bit for bit (the plots' samples are measured apart): the
      // label differs from the check's value by its rounding to 4 significant digits only.
      return Math.abs(Number(m[3]) - value(s)) > 5.01e-4 * Math.abs(value(s));
    });
    check(bad.length === 0, `each label names a gap or kink with its value${bad.length ? ': ' + JSON.stringify(bad) : ''}`);
    // The worst ones: no unlabelled kink above the smallest labelled kink; a gap labelled only when every kink is.
    const isLabelled = new Set(labels.map((l) => l.k));
    const kinks = seams.map((s, k) => ({ s, k })).filter(({ s }) => s && s.verdict === 'kink');
    const labelledKinks = kinks.filter(({ k }) => isLabelled.has(k)).map(({ s }) => s.g1_max_deg);
    const floor = labelledKinks.length ? Math.min(...labelledKinks) : Infinity;
    const passed = kinks.filter(({ s, k }) => !isLabelled.has(k) && s.g1_max_deg > floor * (1 + 1e-9));
    const gapsEarly = labels.some((l) => seams[l.k].verdict === 'gap') && labelledKinks.length < kinks.length;
    check(passed.length === 0 && !gapsEarly,
          `the labels go to the worst seams (${passed.length} larger kinks passed over, gaps before kinks: ${gapsEarly})`);
    if (labels.length) {
      await page.uncheck('#view3d-labels');
      const hidden = await page.evaluate(() => window.seamView.labels().every((l) => !l.shown));
      await page.check('#view3d-labels');
      const shown = await page.evaluate(() => window.seamView.labels().some((l) => l.shown));
      check(hidden && shown, `the checkbox hides the labels (${hidden}) and shows them again (${shown})`);
    }
  }

  // Click a seam that has plots and no other seam near its middle on screen.
  const target = await page.evaluate(() => {
    const r = document.querySelector('#view3d-canvas canvas').getBoundingClientRect();
    for (const k of window.seamView.seamIndices()) {
      const p = window.seamView.seamScreenPoint(k);
      if (p.plot && p.clear && p.x > r.left + 5 && p.x < r.right - 5 && p.y > r.top + 5 && p.y < r.bottom - 5)
        return { k, x: p.x, y: p.y };
    }
    return null;
  });
  check(target !== null, 'a seam with plots can be clicked');
  if (target) {
    await page.mouse.click(target.x, target.y);
    const panel = page.locator(`#view3d-panel[data-seam="${target.k}"]`);
    await panel.waitFor({ timeout: 5000 }).catch(() => {});
    const plots = await page.locator('#view3d-panel svg.plot').count();
    check(plots === 3, `clicking seam #${target.k} opens its plots (${plots} plots in the panel)`);
    await page.locator('.v3row').screenshot({ path: path.join(outDir, 'clicked.png') });
  }
  // Without WebGL the 3-D view steps aside and the 2-D drawing is the view.
  const flat = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
  flat.on('console', (m) => { if (m.type() === 'error') errors.push(`console (no WebGL): ${m.text()}`); });
  flat.on('pageerror', (e) => errors.push(`page error (no WebGL): ${e.message}`));
  await flat.addInitScript(() => {
    const get = HTMLCanvasElement.prototype.getContext;
    HTMLCanvasElement.prototype.getContext = function (type, ...rest) {
      return /webgl/.test(type) ? null : get.call(this, type, ...rest);
    };
  });
  await flat.goto(pathToFileURL(html).href);
  await flat.waitForLoadState('load');
  const fallback = await flat.evaluate(() => ({
    hidden: getComputedStyle(document.getElementById('view3d')).display === 'none',
    open: document.getElementById('view2d').open,
    drawn: document.querySelectorAll('#view2d svg polyline').length,
    note: document.getElementById('view3d-note').textContent,
    view: !!window.seamView,
  }));
  check(fallback.hidden && fallback.open && fallback.drawn > 0 && !fallback.view && /WebGL/.test(fallback.note),
        `without WebGL the 2-D drawing is the view (${fallback.drawn} polylines)`);
  check(requests.length === 0, `no network requests (${requests.join(' ')})`);
  check(errors.length === 0, `no console errors${errors.length ? ': ' + errors.join(' | ') : ''}`);
} finally {
  await browser.close();
}
console.log(`time: ${((Date.now() - t0) / 1000).toFixed(1)} s`);
if (failures.length) {
  console.error(`${failures.length} check(s) failed: ${failures.join('; ')}`);
  process.exit(1);
}
