// Drives Debian's chromium (headless) through a `growbench history plot` page opened from file://, the network
// refused, and checks its interactive plot as a reader uses it:
//   node tools/viewer/test-history.mjs PLOT/index.html CELL COMMIT RATIO
// CELL stepped by RATIO (within 2%) at COMMIT, a change point: the plot draws a line per cell; the filter keeps
// the cells it names; hovering CELL's line names it; CELL's point at COMMIT is a change point (a diamond) whose
// tooltip names the commit; clicking it lists the commit's values, CELL first with its ratio to the commit
// before. No console error, page error or failed request. Exit status 1 on any failure.
import { checker, fileUrl, launch, watchedPage } from './browser.mjs';

const [file, cell, commit, ratioText] = process.argv.slice(2);
if (!ratioText) { console.error('usage: test-history.mjs PLOT/index.html CELL COMMIT RATIO'); process.exit(2); }
const { check, finish } = checker('test-history.mjs');
const browser = await launch();
try {
  const errors = [];
  const page = await watchedPage(browser, errors);
  await page.goto(fileUrl(file), { waitUntil: 'load' });
  await page.waitForFunction(() => document.body.dataset.history === 'ready', { timeout: 60000 });
  const box = '.gb-history';
  const data = await page.$eval(`${box} .gb-data`, e => JSON.parse(e.textContent));
  const metric = await page.$eval(`${box} .gb-metric`, s => s.value);
  const cells = Object.keys(data.series[metric]);
  const lines = () => page.$$eval(`${box} g.gb-cell`, gs => gs.map(g => g.dataset.cell));
  check((await lines()).length === cells.length, `${(await lines()).length} lines for ${cells.length} cells of ${metric}`);

  // The filter keeps the cells whose names hold the words.
  await page.type(`${box} .gb-filter`, cell);
  const kept = await lines();
  check(kept.length >= 1 && kept.every(c => c.includes(cell)) && kept.length < cells.length,
        `filter '${cell}' kept ${kept.join(', ')} of ${cells.length}`);
  await page.$eval(`${box} .gb-filter`, e => { e.value = ''; e.dispatchEvent(new Event('input')); });

  // The step is a change point at COMMIT; hovering it names the cell, clicking it lists the commit's values.
  const sel = `${box} g.gb-cell[data-cell="${cell}"]`;
  const i = data.commits.indexOf(commit);
  check(i > 0, `${commit} is not a commit of the page: ${data.commits.join(' ')}`);
  const diamond = `${sel} .gb-change[data-commit="${i}"]`;
  check(await page.$(diamond) !== null, `no change point drawn for ${cell} at ${commit}`);
  if (await page.$(diamond)) {
    await page.hover(diamond);
    const hover = await page.$eval(`${box} .gb-hover`, e => e.textContent);
    check(hover === cell, `hovering ${cell}'s line shows '${hover}'`);
    const tip = await page.$eval(`${diamond} title`, t => t.textContent);
    check(tip.includes(commit) && tip.includes('change point'), `the tooltip says '${tip}'`);
    await page.click(diamond);
    const shown = await page.$eval(box, b => b.dataset.commit);
    check(shown === commit, `clicking showed commit ${shown}`);
    const rows = await page.$$eval(`${box} .gb-commit-table tr`, trs => trs.slice(1).map(tr => [...tr.cells].map(td => td.textContent)));
    check(rows.length === cells.length, `${rows.length} rows for ${cells.length} cells`);
    check(rows[0] && rows[0][0] === cell && Math.abs(Number(rows[0][3]) / Number(ratioText) - 1) < 0.02,
          `first row ${JSON.stringify(rows[0])}, expected ${cell} at ratio ${ratioText}`);
    console.log(`  ${commit}: ${rows.map(r => `${r[0]} ${r[3]}`).join(', ')}`);
    const href = await page.$eval(`${box} a.gb-file`, a => a.href);
    check(href.startsWith('file:') && href.endsWith(`/${commit}.json`), `the commit's file link is ${href}`);
  }
  // The wheel zooms in on the commits; a double click shows them all again.
  const all = await page.$eval(box, b => b.dataset.window);
  const plot = await (await page.$(`${box} .gb-plot`)).boundingBox();
  await page.mouse.move(plot.x + plot.width / 2, plot.y + plot.height / 2);
  await page.mouse.wheel({ deltaY: -200 });
  const zoomed = await page.$eval(box, b => b.dataset.window);
  const width = w => { const [x, y] = w.split('..').map(Number); return y - x; };
  check(width(zoomed) < width(all), `the wheel left the window at ${zoomed} (was ${all})`);
  await page.mouse.click(plot.x + 5, plot.y + 5, { clickCount: 2 });
  check(await page.$eval(box, b => b.dataset.window) === all, 'a double click did not show every commit again');
  console.log(`  zoom: ${all} -> ${zoomed}`);
  check(errors.length === 0, `console errors:\n    ${errors.join('\n    ')}`);
} finally {
  await browser.close();
}
finish();
