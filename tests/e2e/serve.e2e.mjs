// End-to-end test of `uphill serve` in a real headless browser (Debian's chromium, driven by
// playwright-core; never `npx playwright install`). Started by run.sh, which runs the server:
//   UPHILL_URL        the page, e.g. http://127.0.0.1:40123/
//   UPHILL_EXP_DIR    the (new, empty) experiment folder the server writes
//   UPHILL_E2E_SCREENSHOTS  optional folder for screenshots (empty, rows and flags, plot)
// A technician creates an experiment, types rows with the keyboard, sees the flags and the plot
// update, deletes and undoes, reloads and finds the rows; the CSV on disk has them.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { launchBrowser, openPage } from './browser.mjs';

const url = process.env.UPHILL_URL;
const dir = process.env.UPHILL_EXP_DIR;
const shots = process.env.UPHILL_E2E_SCREENSHOTS || '';
assert.ok(url && dir, 'UPHILL_URL and UPHILL_EXP_DIR must be set (use run.sh)');

const browser = await launchBrowser();
let failed = false;
try {
  const { page, problems } = await openPage(browser, url, 10000);
  const shot = async (name) => { if (shots) await page.screenshot({ path: path.join(shots, name), fullPage: true }); };

  await page.goto(url);
  await page.waitForSelector('#status:has-text("New experiment")');
  assert.equal(await page.isVisible('#rows-section'), false, 'no rows before the experiment exists');
  await shot('1-empty.png');

  // The experiment, typed into the form; Enter in a field submits it.
  await page.fill('#f-title', 'E2E series <b>bold?</b>');
  await page.fill('#f-operator', 'Browser Test');
  await page.selectOption('#f-body', 'spheroid');
  await page.fill('#f-a', '15.875 mm');
  await page.fill('#f-b', '25.4 mm');
  await page.fill('#f-H', '300 mm');
  await page.fill('#f-uL', '1 mm');
  await page.fill('#f-uD', '0.2 mm');
  await page.fill('#f-uY', '0.5 mm');
  await page.focus('#f-uY');
  await page.keyboard.press('Enter');
  await page.waitForSelector('#status:has-text("version 1")');
  assert.equal(await page.textContent('#title'), 'E2E series <b>bold?</b>', 'the title is shown as text');
  assert.equal(await page.locator('#title b').count(), 0, 'no HTML from user text');

  // Rows with the keyboard only: after creating, the cursor is in the entry row's trial field.
  const entryValue = (name) => page.inputValue(`#entry input[name="${name}"]`);
  assert.equal(await page.evaluate(() => document.activeElement.name), 'trial', 'focus is in the entry row');
  const typeRow = async (values) => {
    // values: trial, series, L, D, Y, note in the page's tab order; each replaces the field.
    for (const [i, v] of values.entries()) {
      if (v !== null) { await page.keyboard.press('Control+A'); await page.keyboard.type(v); }
      if (i < values.length - 1) await page.keyboard.press('Tab');
    }
  };
  const rowCount = () => page.locator('#body tr').count();
  await typeRow(['t1', 's2', '1165', '150', '392', 'first']);
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => document.querySelectorAll('#body tr').length === 1);
  // The next trial label is proposed, L and D kept, the cursor in Y.
  assert.equal(await entryValue('trial'), 't2');
  assert.equal(await entryValue('D'), '150');
  assert.equal(await page.evaluate(() => document.activeElement.name), 'Y');
  await page.keyboard.press('Shift+Tab');           // back to D
  await page.keyboard.press('Control+A');
  await page.keyboard.type('200');
  await page.keyboard.press('Tab');
  await page.keyboard.type('292');
  await page.keyboard.press('Tab');
  await page.keyboard.type('<img src=x onerror="document.title=1">');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => document.querySelectorAll('#body tr').length === 2);
  assert.equal(await page.locator('#body img').count(), 0, 'a note is never HTML');
  assert.match(await page.textContent('#body tr:nth-child(2) td.note'), /<img src=x/);

  // The live check: θ, α, X appear while typing; a Y typed in inches is flagged before saving.
  await page.focus('#entry input[name="D"]');
  await typeRow(['250', '9.1']);  // 231 mm typed as inches
  await page.waitForSelector('#entry .badge[data-code="unit_mixup"]');
  assert.match(await page.textContent('#entry-flags'), /inches/);
  assert.match(await page.textContent('#entry td.computed-x'), /±/);
  await page.keyboard.press('Enter');  // saved anyway: the flag is a warning, the technician decides
  await page.waitForFunction(() => document.querySelectorAll('#body tr').length === 3);
  await page.waitForSelector('#body tr:nth-child(3) .badge[data-code="unit_mixup"]');
  // Fix it by editing with the keyboard: focus the row, Enter edits, Enter saves.
  await page.focus('#body tr:nth-child(3)');
  await page.keyboard.press('Enter');
  await page.waitForSelector('#body tr.editing');
  await page.focus('#body tr.editing input[name="Y"]');
  await page.keyboard.press('Control+A');
  await page.keyboard.type('232');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => !document.querySelector('#body tr.editing') &&
    document.querySelector('#body tr:nth-child(3) td:nth-child(6)')?.textContent === '232');
  assert.equal(await page.locator('#body tr:nth-child(3) .badge').count(), 0);
  // A duplicate label is flagged live.
  await page.focus('#entry input[name="trial"]');
  await typeRow(['t1', null, null, '150', '392.5']);
  await page.waitForSelector('#entry .badge[data-code="duplicate_trial"]');
  await page.keyboard.press('Shift+Tab');  // Y → D → L → series → trial
  await page.keyboard.press('Shift+Tab');
  await page.keyboard.press('Shift+Tab');
  await page.keyboard.press('Shift+Tab');
  await page.keyboard.press('Control+A');
  await page.keyboard.type('t4');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => document.querySelectorAll('#body tr').length === 4);

  // Plot: a point per row, the fit line and y = x; the fit panel.
  await page.waitForFunction(() => document.querySelectorAll('#plot circle.point:not(.draft)').length === 4);
  assert.equal(await page.locator('#plot line.fit').count(), 1);
  assert.equal(await page.locator('#plot line.diag').count(), 1);
  assert.match(await page.textContent('#fit'), /slope k/);
  // Something flagged for the screenshot: a far Y being typed.
  await page.focus('#entry input[name="Y"]');
  await page.keyboard.press('Control+A');
  await page.keyboard.type('700');
  await page.waitForSelector('#entry .badge[data-code="y_far"]');
  await shot('2-rows-flags.png');
  await page.locator('#plot-section').screenshot(shots ? { path: path.join(shots, '3-plot.png') } : {});

  // Delete with the keyboard and undo with Ctrl+Z.
  await page.focus('#body tr:nth-child(2)');
  await page.keyboard.press('Delete');
  await page.waitForFunction(() => document.querySelectorAll('#body tr').length === 3);
  await page.focus('#body tr:nth-child(1)');
  await page.keyboard.press('Control+z');
  await page.waitForFunction(() => document.querySelectorAll('#body tr').length === 4);

  // Exclude a row from the fit with its reason: it stays in the table and the plot (hollow), the
  // live fit leaves it out, and the report lists it; Ctrl+Z takes it back.
  page.once('dialog', (dialog) => dialog.accept('bumped the rail'));
  await page.click('#body tr:nth-child(2) td.fit-toggle input');
  await page.waitForSelector('#plot circle.point.excluded');
  assert.match(await page.textContent('#fit'), /3 \(1 excluded\)/);
  assert.equal(await page.locator('#body tr').count(), 4);

  // The report button writes the report and links to it.
  await page.click('#report-button');
  await page.waitForSelector('#report-link:not([hidden])', { timeout: 60000 });
  const report = await page.request.get(url + 'report/report.html');
  assert.equal(report.status(), 200);
  assert.match(await report.text(), /trial t2 \(row 3\): bumped the rail/);
  await page.focus('#body tr:nth-child(1)');
  await page.keyboard.press('Control+z');
  await page.waitForFunction(() => !document.querySelector('#plot circle.point.excluded'));

  // Reload: everything is still there (and the half-typed draft too).
  await page.reload();
  await page.waitForFunction(() => document.querySelectorAll('#body tr').length === 4);
  const trials = await page.$$eval('#body tr td:nth-child(2)', (tds) => tds.map((td) => td.textContent));
  assert.deepEqual(trials, ['t1', 't2', 't3', 't4']);
  assert.equal(await entryValue('Y'), '700', 'the draft survives a reload');

  // The CSV on disk.
  const csv = fs.readFileSync(path.join(dir, 'measurements.csv'), 'utf8').trim().split('\n');
  assert.equal(csv[0], 'trial,series,L_mm,D_mm,Y_mm,note');
  assert.equal(csv[1], 't1,s2,1165,150,392,first');
  assert.equal(csv[3], 't3,s2,1165,250,232,');
  assert.equal(csv.length, 5);
  assert.ok(fs.existsSync(path.join(dir, 'journal.jsonl')));
  assert.deepEqual(problems, []);
  console.log('serve e2e: ok (4 rows typed, flags, plot, edit, delete/undo, exclude/undo, report, reload, CSV)');
} catch (e) {
  failed = true;
  console.error(e);
} finally {
  await browser.close();
}
process.exit(failed ? 1 : 0);
