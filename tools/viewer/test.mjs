// Drives Debian's chromium (headless, WebGL on SwiftShader) through report pages opened from file://, with
// every request that is not file:// refused (the network off), and checks each page's 3D viewer:
//  - it loads its plant and scene (<body data-viewer="loaded">) with no console error, page error or
//    failed request, and draws triangles;
//  - the branches/leaves/flowers toggles change what is drawn;
//  - the playback slider (a real mouse click on it) changes what is drawn, and End brings the whole
//    plant back; Play advances the step;
// and prints what it measured. Exit status 1 on any failure.
//   node tools/viewer/test.mjs [--screenshots DIR] [--require-growth] [--require-scene] PAGE.html...
import { fileUrl, launch } from './browser.mjs';
import { mkdirSync } from 'node:fs';
import { basename } from 'node:path';

const args = process.argv.slice(2);
let shots = null, requireGrowth = false, requireScene = false;
const pages = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--screenshots') shots = args[++i];
  else if (args[i] === '--require-growth') requireGrowth = true;
  else if (args[i] === '--require-scene') requireScene = true;
  else pages.push(args[i]);
}
if (!pages.length) { console.error('test.mjs: no pages given'); process.exit(2); }
if (shots) mkdirSync(shots, { recursive: true });

const failures = [];
const fail = (page, what) => { failures.push(`${page}: ${what}`); console.log(`  FAIL ${what}`); };
const browser = await launch(['--use-angle=swiftshader', '--enable-unsafe-swiftshader']);  // WebGL 2 on the CPU
try {
  for (const file of pages) {
    const name = basename(file, '.html');
    console.log(`${name}:`);
    const page = await browser.newPage();
    await page.setViewport({ width: 1100, height: 900 });
    const errors = [], warnings = [], offsite = [];
    page.on('console', m => (m.type() === 'error' ? errors : m.type() === 'warn' ? warnings : []).push(m.text()));
    page.on('pageerror', e => errors.push(`page error: ${e.message}`));
    page.on('requestfailed', r => errors.push(`request failed: ${r.url()} (${r.failure()?.errorText})`));
    await page.setRequestInterception(true);
    page.on('request', r => {
      if (r.url().startsWith('file:') || r.url().startsWith('data:') || r.url().startsWith('blob:')) return r.continue();
      offsite.push(r.url());
      r.abort();
    });
    const t0 = performance.now();
    try {
      await page.goto(fileUrl(file), { waitUntil: 'load' });
    } catch (e) {
      fail(name, `cannot open the page: ${e.message}`);
      await page.close();
      continue;
    }
    const settled = () => page.waitForFunction(() => ['loaded', 'error', 'deferred'].includes(document.body.dataset.viewer),
                                               { timeout: 180000 });
    await settled();
    if (await page.evaluate(() => document.body.dataset.viewer) === 'deferred') {
      console.log(`  deferred: ${await page.$eval('.gb-viewer .gb-load', b => b.textContent)}; clicking it`);
      await page.click('.gb-viewer .gb-load');
      await settled();
    }
    const loadedMs = performance.now() - t0;
    const state = await page.evaluate(() => document.body.dataset.viewer);
    const frame = () => page.evaluate(() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r))));
    const stats = () => page.evaluate(() => GBViewer.viewers[0].stats());
    if (state !== 'loaded') {
      const status = await page.$eval('.gb-viewer .gb-status', e => e.textContent).catch(() => '?');
      fail(name, `viewer state ${state}: ${status}${errors.length ? `\n    ${errors.join('\n    ')}` : ''}`);
      await page.close();
      continue;
    }
    const full = await stats();
    console.log(`  loaded in ${Math.round(loadedMs)} ms (page ${JSON.stringify(full.timings)}), parts ${JSON.stringify(full.parts)}, ` +
                `steps 0..${full.lastStep}, drawn: ${full.frame?.triangles} triangles, ${full.frame?.lines} lines, ` +
                `${full.frame?.calls} calls; plant indices ${full.indices}, instances ${full.instances}`);
    if (!(full.frame?.triangles > 0)) fail(name, 'nothing drawn');
    if (shots) await (await page.$('.gb-viewer')).screenshot({ path: `${shots}/${name}-full.png` });

    // Toggles: each part there is, off and on again.
    for (const part of ['leaves', 'flowers', 'branches']) {
      if (!full.parts[part]) continue;
      await page.click(`.gb-viewer input[data-part=${part}]`);
      await frame();
      const off = await stats();
      if (!(off.frame.triangles < full.frame.triangles)) fail(name, `hiding ${part} drew ${off.frame.triangles} triangles of ${full.frame.triangles}`);
      if (shots && part === 'leaves') await (await page.$('.gb-viewer')).screenshot({ path: `${shots}/${name}-no-leaves.png` });
      await page.click(`.gb-viewer input[data-part=${part}]`);
      await frame();
      console.log(`  without ${part}: ${off.frame.triangles} triangles`);
    }

    // The scene toggle, and orbiting (a drag on the canvas moves the camera and redraws).
    const hasScene = await page.$eval('.gb-viewer input[data-part=scene]', e => !e.disabled);
    let noScene = full;
    if (hasScene) {
      await page.click('.gb-viewer input[data-part=scene]');
      await frame();
      noScene = await stats();
      if (!(noScene.frame.triangles < full.frame.triangles)) fail(name, 'hiding the scene drew as much as before');
      await page.click('.gb-viewer input[data-part=scene]');
    } else if (requireScene) {
      fail(name, 'no scene.glb on this page');
    } else {
      console.log('  no scene.glb on this page');
    }
    const canvas = await (await page.$('.gb-viewer canvas')).boundingBox();
    const cx = canvas.x + canvas.width / 2, cy = canvas.y + canvas.height / 2;
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    for (let i = 1; i <= 10; i++) await page.mouse.move(cx - 25 * i, cy + 6 * i);
    await page.mouse.up();
    await page.mouse.wheel({ deltaY: -300 });
    await frame();
    const orbited = await stats();
    const moved = Math.hypot(...orbited.camera.map((v, i) => v - full.camera[i]));
    console.log(`  without the scene: ${noScene.frame.triangles} triangles; a drag and a wheel moved the camera ${moved.toFixed(2)} m`);
    if (!(moved > 0.01)) fail(name, 'dragging the canvas did not move the camera');
    if (shots) await (await page.$('.gb-viewer')).screenshot({ path: `${shots}/${name}-orbited.png` });
    await page.click('.gb-viewer .gb-reset');
    await frame();

    // Growth playback.
    if (full.growthMeshes > 0 && full.lastStep > 0) {
      const box = await (await page.$('.gb-viewer .gb-slider')).boundingBox();
      const seen = [];
      for (const at of [0.25, 0.5]) {
        await page.mouse.click(box.x + at * box.width, box.y + box.height / 2);
        await frame();
        const s = await stats();
        seen.push(s);
        // Faithful: what is drawn is exactly what was born by this step, checked item by item.
        const f = await page.evaluate(() => GBViewer.viewers[0].frameCheck());
        if (f.drawnLater || f.hiddenEarlier || !f.items)
          fail(name, `step ${f.step}: ${f.drawnLater} drawn items born later, ${f.hiddenEarlier} hidden items born by then, of ${f.items}`);
        console.log(`  slider at ${at * 100}%: step ${s.step}, ${s.frame.triangles} triangles, plant indices ${s.indices}, instances ${s.instances}`);
        if (shots) await (await page.$('.gb-viewer')).screenshot({ path: `${shots}/${name}-step-${s.step}.png` });
      }
      if (!(seen[0].step < seen[1].step && seen[1].step < full.lastStep)) fail(name, `slider steps ${seen.map(s => s.step)}`);
      if (!(seen[0].indices < seen[1].indices && seen[1].indices < full.indices)) fail(name, `plant indices did not grow with the step: ${seen.map(s => s.indices)} of ${full.indices}`);
      if (!(seen[0].frame.triangles < seen[1].frame.triangles && seen[1].frame.triangles < full.frame.triangles)) fail(name, 'drawn triangles did not grow with the step');
      await page.focus('.gb-viewer .gb-slider');
      await page.keyboard.press('End');
      await frame();
      const end = await stats();
      if (end.step !== full.lastStep || end.frame.triangles !== full.frame.triangles) fail(name, `End: step ${end.step}, ${end.frame.triangles} triangles`);
      await page.click('.gb-viewer .gb-play');  // from the end, Play starts again at step 0
      await new Promise(r => setTimeout(r, 1500));
      const playing = await stats();
      await page.click('.gb-viewer .gb-play');  // pause
      console.log(`  play for 1.5 s: step ${playing.step}`);
      if (!(playing.step > 0 && playing.step < full.lastStep)) fail(name, `play reached step ${playing.step}`);
    } else if (requireGrowth) {
      fail(name, `no growth to play: ${await page.$eval('.gb-viewer .gb-step', e => e.textContent)}`);
    } else {
      console.log(`  playback off: ${await page.$eval('.gb-viewer .gb-step', e => e.textContent)}`);
    }
    if (errors.length) fail(name, `console errors:\n    ${errors.join('\n    ')}`);
    if (offsite.length) fail(name, `requests off file://: ${offsite.join(', ')}`);
    if (warnings.length) console.log(`  console warnings (not failures): ${warnings.join(' | ')}`);
    await page.close();
  }
} finally {
  await browser.close();
}
console.log(failures.length ? `test.mjs: ${failures.length} failures` : `test.mjs: ${pages.length} pages passed`);
process.exit(failures.length ? 1 : 0);
