// End-to-end test of a trial's video in `uphill serve` (issue 13), in headless Chromium like
// serve.e2e.mjs (run.sh starts the server; UPHILL_MAKE_VIDEO is tools/make_video). A new
// technician, in the page alone: creates the experiment, uploads chessboard photos and calibrates
// the camera from them, uploads a trial's recording, clicks the calibration points on a
// frame, saves the scene, tracks the video, accepts the rest position as Y, opens the report,
// reloads and finds all of it again. Then, outside the counted steps (issue 32): a fresh browser
// restores the clicks, marks and table height from the scene file; the frame names the points and
// the left rail (+y); the scrubber and play/pause move through the clip; O clicked 5 px off is
// the point the leave-one-out check names; the video is detached and leaves the folder's list.
//
// Truth: tools/make_video's clip of its default apparatus (sphere R = 25.4 mm, 8 mm rods,
// L = 1000 mm, H = 100 mm, D = 150 mm; table 30 mm below O), its exact camera (cam.json) and pose
// (scene.json), and the exact pixels of the apparatus points a person sees in the first frame
// (points.csv: O, the rails on the crossbar, the crossbar's feet, the tape marks round the rods;
// a point behind a rod or the ball is not listed): the clicks land there.
//
// It asserts the steps a technician takes in the page (each click, typed field, choice or file
// pick counts one): at most 30 from an empty folder to the report, the claim of README.md and
// docs/serve.md. It estimates the time, not measured: the run's wall time (the
// server's work: calibration, decoding, tracking, report) plus the keystroke-level model of Card,
// Moran and Newell for the person (per step: mental preparation M = 1.35 s; a click P + B = 1.1 +
// 0.2 s; a field: a click and K = 0.28 s per character; a choice: two clicks; a file pick: four
// clicks; a click on a point of the frame: 2.0 s of aiming with the zoom). Printed at the end.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { launchBrowser, openPage } from './browser.mjs';

const url = process.env.UPHILL_URL;
const dir = process.env.UPHILL_EXP_DIR;
const work = process.env.UPHILL_E2E_WORK;
const makeVideo = process.env.UPHILL_MAKE_VIDEO;
const shots = process.env.UPHILL_E2E_SCREENSHOTS || '';
assert.ok(url && dir && work && makeVideo, 'UPHILL_URL, UPHILL_EXP_DIR, UPHILL_E2E_WORK, UPHILL_MAKE_VIDEO (use run.sh)');

// The clip: 640 × 360, 1 s, a trial whose ball rests inside its rest band (rolling resistance
// μ = 0.05), and 12 chessboard views of the same camera.
const clip = path.join(work, 'clip');
execFileSync(makeVideo, [clip, '--width', '640', '--height', '360', '--boards', '12', '--noise', '1', '--mu', '0.05',
  '--x0-band', '-0.02', '--seconds', '1'], { stdio: 'ignore' });
const truthLines = fs.readFileSync(path.join(clip, 'truth.csv'), 'utf8').trim().split('\n');
const truthX = Number(truthLines[truthLines.length - 1].split(',')[2]);
const truthFrames = truthLines.length - 1;  // a line per frame after the header
const truthPoints = fs.readFileSync(path.join(clip, 'points.csv'), 'utf8').trim().split('\n').slice(1).map((line) => {
  const [name, u, v, x, y, z] = line.split(',');
  return { name, u: Number(u), v: Number(v), x: Number(x), y: Number(y), z: Number(z) };
});
const cameraCentre = (scene) => {
  const R = scene.pose.rotation, t = scene.pose.translation_m;
  return [0, 1, 2].map((i) => -(R[0][i] * t[0] + R[1][i] * t[1] + R[2][i] * t[2]));
};

const KLM = { M: 1.35, click: 1.3, key: 0.28, aim: 2.0 };
let steps = 0, personSeconds = 0;
const count = (seconds) => { steps += 1; personSeconds += KLM.M + seconds; };

const browser = await launchBrowser();
let failed = false;
try {
  // A refused request (422: fewer than 4 clicks so far) is logged by the browser as a failed
  // resource; only the page's own errors count. Each step may wait 60 s: the server calibrates
  // and tracks on the same two cores as the rest of `ctest -j2`, and once took over 20 s.
  const { page, problems } = await openPage(browser, url, 60000, (text) => /status of 4\d\d/.test(text));
  const shot = async (name) => { if (shots) await page.screenshot({ path: path.join(shots, name), fullPage: true }); };
  const click = async (selector) => { count(KLM.click); await page.click(selector); };
  const fill = async (selector, text) => { count(KLM.click + KLM.key * text.length); await page.fill(selector, text); };
  const choose = async (selector, value) => { count(2 * KLM.click); await page.selectOption(selector, value); };

  const started = Date.now();
  await page.goto(url);
  await page.waitForSelector('#status:has-text("New experiment")');

  // 1. The experiment: the ball and the apparatus.
  await choose('#f-body', 'sphere');
  await fill('#f-R', '25.4 mm');
  await fill('#f-L', '1000 mm');
  await fill('#f-H', '100 mm');
  await fill('#f-D', '150 mm');
  await fill('#f-rod', '8 mm');
  await click('#save-experiment');
  await page.waitForSelector('#status:has-text("version 1")');

  // 2. The camera: the chessboard photos are uploaded from the page (one file pick of all 12);
  // the folder they land in is filled in for the calibration.
  await click('#camera-details summary');
  const boards = fs.readdirSync(path.join(clip, 'boards')).sort().map((name) => path.join(clip, 'boards', name));
  assert.equal(boards.length, 12);
  count(4 * KLM.click);
  await page.setInputFiles('#cam-upload', boards);
  await page.waitForSelector('#cam-upload-status:has-text("12 of 12 views uploaded into calibration/views.")',
    { timeout: 60000 });
  for (const board of boards)
    assert.ok(fs.readFileSync(path.join(dir, 'calibration', 'views', path.basename(board))).equals(fs.readFileSync(board)),
      `${path.basename(board)} uploaded byte for byte`);
  assert.equal(await page.inputValue('#cam-folder'), 'calibration/views');
  // A file that is not an image is refused, named with the rule, and leaves nothing behind.
  const notImage = path.join(work, 'notes.png');
  fs.writeFileSync(notImage, 'not an image');
  await page.setInputFiles('#cam-upload', notImage);
  await page.waitForSelector('#cam-upload-status:has-text("0 of 1 views uploaded")');
  assert.match(await page.textContent('#cam-upload-status'), /notes\.png: not an image OpenCV can decode/);
  assert.deepEqual(fs.readdirSync(path.join(dir, 'calibration', 'views')).sort(), boards.map((b) => path.basename(b)));
  await click('#cam-run');  // 9 × 6 inner corners of 20 mm: the form's defaults
  // The verdict and its reasons are shown (make_video's 12 views cover only half of the image:
  // "poor", with that reason); the focal length is the true camera's within 1 %.
  await page.waitForSelector('#camera-result [class^="verdict-"]', { timeout: 60000 });
  assert.match(await page.textContent('#camera-summary'), /calibration\/camera\.json/);
  const fx = Number(/fx ([0-9.]+) px/.exec(await page.textContent('#camera-result'))[1]);
  const trueFx = JSON.parse(fs.readFileSync(path.join(clip, 'cam.json'), 'utf8')).fx_px;
  assert.ok(Math.abs(fx - trueFx) < 0.01 * trueFx, `fx ${fx} px, true ${trueFx} px`);

  // 3. The recording: uploaded, it becomes trial 1.
  count(4 * KLM.click);
  await page.setInputFiles('#v-upload', path.join(clip, 'clip.mp4'));
  await page.waitForSelector('#v-status:has-text("attached videos/clip.mp4")');
  await page.waitForFunction(() => document.querySelectorAll('#body tr').length === 1);
  assert.ok(fs.existsSync(path.join(dir, 'videos', 'clip.mp4')));
  await page.waitForFunction(() => document.getElementById('s-img').naturalWidth === 640);

  // 4. The scene: the table's height and the marks, then a click on each point, where the clip's
  // truth puts it. The page offers the points of L, H, D in order; a point out of view is skipped
  // by picking the next one in the list.
  await fill('#s-table', '-30');
  await page.press('#s-table', 'Tab');
  await fill('#s-marks', '300, 600, 900');
  await page.press('#s-marks', 'Tab');
  await page.waitForSelector('#s-points tr[data-name="mark 900 right"]');
  await shot('video-1-frame.png');
  await choose('#s-zoom', '8');  // 8 screen pixels per pixel of the frame: clicks to 1/16 px
  for (const p of truthPoints) {
    const row = page.locator(`#s-points tr[data-name="${p.name}"]`);
    if (!(await row.getAttribute('class')).includes('active')) { count(KLM.click); await row.locator('button.pick').click(); }
    // Scroll the zoomed frame so that the point is in the middle of the view (what a person does
    // with the scroll bars), then click its screen position.
    await page.evaluate(([u, v]) => {
      const view = document.getElementById('s-view');
      const scale = document.getElementById('s-img').getBoundingClientRect().width / 640;
      view.scrollLeft = (u + 0.5) * scale - view.clientWidth / 2;
      view.scrollTop = (v + 0.5) * scale - view.clientHeight / 2;
      document.getElementById('s-view').scrollIntoView({ block: 'nearest' });
    }, [p.u, p.v]);
    const box = await page.locator('#s-img').boundingBox();
    const scale = box.width / 640;
    count(KLM.aim);
    await page.mouse.click(box.x + (p.u + 0.5) * scale, box.y + (p.v + 0.5) * scale);
  }
  await page.waitForSelector('#s-result [class^="verdict-"]');
  // Only what a person can see was clicked: points.csv lists the points whose ray meets nothing
  // before them (make_video), and each tape mark is dark on the frame the page shows: the darkest
  // grey around it is well below the lightest of the bare rod 10 px nearer O.
  const marks = truthPoints.filter((p) => p.name.startsWith('mark '));
  assert.ok(marks.length >= 4 && truthPoints.length >= 8, `${truthPoints.length} points in view, ${marks.length} marks`);
  const o0 = truthPoints.find((p) => p.name === 'O');
  const greys = await page.evaluate(([points, o]) => {
    const img = document.getElementById('s-img');
    const canvas = document.createElement('canvas');
    canvas.width = img.naturalWidth;
    canvas.height = img.naturalHeight;
    const g = canvas.getContext('2d');
    g.drawImage(img, 0, 0);
    const around = (u, v) => {  // the greys of the 3 × 3 pixels round (u, v)
      const d = g.getImageData(Math.round(u) - 1, Math.round(v) - 1, 3, 3).data, out = [];
      for (let k = 0; k < 9; ++k) out.push((d[4 * k] + d[4 * k + 1] + d[4 * k + 2]) / 3);
      return out;
    };
    return points.map(([u, v]) => {
      const n = Math.hypot(o[0] - u, o[1] - v);
      return [Math.min(...around(u, v)), Math.max(...around(u + 10 * (o[0] - u) / n, v + 10 * (o[1] - v) / n))];
    });
  }, [marks.map((p) => [p.u, p.v]), [o0.u, o0.v]]);
  marks.forEach((p, k) => assert.ok(greys[k][0] < greys[k][1] - 50,
    `${p.name}: grey ${greys[k][0]} at the tape, ${greys[k][1]} on the bare rod: no tape to see`));
  // Each click landed on its true pixel, to the browser's whole screen pixel (mouse events carry
  // whole CSS pixels: 1/8 px of the frame at zoom 8; the table shows 0.01 px) ...
  for (const p of truthPoints) {
    const cells = await page.$$eval(`#s-points tr[data-name="${p.name}"] td`, (tds) => tds.map((td) => td.textContent));
    assert.ok(Math.abs(Number(cells[4]) - p.u) < 0.135 && Math.abs(Number(cells[5]) - p.v) < 0.135,
      `${p.name}: clicked at (${cells[4]}, ${cells[5]}), true pixel (${p.u}, ${p.v})`);
  }
  // ... and what remains is the calibrated camera's own error (well under a pixel).
  const rms = Number(/RMS ([0-9.]+) px/.exec(await page.textContent('#s-result'))[1]);
  assert.ok(rms < 1, `clicks at the true pixels with the calibrated camera: RMS ${rms} px`);
  assert.ok(await page.locator('#s-overlay polyline.path').count() === 1, 'the model path is drawn');
  await shot('video-2-scene.png');
  await click('#s-save');
  await page.waitForSelector('#scene-summary:has-text("main")');
  const saved = JSON.parse(fs.readFileSync(path.join(dir, 'calibration', 'scene-main.json'), 'utf8'));
  const truth = JSON.parse(fs.readFileSync(path.join(clip, 'scene.json'), 'utf8'));
  const [a, b] = [cameraCentre(saved), cameraCentre(truth)];
  const miss = Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]) / Math.hypot(...b);
  assert.ok(miss < 0.01, `the saved pose's camera centre is ${(100 * miss).toFixed(2)} % of the distance from the truth`);

  // 5. Track: the outline on a strip of frames, the analysis; accept the rest position as Y.
  await click('#t-run');
  await page.waitForSelector('#t-result dl', { timeout: 120000 });
  assert.ok(await page.locator('#t-strip figure').count() >= 4, 'a strip of frames');
  assert.ok(await page.locator('#t-strip circle').count() >= 4, 'the outline found on them');
  const restText = await page.textContent('#t-result');
  const restY = Number(/Y = ([0-9.]+) ±/.exec(restText)[1]);
  // The calibrated camera and the clicked scene put the resting ball where make_video drew it.
  assert.ok(Math.abs(restY - truthX) < 2, `rest Y ${restY} mm, drawn at ${truthX} mm`);
  await shot('video-3-track.png');
  await click('#t-accept');
  // The Y cell reads "from video" until the server has stored the accepted Y: wait for a number.
  await page.waitForFunction(() => /^[0-9.]+$/.test(document.querySelector('#body tr td:nth-child(4)')?.textContent ?? ''));
  const state = await (await page.request.get(url + 'api/state')).json();
  assert.ok(Math.abs(Number(state.rows[0].Y) - restY) <= 0.05 + 1e-9, `Y ${state.rows[0].Y} accepted (shown ${restY})`);


  // 6. The report.
  await click('#report-button');
  await page.waitForSelector('#report-link:not([hidden])', { timeout: 120000 });
  count(KLM.click);
  const report = await page.request.get(url + 'report/report.html');
  assert.equal(report.status(), 200);
  const seconds = (Date.now() - started) / 1000;
  const stepsToReport = steps;

  // 7. Reload: the trial's video, the camera, the scene, the clicks and the report are there.
  await page.reload();
  await page.waitForFunction(() => document.querySelectorAll('#body tr').length === 1);
  await page.waitForSelector('#scene-summary:has-text("main")');
  assert.match(await page.textContent('#camera-summary'), /calibration\/camera\.json/);
  assert.match(await page.getAttribute('#body tr .video-button', 'title'), /videos\/clip\.mp4/);
  await page.waitForFunction(() => document.getElementById('s-img').naturalWidth === 640);
  await page.waitForSelector('#s-result [class^="verdict-"]');
  assert.ok(await page.isVisible('#report-link'));
  assert.equal(await page.textContent('#body tr td:nth-child(4)'), state.rows[0].Y);
  const experiment = JSON.parse(fs.readFileSync(path.join(dir, 'experiment.json'), 'utf8'));
  assert.equal(experiment.format, 'uphill-experiment/2');
  assert.equal(experiment.camera, 'calibration/camera.json');
  assert.equal(experiment.scenes.main, 'calibration/scene-main.json');
  const csv = fs.readFileSync(path.join(dir, 'measurements.csv'), 'utf8').trim().split('\n');
  assert.equal(csv[0].split(',').includes('video'), true);

  // The checks below are not steps of the technician's path (not counted).
  // 8. The clicks, the marks and the table's height are in the scene file, and a fresh browser
  // (no local storage) restores them from it (issue 32, item 7).
  assert.deepEqual(saved.points.map((p) => p.name), truthPoints.map((p) => p.name));
  assert.deepEqual(saved.marks_m.map((m) => Math.round(m * 1e6) / 1e3), [300, 600, 900]);  // mm, kept in m
  assert.equal(Math.round(saved.table_z_m * 1e6) / 1e3, -30);
  const fresh = await openPage(browser, url, 60000, (text) => /status of 4\d\d/.test(text));
  await fresh.page.goto(url);
  await fresh.page.waitForSelector('#s-points tr[data-name="mark 900 right"]');
  await fresh.page.waitForSelector('#s-result [class^="verdict-"]');
  assert.equal(await fresh.page.inputValue('#s-marks'), '300, 600, 900');
  assert.equal(await fresh.page.inputValue('#s-table'), '-30');
  for (const p of truthPoints) {
    const cells = await fresh.page.$$eval(`#s-points tr[data-name="${p.name}"] td`, (tds) => tds.map((td) => td.textContent));
    const clicked = saved.points.find((q) => q.name === p.name);
    assert.equal(cells[4], clicked.u_px.toFixed(2), `${p.name} restored in a fresh browser`);
    assert.equal(cells[5], clicked.v_px.toFixed(2), `${p.name} restored in a fresh browser`);
  }
  assert.deepEqual(fresh.problems, []);
  await fresh.page.context().close();

  // 9. The overlay names the points and the axes (+y: the left rail); a player replaces the frame
  // number: a scrubber over the clip's frames and play/pause (items 9).
  await page.selectOption('#s-zoom', '1');
  await shot('video-4-labels.png');
  const labels = await page.$$eval('#s-overlay text', (ts) => ts.map((t) => t.textContent));
  assert.ok(labels.some((t) => t.startsWith('O ')), `O named on the frame: ${labels}`);
  assert.ok(labels.some((t) => t.startsWith('left rail crossbar (+y) ')), `the left rail is +y on the frame: ${labels}`);
  assert.match(await page.textContent('#s-points tr[data-name="left rail crossbar"] button.pick'), /\(\+y\)/);
  assert.ok(await page.isVisible('#s-play'));
  const frames = Number(await page.getAttribute('#s-scrub', 'max')) + 1;
  assert.equal(frames, truthFrames, 'the scrubber spans the clip');
  await page.$eval('#s-scrub', (s) => { s.value = '10'; s.dispatchEvent(new Event('change')); });
  await page.waitForSelector(`#s-where:has-text("frame 11 of ${truthFrames}")`);
  await page.click('#s-play');  // plays from frame 11 to the end, then shows the last frame
  await page.waitForSelector(`#s-where:has-text("frame ${truthFrames} of ${truthFrames}")`);
  await page.waitForSelector('#s-play:has-text("Play")');

  // 10. O clicked 5 px off: the leave-one-out check names O, not the largest residual (item 8).
  await page.selectOption('#s-zoom', '8');
  await page.evaluate(() => { document.getElementById('s-view').scrollIntoView({ block: 'nearest' }); });
  const o = truthPoints.find((p) => p.name === 'O');
  await page.locator('#s-points tr[data-name="O"] button.pick').click();
  await page.evaluate(([u, v]) => {
    const view = document.getElementById('s-view');
    const scale = document.getElementById('s-img').getBoundingClientRect().width / 640;
    view.scrollLeft = (u + 0.5) * scale - view.clientWidth / 2;
    view.scrollTop = (v + 0.5) * scale - view.clientHeight / 2;
  }, [o.u, o.v]);
  const box = await page.locator('#s-img').boundingBox();
  const zoom = box.width / 640;
  await page.mouse.click(box.x + (o.u + 0.5 + 3) * zoom, box.y + (o.v + 0.5 - 4) * zoom);
  await page.waitForSelector('#s-points tr.suspect[data-name="O"]');
  assert.match(await page.textContent('#s-result'), /O: [0-9.]+ px from where the other points place it/);
  assert.equal(await page.locator('#s-points tr.suspect').count(), 1);

  // 11. Detaching the video (confirmed): the trial keeps its Y but no video, and the file leaves
  // the folder's list for .detached/ (item 6).
  page.once('dialog', (d) => d.accept());
  await page.click('#v-detach');
  await page.waitForSelector('#v-status:has-text("detached videos/clip.mp4")');
  assert.ok(!fs.existsSync(path.join(dir, 'videos', 'clip.mp4')));
  assert.ok(fs.existsSync(path.join(dir, '.detached', 'clip.mp4')));
  const afterDetach = await (await page.request.get(url + 'api/state')).json();
  assert.equal(afterDetach.rows[0].video, undefined);
  assert.equal(afterDetach.rows[0].Y, state.rows[0].Y);
  const listed = await (await page.request.get(url + 'api/videos')).json();
  assert.deepEqual(listed.videos, []);
  assert.ok(await page.isHidden('#v-panel'));
  assert.deepEqual(problems, []);
  // The claim of README.md and docs/serve.md: at most 30 steps from an empty folder to the report.
  assert.ok(stepsToReport <= 30, `${stepsToReport} steps from an empty folder to the report`);
  console.log(`video e2e: ok — ${stepsToReport} steps, ` +
    `${seconds.toFixed(1)} s of the server's and the browser's work, ` +
    `about ${Math.round(seconds + personSeconds)} s for a person (keystroke-level model: ${personSeconds.toFixed(0)} s)`);
} catch (e) {
  failed = true;
  console.error(e);
} finally {
  await browser.close();
}
process.exit(failed ? 1 : 0);
