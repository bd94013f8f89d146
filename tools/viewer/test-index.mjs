// Drives Debian's chromium (headless) through a report's index.html opened from file://, the network refused,
// and checks its "Explore the trials" section as a reader uses it:
//  - the table has a row per trial cell and the plot a point per cell with the chosen metric;
//  - clicking a column's header sorts the rows by it (numbers as numbers, n/a last), again reverses them;
//  - typing in the filter keeps only the matching rows and points, and says how many;
//  - choosing another metric redraws the plot;
//  - clicking a point opens that trial's page;
// with no console error, page error or failed request. Exit status 1 on any failure.
//   node tools/viewer/test-index.mjs REPORT/index.html
import { checker, fileUrl, launch, watchedPage } from './browser.mjs';

const file = process.argv[2];
if (!file) { console.error('test-index.mjs: give a report index.html'); process.exit(2); }
const { check, finish } = checker('test-index.mjs');
const browser = await launch();
try {
  const errors = [];
  const page = await watchedPage(browser, errors);
  await page.goto(fileUrl(file), { waitUntil: 'load' });
  await page.waitForFunction(() => document.body.dataset.explore === 'ready', { timeout: 60000 });
  const data = await page.evaluate(() => JSON.parse(document.getElementById('gb-explore-data').textContent));
  const rows = () => page.$$eval('#gb-trials tbody tr', trs => trs.map(tr => tr.dataset.id));
  const points = () => page.$$eval('#gb-plot a.gb-point', as => as.map(a => a.dataset.id));
  const n = data.rows.length;
  check((await rows()).length === n, `${(await rows()).length} table rows for ${n} trial cells`);
  const y = await page.$eval('#gb-y', s => s.value);
  const withY = data.rows.filter(r => typeof r.metrics[y] === 'number' && typeof r.growth_s === 'number' && r.growth_s > 0);
  check((await points()).length === withY.length, `${(await points()).length} points for ${withY.length} cells with ${y}`);
  console.log(`  ${n} rows, ${withY.length} points of ${y}`);

  // Sorting by a numeric column, both ways; n/a (absent) stays last.
  const col = await page.$$eval('#gb-trials thead th', ths => ths.map(th => th.dataset.key));
  const nodesAt = col.indexOf('nodes');
  const columnValues = i => page.$$eval('#gb-trials tbody tr', (trs, i) => trs.map(tr => tr.children[i].textContent), i);
  const asNumbers = v => v.filter(x => x !== 'n/a').map(Number);
  await page.click('#gb-trials thead th[data-key=nodes]');
  let v = asNumbers(await columnValues(nodesAt));
  check(v.every((x, i) => i === 0 || v[i - 1] <= x), `nodes ascending: ${v.join(' ')}`);
  await page.click('#gb-trials thead th[data-key=nodes]');
  v = asNumbers(await columnValues(nodesAt));
  check(v.every((x, i) => i === 0 || v[i - 1] >= x), `nodes descending: ${v.join(' ')}`);
  check(v.length > 1 && v[0] > v[v.length - 1], 'the nodes column has different values to sort');

  // Filtering: the first cell's scene and entry.
  const first = data.rows[0];
  const words = `${first.entry} ${first.scene}`;
  await page.type('#gb-filter', words);
  const kept = await rows();
  const expect = data.rows.filter(r => `${r.id} ${r.entry} ${r.scene} s${r.seed} ${r.verdict}`.toLowerCase()
    .includes(first.entry.toLowerCase()) && `${r.id} ${r.entry} ${r.scene}`.toLowerCase().includes(first.scene.toLowerCase()));
  check(kept.length === expect.length && kept.length < n, `filter '${words}' kept ${kept.length} rows, expected ${expect.length} of ${n}`);
  check((await points()).every(id => kept.includes(id)), 'the plot shows a point the filter removed');
  const count = await page.$eval('#gb-count', e => e.textContent);
  check(count.startsWith(`${kept.length} of ${n}`), `count says '${count}'`);
  console.log(`  filter '${words}': ${kept.length} rows, '${count}'`);
  await page.$eval('#gb-filter', e => { e.value = ''; e.dispatchEvent(new Event('input')); });
  check((await rows()).length === n, 'clearing the filter brings every row back');

  // The scene and verdict choices keep only their rows.
  await page.select('#gb-explore select.gb-choice[data-key=scene]', first.scene);
  const sceneRows = await rows();
  const sceneExpect = data.rows.filter(r => r.scene === first.scene).map(r => r.id);
  check(JSON.stringify([...sceneRows].sort()) === JSON.stringify([...sceneExpect].sort()),
        `scene ${first.scene}: rows ${sceneRows.join(' ')}, expected ${sceneExpect.join(' ')}`);
  await page.select('#gb-explore select.gb-choice[data-key=scene]', '');
  check((await rows()).length === n, 'choosing every scene again brings every row back');

  // A point's tooltip names its trial, its numbers and its parameters.
  const tip = await page.$eval(`#gb-plot a.gb-point[data-id="${(await points())[0]}"] title`, t => t.textContent);
  check(tip.startsWith((await points())[0]) && /(parameters|swept): \S+=/.test(tip), `tooltip '${tip}'`);

  // Another metric redraws the plot with that metric's cells.
  const metrics = await page.$$eval('#gb-y option', os => os.map(o => o.value));
  if (metrics.length > 1) {
    const other = metrics.find(m => m !== y);
    await page.select('#gb-y', other);
    const has = data.rows.filter(r => typeof r.metrics[other] === 'number' && typeof r.growth_s === 'number' && r.growth_s > 0);
    check((await points()).length === has.length, `${other}: ${(await points()).length} points for ${has.length} cells`);
    const label = await page.$$eval('#gb-plot text', ts => ts.map(t => t.textContent));
    const named = (await page.$eval(`#gb-y option[value="${other}"]`, o => o.textContent));
    check(label.includes(named), `the plot's axis does not name ${named}`);
    await page.select('#gb-y', y);
  }

  // A point opens its trial's page.
  const target = (await points())[0];
  const expected = data.rows.find(r => r.id === target).page;
  await Promise.all([page.waitForNavigation({ waitUntil: 'load' }), page.click(`#gb-plot a.gb-point[data-id="${target}"] circle`)]);
  check(page.url().endsWith(expected), `clicking ${target}'s point opened ${page.url()}, not ${expected}`);
  const h1 = await page.$eval('h1', e => e.textContent);
  check(h1 === target, `the page's title is '${h1}', not '${target}'`);
  console.log(`  clicked ${target}: ${page.url().split('/').slice(-2).join('/')}`);
  check(errors.length === 0, `console errors:\n    ${errors.join('\n    ')}`);
} finally {
  await browser.close();
}
finish();
