// What the browser tests share: Debian's chromium, headless and cut off from the network, and a page opened
// from file:// that records every console error, page error and failed request.
import puppeteer from 'puppeteer-core';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

// extraArgs: e.g. WebGL on the CPU for the 3D view.
export function launch(extraArgs = []) {
  return puppeteer.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox',                              // root in CI, as tests/reports/report_e2e.sh
           '--host-resolver-rules=MAP * ~NOTFOUND',     // no name resolves: the network is off
           '--window-size=1200,900', ...extraArgs],
  });
}

// A new page of `browser` that collects into `errors`; not yet opened.
export async function watchedPage(browser, errors) {
  const page = await browser.newPage();
  await page.setViewport({ width: 1200, height: 900 });
  page.on('console', m => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', e => errors.push(`page error: ${e.message}`));
  page.on('requestfailed', r => errors.push(`request failed: ${r.url()} (${r.failure()?.errorText})`));
  return page;
}

export const fileUrl = file => pathToFileURL(resolve(file)).href;

// check(ok, what) records a failure; finish() prints the verdict and exits 1 on any.
export function checker(name) {
  const failures = [];
  return {
    failures,
    check: (ok, what) => { if (!ok) { failures.push(what); console.log(`  FAIL ${what}`); } },
    finish: () => {
      console.log(failures.length ? `${name}: ${failures.length} failures` : `${name}: passed`);
      process.exit(failures.length ? 1 : 0);
    },
  };
}
