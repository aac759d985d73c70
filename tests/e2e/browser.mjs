// What the browser tests share: Debian's chromium, headless, driven by playwright-core, and a
// page that collects what went wrong in it (script errors, console errors, requests that leave
// the server: the page must work offline).
import { chromium } from 'playwright-core';

export async function launchBrowser() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
}

// A page of a 1280 × 900 window. `problems` collects the page's errors; `ignoreConsole(text)`
// says which console errors are expected (e.g. the browser's line for a refused request).
export async function openPage(browser, url, timeout, ignoreConsole = () => false) {
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await context.newPage();
  page.setDefaultTimeout(timeout);
  const problems = [];
  page.on('pageerror', (e) => problems.push('page error: ' + e.message));
  page.on('console', (m) => { if (m.type() === 'error' && !ignoreConsole(m.text())) problems.push('console: ' + m.text()); });
  page.on('request', (r) => { if (!r.url().startsWith(url)) problems.push('request off the server: ' + r.url()); });
  return { page, problems };
}
