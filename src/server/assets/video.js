// The video section of the page of `uphill serve`: the camera from chessboard views, a trial's
// recording (picked from the folder or uploaded), the scene calibrated by clicks on a frame, and
// the track with its analysis. As in app.js, the server computes everything (the pose at each
// click, the residuals, the leave-one-out check, where the unclicked points and the axes are, the
// model's path, the track) and this script only draws its answers. A saved scene file keeps the
// clicks, the marks and the table's height: the page restores them from it (GET /api/scenes/N).
// Uses app.js's S, api, change, el, svg, $, fmt, showMessage, nextTrial.
'use strict';

const V = {
  rowId: null,      // the trial shown
  video: '',        // its video (a path in the folder)
  width: 0, height: 0,
  frames: 0, fps: 25, playing: false,  // the video's frame count and rate (GET /api/video/info), the player
  frameSeq: 0,      // answers to older frame requests are dropped
  points: [],       // [{name, x, y, z, u, v, own}] lengths in the experiment's unit, u v raw px
  restored: [],     // the clicks of the saved scene (the same form), merged in by loadPoints
  active: 0,        // index of the point the next click places
  solution: null,   // the server's last answer to /api/scene/solve
  track: null,      // the server's last answer to /api/rows/<id>/track
  seq: 0,           // answers to older solves are ignored
  pointsSeq: 0,     // and to older requests for the points
};
const rowOf = (id) => (S ? S.rows.find((r) => r.id === id) : null);
const clicksKey = () => `uphill-clicks:${S ? S.directory : ''}:${V.video}`;

// ---- following the state ------------------------------------------------------------------------
function onStateApplied() {
  $('video-section').hidden = !S.exists;
  for (const u of document.querySelectorAll('.unit-name')) u.textContent = S.unit;
  const camera = S.experiment.camera;
  $('camera-summary').textContent = camera ? `— ${camera}` : '— none yet: calibrate it from chessboard views';
  const scenes = S.experiment.scenes || {};
  $('scene-summary').textContent = Object.keys(scenes).length
    ? '— saved: ' + Object.entries(scenes).map(([n, p]) => `${n} (${p})`).join(', ') : '';
  const select = $('v-row');
  const chosen = V.rowId !== null && rowOf(V.rowId) ? V.rowId : (S.rows.length ? S.rows[0].id : null);
  select.replaceChildren();
  for (const r of S.rows) {
    const o = el('option', { value: String(r.id) }, r.trial + (r.video ? ` — ${r.video}` : ''));
    select.append(o);
  }
  select.append(el('option', { value: 'new' }, `+ new trial ${nextTrial(S.rows.length ? S.rows[S.rows.length - 1].trial : '')}`));
  select.value = chosen === null ? 'new' : String(chosen);
  showRow(chosen);
}

function openVideoOf(id) {
  $('v-row').value = String(id);
  showRow(id);
  $('video-section').scrollIntoView({ behavior: 'smooth', block: 'start' });
}

// Shows the trial's video panel (when it has a video), reloading the frame only when it changed.
function showRow(id) {
  V.rowId = id;
  const row = id === null ? null : rowOf(id);
  const video = row && row.video ? row.video : '';
  $('v-panel').hidden = !video;
  $('v-detach').hidden = !video;
  $('t-accept').hidden = !V.track || V.track.row !== id;
  if (video === V.video) return;
  V.video = video;
  V.solution = null;
  V.track = null;
  $('t-result').replaceChildren();
  $('t-strip').replaceChildren();
  $('s-result').replaceChildren();
  $('track-summary').textContent = '';
  V.playing = false;
  V.frames = 0;
  $('s-scrub').value = '0';
  if (video) {
    loadVideoInfo();
    loadFrame();
    restoreScene().then(loadPoints);
  }
}

// The scene saved for this trial (its `scene` cell, else the one named in the form, else the
// experiment's only scene): its clicks, marks and table height, as they were when it was saved.
async function restoreScene() {
  V.restored = [];
  const row = rowOf(V.rowId);
  const scenes = (S && S.experiment.scenes) || {};
  const names = Object.keys(scenes);
  let name = row && row.scene && scenes[row.scene] ? row.scene : $('s-name').value.trim();
  if (!scenes[name]) name = names.length === 1 ? names[0] : '';
  if (!name) return;
  const { status, data } = await api('GET', `/api/scenes/${encodeURIComponent(name)}`);
  if (status !== 200) return;
  const tidy = (m) => String(Number(m.toPrecision(9)));  // 300 mm, not 300.00000000000006 from metres
  $('s-name').value = name;
  if (data.marks.length) $('s-marks').value = data.marks.map(tidy).join(', ');
  if (data.table_z !== null) $('s-table').value = tidy(data.table_z);
  V.restored = data.points.map((p) => ({ name: p.name, x: p.x, y: p.y, z: p.z, u: p.u, v: p.v, own: true }));
}

// ---- videos in the folder, attach, upload -------------------------------------------------------
async function loadVideoList(select) {
  const { status, data } = await api('GET', '/api/videos');
  if (status !== 200) return;
  const list = $('v-file');
  list.replaceChildren(el('option', { value: '' }, data.videos.length ? '— pick a video —' : '— no videos in the folder —'));
  for (const v of data.videos) list.append(el('option', { value: v.path }, `${v.path} (${formatBytes(v.bytes)})`));
  if (select) list.value = select;
}

async function attach(video) {
  if (!video) { showMessage('Pick a video from the list, or upload one', 'error'); return; }
  $('v-status').textContent = 'Checking the video…';
  const fresh = V.rowId === null;
  const trial = fresh ? nextTrial(S.rows.length ? S.rows[S.rows.length - 1].trial : '') : '';
  const result = await change('POST', `/api/rows/${fresh ? 'new' : V.rowId}/video`, fresh ? { video, trial } : { video });
  if (result && result.error) { $('v-status').textContent = result.error; return; }
  if (!result || result.conflict) { $('v-status').textContent = ''; return; }
  $('v-status').textContent = `attached ${video}`;
  if (fresh) { V.rowId = S.rows[S.rows.length - 1].id; onStateApplied(); }
}

function upload(file) {
  if (!file) return;
  $('v-status').textContent = `Uploading ${file.name}…`;
  const xhr = new XMLHttpRequest();
  xhr.open('PUT', '/api/videos/' + encodeURIComponent(file.name));
  xhr.setRequestHeader('Content-Type', 'application/octet-stream');
  xhr.upload.onprogress = (ev) => {
    if (ev.lengthComputable) $('v-status').textContent = `Uploading ${file.name}: ${Math.round(100 * ev.loaded / ev.total)} %`;
  };
  xhr.onerror = () => { $('v-status').textContent = 'Upload failed: the connection broke; nothing was kept'; };
  xhr.onload = async () => {
    let data = {};
    try { data = JSON.parse(xhr.responseText); } catch (e) { data = { error: 'HTTP ' + xhr.status }; }
    if (xhr.status !== 200) {
      $('v-status').textContent = 'Not uploaded: ' + data.error;
      showMessage('Not uploaded: ' + data.error, 'error');
      return;
    }
    await loadVideoList(data.path);
    await attach(data.path);
  };
  xhr.send(file);
}

// Detaching: the row loses its video, and the file leaves the folder's list of videos (the server
// moves it into .detached/ unless another trial uses it). The page cannot undo it: confirmed first.
async function detach() {
  const row = rowOf(V.rowId);
  if (!row || !row.video) return;
  if (!window.confirm(`Detach ${row.video} from trial ${row.trial}? The file is moved to the folder's .detached/ ` +
    'folder (unless another trial uses it) and leaves the list of videos. This cannot be undone from the page.')) return;
  const { status, data } = await api('POST', `/api/rows/${row.id}/detach`, { version: S.version });
  if (status === 409) { applyState(data.state); showMessage(data.error, 'error'); return; }
  if (status !== 200) { $('v-status').textContent = 'Not detached: ' + data.error; return; }
  applyState(data.state);
  savedStatus();
  await loadVideoList();
  $('v-status').textContent = `detached ${data.video}` + (data.moved_to ? `; the file is now ${data.moved_to}` : '');
}

// ---- camera -------------------------------------------------------------------------------------
// Chessboard views uploaded one after another into calibration/views (the folder the calibration
// then reads); each refused file is listed with the server's reason, the others are kept.
async function uploadViews(files) {
  if (!files.length) return;
  const status = $('cam-upload-status');
  const refused = el('ul', { class: 'flag-list' });
  let stored = 0;
  for (const [i, file] of files.entries()) {
    status.replaceChildren(`Uploading ${file.name} (${i + 1} of ${files.length})…`);
    let error = '';
    try {
      const response = await fetch('/api/views/' + encodeURIComponent(file.name),
        { method: 'PUT', headers: { 'Content-Type': 'application/octet-stream' }, body: file });
      let data = {};
      try { data = await response.json(); } catch (e) { data = { error: 'HTTP ' + response.status }; }
      if (response.ok) ++stored; else error = data.error;
    } catch (e) {
      error = 'the connection broke; nothing was kept';
    }
    if (error) refused.append(el('li', {}, error.includes(file.name) ? error : `${file.name}: ${error}`));
  }
  $('cam-folder').value = 'calibration/views';
  const said = `${stored} of ${files.length} views uploaded into calibration/views`;
  status.replaceChildren(refused.childElementCount ? `${said}; not uploaded:` : `${said}.`);
  if (refused.childElementCount) status.append(refused);
  $('cam-upload').value = '';
}

async function calibrateCamera(ev) {
  ev.preventDefault();
  const out = $('camera-result');
  out.replaceChildren(el('p', { class: 'muted' }, 'Finding the chessboard in every view and calibrating…'));
  $('cam-run').disabled = true;
  try {
    const body = { version: S.version, folder: $('cam-folder').value.trim(), cols: Number($('cam-cols').value),
      rows: Number($('cam-rows').value), square: Number($('cam-square').value) };
    const { status, data } = await api('POST', '/api/camera/calibrate', body);
    if (status === 409) { applyState(data.state); showMessage(data.error, 'error'); out.replaceChildren(); return; }
    if (status !== 200) { out.replaceChildren(el('p', { class: 'error' }, data.error)); return; }
    applyState(data.state);
    savedStatus();
    const c = data.calibration;
    const verdict = el('p', {}, '');
    verdict.append(el('span', { class: 'verdict-' + c.verdict }, `Verdict: ${c.verdict}`),
      document.createTextNode(` — RMS reprojection error ${c.rms_px.toFixed(3)} px, ${c.views_used} views used, ` +
        `coverage ${(100 * c.coverage).toFixed(0)} %, fx ${c.fx.toFixed(1)} px, fy ${c.fy.toFixed(1)} px, ` +
        `cx ${c.cx.toFixed(1)}, cy ${c.cy.toFixed(1)} (${c.width}×${c.height}); saved as ${S.experiment.camera}`));
    const reasons = el('ul', { class: 'flag-list' });
    for (const r of c.reasons) reasons.append(el('li', {}, r));
    const views = el('ul', { class: 'muted' });
    for (const v of c.views)
      views.append(el('li', {}, v.used ? `${v.name}: ${v.rms_px.toFixed(3)} px, tilted ${v.tilt_deg.toFixed(0)}°`
        : `${v.name}: not used (${v.rejected_because})`));
    out.replaceChildren(verdict, reasons, views);
  } finally {
    $('cam-run').disabled = false;
  }
}

// ---- the frame, the player and the clicks --------------------------------------------------------
// The player replaces a frame-number box: play/pause and a scrubber over the video's frames.
// While playing or dragging, frames come as JPEG (quick); the frame shown when it stops comes
// as PNG, the exact pixels to click.
function buildPlayer() {
  const play = el('button', { type: 'button', id: 's-play', title: 'Play the video; pause it to click a frame' }, '▶ Play');
  const scrub = el('input', { type: 'range', id: 's-scrub', min: '0', max: '0', step: '1', value: '0',
    'aria-label': 'Frame of the video' });
  const where = el('span', { id: 's-where', class: 'muted' }, '');
  const player = el('span', { class: 'player' });
  player.append(play, ' ', scrub, ' ', where);
  $('s-frame').closest('label').replaceWith(player);
}

function frameNumber() {
  const n = Number($('s-scrub').value);
  return Number.isInteger(n) && n >= 0 ? n : 0;
}

// The video's frame count and rate, for the scrubber and for playing.
async function loadVideoInfo() {
  const video = V.video;
  const { status, data } = await api('GET', `/api/video/info?video=${encodeURIComponent(video)}`);
  if (status !== 200 || video !== V.video) return;
  V.frames = data.frames;
  if (data.fps > 0) V.fps = data.fps;
  $('s-scrub').max = String(Math.max(0, data.frames - 1));
  showWhere();
}

const showWhere = () => { $('s-where').textContent = `frame ${frameNumber() + 1} of ${V.frames || '?'} (${(frameNumber() / V.fps).toFixed(2)} s)`; };

// Loads the scrubber's frame; false when it failed or a newer request overtook it.
async function loadFrame(quick) {
  const seq = ++V.frameSeq;
  const img = $('s-img');
  const url = `/api/video/frame?video=${encodeURIComponent(V.video)}&frame=${frameNumber()}` + (quick ? '&format=jpeg' : '');
  const loaded = await new Promise((resolve) => {
    img.onload = () => resolve(true);
    img.onerror = () => resolve(false);
    img.src = url;
  });
  if (seq !== V.frameSeq) return false;
  if (!loaded) {
    // The server says why in JSON: ask again for the message.
    const r = await fetch(url);
    let msg = 'HTTP ' + r.status;
    try { msg = (await r.json()).error; } catch (e) { /* keep the status */ }
    $('s-result').replaceChildren(el('span', { class: 'error' }, msg));
    return false;
  }
  V.width = img.naturalWidth;
  V.height = img.naturalHeight;
  showWhere();
  applyZoom();
  drawOverlay();
  return true;
}

async function togglePlay() {
  if (V.playing) { V.playing = false; return; }
  V.playing = true;
  $('s-play').textContent = '⏸ Pause';
  const scrub = $('s-scrub');
  if (frameNumber() >= V.frames - 1) scrub.value = '0';
  while (V.playing && frameNumber() < V.frames - 1) {
    const started = performance.now();
    scrub.value = String(frameNumber() + 1);
    if (!await loadFrame(true)) break;
    const wait = 1000 / V.fps - (performance.now() - started);  // real time, or as fast as frames decode
    if (wait > 0) await new Promise((resolve) => setTimeout(resolve, wait));
  }
  V.playing = false;
  $('s-play').textContent = '▶ Play';
  await loadFrame(false);
}

function applyZoom() {
  if (!V.width) return;
  const zoom = Number($('s-zoom').value) || 1;
  const view = $('s-view');
  // Zoom 1 fits the frame into the view; each step doubles it.
  const fit = Math.min(1, (view.clientWidth || 860) / V.width);
  $('s-stage').style.width = `${V.width * fit * zoom}px`;
}

function marksList() {
  return $('s-marks').value.split(/[,;\s]+/).map((t) => t.trim()).filter((t) => t !== '').map(Number).filter((m) => isFinite(m));
}

// The points the setting offers (server: from the trial's L, H, D); clicks kept where names match.
async function loadPoints() {
  const q = new URLSearchParams({ row: String(V.rowId), table_z: String(Number($('s-table').value) || 0) });
  const marks = marksList();
  if (marks.length) q.set('marks', marks.join(','));
  const seq = ++V.pointsSeq;
  const { status, data } = await api('GET', '/api/scene/points?' + q.toString());
  if (seq !== V.pointsSeq) return;  // a newer request (the table or the marks changed meanwhile)
  if (status !== 200) { $('s-result').replaceChildren(el('span', { class: 'error' }, data.error)); return; }
  let saved = [];
  try { saved = JSON.parse(localStorage.getItem(clicksKey()) || '[]'); } catch (e) { saved = []; }
  const before = new Map([...V.restored, ...V.points, ...saved].map((p) => [p.name, p]));
  V.points = data.points.map((p) => {
    const old = before.get(p.name);
    return { name: p.name, x: p.x, y: p.y, z: p.z, u: old ? old.u : null, v: old ? old.v : null };
  });
  for (const p of before.values())
    if (p.own && !V.points.some((q) => q.name === p.name)) V.points.push(p);
  V.restored = [];  // merged once: from now on the page's own clicks
  V.active = Math.max(0, V.points.findIndex((p) => p.u === null));
  renderPoints();
  solve();
}

function keepClicks() {
  try { localStorage.setItem(clicksKey(), JSON.stringify(V.points.filter((p) => p.u !== null || p.own))); } catch (e) { /* private mode */ }
}

// Sets style properties through the CSSOM (the page's Content-Security-Policy refuses style
// attributes; properties set here are allowed, and override app.css).
const styled = (node, style) => { Object.assign(node.style, style); return node; };

// Which rail a point of the setting is on, as the apparatus frame says it: the left rail is at +y.
const sideOf = (name) => (/\bleft\b/.test(name) ? ' (+y)' : /\bright\b/.test(name) ? ' (−y)' : '');

function renderPoints() {
  const body = $('s-points').querySelector('tbody');
  body.replaceChildren();
  const d = lengthDecimals();
  const residual = new Map((V.solution ? V.solution.points : []).map((p) => [p.name, p.residual_px]));
  V.points.forEach((p, i) => {
    const suspect = V.solution && V.solution.leave_one_out && V.solution.leave_one_out.explains &&
      V.solution.leave_one_out.name === p.name;
    const tr = styled(el('tr', { class: (i === V.active ? 'active' : '') + (suspect ? ' suspect' : ''), dataset: { name: p.name } }),
      suspect ? { outline: '2px solid #d33' } : {});
    const side = sideOf(p.name);
    const pick = el('button', { type: 'button', class: 'pick', title: 'Click this point in the frame next' +
      (side ? ': the left rail is the one at +y, on your left when you stand at O and look toward the crossbar' : '') },
    p.name + side);
    pick.addEventListener('click', () => { V.active = i; renderPoints(); });
    const nameCell = el('td');
    nameCell.append(pick);
    tr.append(nameCell);
    for (const k of ['x', 'y', 'z']) {
      const td = el('td', { class: 'num' });
      if (p.own) {
        const inp = el('input', { 'aria-label': `${p.name} ${k}`, inputmode: 'decimal', class: 'coord' });
        inp.value = p[k] ?? '';
        inp.addEventListener('change', () => { p[k] = Number(inp.value); keepClicks(); solve(); });
        td.append(inp);
      } else td.textContent = fmt(p[k], d);
      tr.append(td);
    }
    tr.append(el('td', { class: 'num' }, p.u === null ? '—' : p.u.toFixed(2)),
      el('td', { class: 'num' }, p.v === null ? '—' : p.v.toFixed(2)),
      el('td', { class: 'num' }, residual.has(p.name) ? residual.get(p.name).toFixed(2) : ''));
    const clear = el('button', { type: 'button', title: 'Forget this click' }, '×');
    clear.addEventListener('click', () => {
      p.u = p.v = null;
      if (p.own) V.points.splice(i, 1);
      V.active = Math.min(i, V.points.length - 1);
      keepClicks(); renderPoints(); solve();
    });
    const td = el('td');
    td.append(clear);
    tr.append(td);
    body.append(tr);
  });
}

function addOwnPoint() {
  const name = `point ${V.points.filter((p) => p.own).length + 1}`;
  V.points.push({ name, x: 0, y: 0, z: 0, u: null, v: null, own: true });
  V.active = V.points.length - 1;
  renderPoints();
}

// A click on the frame: its raw pixel (OpenCV: (0, 0) is the centre of the top-left pixel).
function frameClick(ev) {
  if (!V.width || !V.points.length) return;
  const rect = $('s-img').getBoundingClientRect();
  const u = (ev.clientX - rect.left) * V.width / rect.width - 0.5;
  const v = (ev.clientY - rect.top) * V.height / rect.height - 0.5;
  const p = V.points[V.active];
  p.u = Math.round(u * 100) / 100;
  p.v = Math.round(v * 100) / 100;
  const next = V.points.findIndex((q, i) => i > V.active && q.u === null);
  V.active = next >= 0 ? next : Math.max(0, V.points.findIndex((q) => q.u === null));
  keepClicks();
  renderPoints();
  drawOverlay();
  solve();
}

function clickedPoints() {
  return V.points.filter((p) => p.u !== null).map((p) => ({ name: p.name, u: p.u, v: p.v, x: p.x, y: p.y, z: p.z }));
}

// What the scene file keeps besides the clicks, and the points to show where the pose puts them.
function sceneInputs() {
  return { marks: marksList(), table_z: Number($('s-table').value) || 0,
    unclicked: V.points.filter((p) => p.u === null).map((p) => ({ name: p.name, x: p.x, y: p.y, z: p.z })) };
}

async function solve() {
  const clicks = clickedPoints();
  const out = $('s-result');
  if (clicks.length < 4) {
    V.solution = null;
    out.replaceChildren(el('span', { class: 'muted' }, `${clicks.length} point${clicks.length === 1 ? '' : 's'} clicked: ` +
      `click ${4 - clicks.length} more (spread over the frame, not all on one line)`));
    drawOverlay();
    return;
  }
  const seq = ++V.seq;
  const { status, data } = await api('POST', '/api/scene/solve', Object.assign({ video: V.video, row: V.rowId, clicks }, sceneInputs()));
  if (seq !== V.seq) return;
  if (status !== 200) {
    V.solution = null;
    out.replaceChildren(el('span', { class: 'error' }, data.error));
  } else {
    V.solution = data;
    const c = data.camera_centre, d = lengthDecimals();
    const line = el('span', {}, '');
    line.append(el('span', { class: 'verdict-' + data.verdict }, `Pose: ${data.verdict}`),
      document.createTextNode(` — RMS ${data.rms_px.toFixed(3)} px over ${data.points.length} points; camera at ` +
        `(${fmt(c.x, d)}, ${fmt(c.y, d)}, ${fmt(c.z, d)}) ${data.unit}`));
    out.replaceChildren(line);
    if (data.reasons.length) {
      const ul = el('ul', { class: 'flag-list' });
      for (const r of data.reasons) ul.append(el('li', {}, r));
      out.append(ul);
    }
  }
  renderPoints();
  drawOverlay();
}

// Over the frame: each clicked point (a circle) with its name, where the pose puts it (a cross)
// and its residual; the points not clicked yet where the pose expects them (a diamond, named);
// the axes at O (+x toward the crossbar, +y toward the left rail); the model's path. The point
// the leave-one-out check names is drawn in the error colour.
function drawOverlay() {
  const layer = $('s-overlay');
  layer.replaceChildren();
  if (!V.width) return;
  layer.setAttribute('viewBox', `-0.5 -0.5 ${V.width} ${V.height}`);
  // Frame pixels per screen pixel: marks and labels keep their size on screen at every zoom.
  const scale = V.width / ($('s-stage').getBoundingClientRect().width || V.width);
  const r = 6 * scale;
  const colour = { axis: '#7cfc00', expected: '#ff9f1c', suspect: '#ff3b3b' };
  const label = (x, y, text, cls) => {
    const t = styled(svg('text', { x: x + r * 1.5, y: y - r, 'font-size': 12 * scale, class: cls }),
      colour[cls] ? { fill: colour[cls] } : {});
    t.textContent = text;
    layer.append(t);
  };
  const solution = V.solution;
  const loo = solution && solution.leave_one_out && solution.leave_one_out.explains ? solution.leave_one_out.name : null;
  if (solution) {
    const path = solution.path.map(([u, v]) => `${u.toFixed(2)},${v.toFixed(2)}`).join(' ');
    if (path) layer.append(svg('polyline', { class: 'path', points: path, 'stroke-width': 2 * scale }));
    const o = solution.axes.find((a) => a.name === 'O');
    for (const a of solution.axes)
      if (o && a !== o) {
        layer.append(styled(svg('line', { class: 'axis', x1: o.u, y1: o.v, x2: a.u, y2: a.v, 'stroke-width': 2 * scale }),
          { stroke: colour.axis }));
        label(a.u, a.v, a.name, 'axis');
      }
    for (const p of solution.expected) {
      const s = 5 * scale;
      layer.append(styled(svg('path', { class: 'expected', 'stroke-width': 1.5 * scale,
        d: `M${p.u},${p.v - s}L${p.u + s},${p.v}L${p.u},${p.v + s}L${p.u - s},${p.v}Z` }), { fill: 'none', stroke: colour.expected }));
      label(p.u, p.v, p.name + sideOf(p.name), 'expected');
    }
    for (const p of solution.points) {
      const s = 5 * scale;
      layer.append(svg('path', { class: 'model', 'stroke-width': 1.5 * scale,
        d: `M${p.u_model - s},${p.v_model - s}L${p.u_model + s},${p.v_model + s}M${p.u_model - s},${p.v_model + s}L${p.u_model + s},${p.v_model - s}` }));
    }
  }
  const residual = new Map((solution ? solution.points : []).map((p) => [p.name, p.residual_px]));
  for (const p of V.points)
    if (p.u !== null) {
      layer.append(styled(svg('circle', { class: p.name === loo ? 'clicked suspect' : 'clicked', cx: p.u, cy: p.v, r,
        'stroke-width': 1.5 * scale }), p.name === loo ? { stroke: colour.suspect } : {}));
      label(p.u, p.v, p.name + sideOf(p.name) + (residual.has(p.name) ? ` ${residual.get(p.name).toFixed(2)} px` : ''),
        p.name === loo ? 'suspect' : 'clicked-label');
    }
}

async function saveScene() {
  const clicks = clickedPoints();
  const name = $('s-name').value.trim() || 'main';
  const result = await change('PUT', `/api/scenes/${encodeURIComponent(name)}`,
    Object.assign({ video: V.video, row: V.rowId, clicks }, sceneInputs()));
  if (result && result.error) { $('s-result').replaceChildren(el('span', { class: 'error' }, 'Not saved: ' + result.error)); return; }
  if (result && !result.conflict) showMessage(`Scene "${name}" saved as ${S.experiment.scenes[name]}`, 'info');
}

// ---- tracking -------------------------------------------------------------------------------------
async function track() {
  if (V.rowId === null) return;
  const id = V.rowId;
  $('t-run').disabled = true;
  $('track-summary').textContent = '— tracking (every frame)…';
  try {
    const { status, data } = await api('POST', `/api/rows/${id}/track`, {});
    if (status !== 200) {
      $('track-summary').textContent = '';
      $('t-result').replaceChildren(el('p', { class: 'error' }, data.error));
      return;
    }
    V.track = Object.assign({ row: id }, data);
    renderTrack();
  } finally {
    $('t-run').disabled = false;
  }
}

function renderTrack() {
  const t = V.track, d = lengthDecimals();
  const out = $('t-result');
  out.replaceChildren();
  $('track-summary').textContent = `— ${t.frames_tracked} of ${t.frames} frames` + (t.partial ? ` (partial: ${t.partial_reason})` : '');
  const dl = el('dl', { class: 'analysis' });
  const add = (k, v) => { dl.append(el('dt', {}, k), el('dd', {}, v)); };
  const pm = (q) => (q ? `${fmt(q.value, d)} ± ${fmt(q.u, d)} ${S.unit}` : '—');
  add('release', t.release ? `x0 = ${pm(t.release.x0)} at t0 = ${t.release.t0.value.toFixed(3)} ± ${t.release.t0.u.toFixed(3)} s` : '—');
  add('direction', t.direction || '—');
  add('turning points', t.turns && t.turns.length ? t.turns.map((p) => `${fmt(p.x, d)} ${S.unit} at ${p.t.toFixed(2)} s`).join('; ') : 'none');
  add('rest', t.rest ? `Y = ${pm(t.rest.y)} from ${t.rest.t.toFixed(2)} s` : (t.never_at_rest || 'never at rest'));
  add('motion fit', t.fit ? t.fit.text : '—');
  out.append(dl);
  for (const w of t.warnings || []) out.append(el('p', { class: 'error' }, w));
  $('t-accept').hidden = !t.rest;
  const strip = $('t-strip');
  strip.replaceChildren();
  for (const f of t.strip || []) {
    const fig = el('figure');
    const img = el('img', { alt: `frame ${f.frame}`, src: `/api/video/frame?video=${encodeURIComponent(V.video)}&frame=${f.frame}&format=jpeg` });
    const outline = svg('svg', { viewBox: `-0.5 -0.5 ${t.width} ${t.height}`, preserveAspectRatio: 'xMinYMin meet' });
    if (f.u !== null) outline.append(svg('circle', { cx: f.u, cy: f.v, r: f.radius_px, 'vector-effect': 'non-scaling-stroke' }));
    fig.append(img, outline, el('figcaption', {}, `${f.t.toFixed(2)} s` + (f.x === null ? ' (not found)' : `, x = ${fmt(f.x, d)}` + (f.u_x === null ? '' : ` ± ${fmt(f.u_x, d)}`) + ` ${S.unit}`)));
    strip.append(fig);
  }
}

async function acceptY() {
  if (!V.track || V.track.row !== V.rowId) return;
  const result = await change('POST', `/api/rows/${V.rowId}/accept-y`, {});
  if (result && !result.error && !result.conflict) showMessage('Y set from the video\'s rest position', 'info');
}

// ---- wiring ---------------------------------------------------------------------------------------
buildPlayer();
$('v-status').before(el('button', { type: 'button', id: 'v-detach', hidden: '', title: 'Detach the video from this trial' },
  'Detach the video'), ' ');
$('camera-form').addEventListener('submit', calibrateCamera);
$('v-row').addEventListener('change', () => showRow($('v-row').value === 'new' ? null : Number($('v-row').value)));
$('v-attach').addEventListener('click', () => attach($('v-file').value));
$('v-upload').addEventListener('change', () => upload($('v-upload').files[0]));
$('cam-upload').addEventListener('change', () => uploadViews([...$('cam-upload').files]));
$('s-img').addEventListener('click', frameClick);
$('s-zoom').addEventListener('change', () => { applyZoom(); drawOverlay(); });
$('s-play').addEventListener('click', togglePlay);
$('s-scrub').addEventListener('input', () => loadFrame(true));
$('s-scrub').addEventListener('change', () => loadFrame(false));
$('v-detach').addEventListener('click', detach);
$('s-table').addEventListener('change', loadPoints);
$('s-marks').addEventListener('change', loadPoints);
$('s-add').addEventListener('click', addOwnPoint);
$('s-save').addEventListener('click', saveScene);
$('t-run').addEventListener('click', track);
$('t-accept').addEventListener('click', acceptY);
loadVideoList();
// app.js may have applied the first state before this script ran (its request can answer before
// this file arrives, in a browser without a cache): show it now.
if (S) onStateApplied();
