// The page of `uphill serve`. The server is the authority: it stores every change (journal,
// atomic files), computes θ, α, X ± u(X) and the flags, and refuses stale versions. This script
// only renders its answers. User text goes into the page with textContent, never as markup.
'use strict';

const QUANTITIES = ['L', 'H', 'D', 'Y'];
const FLAG_LABELS = {
  invalid: 'invalid', implausible: 'range?', unit_mixup: 'units?', y_below_x: 'Y < X', y_far: 'Y far from X',
  y_beyond_fall_off: 'Y > x_max', x_beyond_crossbar: 'X > crossbar',
  duplicate_trial: 'same label', duplicate_row: 'duplicate',
};
const DECIMALS = { mm: 1, cm: 2, m: 4, in: 3 };

let S = null;            // the server's state
let editingId = null;    // id of the row being edited
let checkSeq = 0;        // answers to older checks are ignored
let checkTimer = null;
let busy = false;

const $ = (id) => document.getElementById(id);
const el = (tag, props = {}, text) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'class') e.className = v; else if (k === 'dataset') Object.assign(e.dataset, v); else e.setAttribute(k, v);
  }
  if (text !== undefined && text !== null) e.textContent = String(text);
  return e;
};
const fmt = (v, d) => (v === null || v === undefined || !isFinite(v)) ? '' : Number(v).toFixed(d);
const lengthDecimals = () => DECIMALS[S ? S.unit : 'mm'] ?? 2;
const rowColumns = () => (S ? S.columns.filter((c) => !c.startsWith('u_')) : ['L', 'D', 'Y']);

// ---- talking to the server -------------------------------------------------------------------
async function api(method, path, body) {
  const options = { method, headers: {} };
  if (body !== undefined) {
    options.headers['Content-Type'] = 'application/json';
    options.body = JSON.stringify(body);
  }
  let response;
  try {
    response = await fetch(path, options);
  } catch (e) {
    setStatus('Server not reachable: nothing was saved. Is `uphill serve` running?', 'error');
    throw e;
  }
  let data = null;
  try { data = await response.json(); } catch (e) { data = { error: 'HTTP ' + response.status }; }
  return { status: response.status, data };
}

function setStatus(text, kind) {
  const s = $('status');
  s.textContent = text;
  s.className = kind || '';
}

function showMessage(text, kind) {
  const m = $('message');
  m.textContent = text;
  m.className = kind || '';
  m.hidden = !text;
  clearTimeout(showMessage.timer);
  if (text) showMessage.timer = setTimeout(() => { m.hidden = true; }, kind === 'info' ? 4000 : 12000);
}

function savedStatus() {
  if (!S.exists) { setStatus('New experiment: fill in the form and create it', ''); return; }
  setStatus(`Saved: version ${S.version}, ${S.rows.length} row${S.rows.length === 1 ? '' : 's'} in ${S.directory}`, 'ok');
}

// A change: on success the new state; on 409 the current state and the server's message.
async function change(method, path, body) {
  if (!S) return null;
  busy = true;
  setStatus('Saving…', '');
  try {
    const { status, data } = await api(method, path, Object.assign({ version: S.version }, body));
    if (status === 200) { applyState(data); savedStatus(); return data; }
    if (status === 409) {
      applyState(data.state);
      savedStatus();
      showMessage(data.error, 'error');
      return { conflict: true };
    }
    setStatus('Not saved: ' + (data.error || 'HTTP ' + status), 'error');
    showMessage(data.error || 'HTTP ' + status, 'error');
    return { error: data.error, field: data.field };
  } finally {
    busy = false;
  }
}

async function load() {
  const { status, data } = await api('GET', '/api/state');
  if (status !== 200) { setStatus('Cannot load the experiment: ' + data.error, 'error'); return; }
  applyState(data, true);
  savedStatus();
}

// Other tabs or technicians: pick up their changes (never while this page has unsaved edits).
async function poll() {
  if (!S || busy || editingId !== null || document.hidden) return;
  try {
    const { status, data } = await api('GET', '/api/state');
    if (status === 200 && data.version !== S.version) { applyState(data); savedStatus(); }
  } catch (e) { /* status already says so */ }
}

// ---- the state ------------------------------------------------------------------------------
function applyState(state, fillForm) {
  const first = S === null;
  S = state;
  $('title').textContent = S.experiment.title || '';
  $('unit-label').textContent = S.exists ? `(lengths in ${S.unit})` : '';
  $('experiment-summary').textContent = S.exists ? summary() : '— not created yet';
  $('save-experiment').textContent = S.exists ? 'Save experiment' : 'Create experiment';
  if (first || fillForm || !formDirty) fillExperimentForm();
  if (first) $('experiment-details').open = !S.exists;
  $('rows-section').hidden = !S.exists;
  $('plot-section').hidden = !S.exists;
  $('undo').disabled = !S.can_undo;
  renderHead();
  renderRows();
  renderEntry();
  renderPlot();
  renderFit();
  renderReport();
  renderJournal();
  if (typeof onStateApplied === 'function') onStateApplied();  // video.js
}

// A journal the server could not trust: it kept the files and says what it found.
function renderJournal() {
  const warning = $('journal-warning');
  const damaged = S.journal && S.journal.status === 'damaged';
  warning.hidden = !damaged;
  warning.textContent = damaged ? 'Journal: ' + S.journal.message : '';
}

function summary() {
  const e = S.experiment, b = e.body || {};
  const dims = ['R', 'a', 'b', 'h'].filter((k) => b[k]).map((k) => `${k} = ${b[k]}`).join(', ');
  const app = Object.entries(e.apparatus || {}).filter(([k]) => k !== 'L_convention').map(([k, v]) => `${k} = ${v}`).join(', ');
  return `— ${b.type || ''} ${dims}${app ? '; ' + app : ''}${e.operator ? '; operator ' + e.operator : ''}`;
}

// ---- experiment form ------------------------------------------------------------------------
let formDirty = false;
const FORM = { title: 'f-title', operator: 'f-operator', date: 'f-date' };
const BODY_DIMS = { R: 'f-R', a: 'f-a', b: 'f-b', h: 'f-h' };
const APPARATUS = { L: 'f-L', H: 'f-H', D: 'f-D', rod_diameter: 'f-rod' };
const UNCERTAINTIES = { L: 'f-uL', H: 'f-uH', D: 'f-uD', Y: 'f-uY' };

function fillExperimentForm() {
  const e = S.experiment || {};
  for (const [k, id] of Object.entries(FORM)) $(id).value = e[k] || '';
  $('f-notes').value = Array.isArray(e.notes) ? e.notes.join('\n') : (e.notes || '');
  const body = e.body || {};
  $('f-body').value = body.type || 'spheroid';
  for (const [k, id] of Object.entries(BODY_DIMS)) $(id).value = body[k] || '';
  const app = e.apparatus || {};
  for (const [k, id] of Object.entries(APPARATUS)) $(id).value = app[k] || '';
  $('f-conv').value = app.L_convention || 'horizontal';
  const u = e.uncertainties || {};
  for (const [k, id] of Object.entries(UNCERTAINTIES)) $(id).value = u[k] || '';
  $('f-unit').value = S.unit || 'mm';
  $('f-unit').disabled = S.rows.length > 0;
  showBodyFields();
  formDirty = false;
}

function showBodyFields() {
  const type = $('f-body').value;
  for (const label of document.querySelectorAll('[data-body]')) label.hidden = !label.dataset.body.split(' ').includes(type);
}

function experimentFromForm() {
  const e = {};
  for (const [k, id] of Object.entries(FORM)) if ($(id).value.trim()) e[k] = $(id).value.trim();
  const notes = $('f-notes').value.split('\n').map((s) => s.trim()).filter((s) => s);
  if (notes.length) e.notes = notes;
  const type = $('f-body').value;
  e.body = { type };
  for (const [k, id] of Object.entries(BODY_DIMS)) {
    const label = $(id).closest('label');
    if (!label.hidden && $(id).value.trim()) e.body[k] = $(id).value.trim();
  }
  e.apparatus = {};
  for (const [k, id] of Object.entries(APPARATUS)) if ($(id).value.trim()) e.apparatus[k] = $(id).value.trim();
  e.apparatus.L_convention = $('f-conv').value;
  e.uncertainties = {};
  for (const [k, id] of Object.entries(UNCERTAINTIES)) if ($(id).value.trim()) e.uncertainties[k] = $(id).value.trim();
  // The calibration files and video options are set by the video section: kept as they are.
  for (const k of ['camera', 'scenes', 'video_analysis']) if (S.experiment[k] !== undefined) e[k] = S.experiment[k];
  return e;
}

async function saveExperiment(event) {
  event.preventDefault();
  $('experiment-error').textContent = '';
  const wasNew = !S.exists;
  const result = await change('PUT', '/api/experiment', { experiment: experimentFromForm(), unit: $('f-unit').value });
  if (result && result.error) { $('experiment-error').textContent = result.error; return; }
  if (result && !result.conflict) {
    formDirty = false;
    fillExperimentForm();
    if (wasNew) { $('experiment-details').open = false; focusEntry(); }
    showMessage('Experiment saved', 'info');
  }
}

// ---- table ----------------------------------------------------------------------------------
function renderHead() {
  const head = $('head-row');
  head.replaceChildren();
  const u = S ? S.unit : 'mm';
  head.append(el('th', { class: 'num' }, '#'), el('th', {}, 'trial'), el('th', {}, 'series'));
  for (const q of rowColumns()) head.append(el('th', { class: 'num' }, `${q} (${u})`));
  head.append(el('th', {}, 'note'), el('th', { class: 'num' }, 'θ (°)'), el('th', { class: 'num' }, 'α (°)'),
    el('th', { class: 'num' }, `X ± u(X) (${u})`), el('th', { class: 'num' }, `Y − X (${u})`),
    el('th', {}, 'flags'), el('th', {}, 'fit'), el('th', {}, ''));
}

function computedCells(tr, check) {
  const d = lengthDecimals();
  const c = check || {};
  tr.append(el('td', { class: 'num' }, fmt(c.theta_deg, 3)), el('td', { class: 'num' }, fmt(c.alpha_deg, 3)));
  const x = c.x === null || c.x === undefined ? '' : `${fmt(c.x, d)} ± ${fmt(c.u_x, d + 1)}`;
  tr.append(el('td', { class: 'num computed-x' }, x), el('td', { class: 'num computed-residual' }, fmt(c.residual, d)));
  const flags = el('td', { class: 'flags' });
  for (const f of (c.flags || [])) {
    flags.append(el('span', { class: 'badge' + (f.severity === 'error' ? ' error' : ''), title: f.message, dataset: { code: f.code } },
      FLAG_LABELS[f.code] || f.code));
  }
  tr.append(flags);
}

function fieldClass(check, field) {
  let cls = '';
  for (const f of ((check && check.flags) || [])) {
    if (f.field !== field) continue;
    if (f.severity === 'error') return 'field-error';
    cls = 'field-warn';
  }
  return cls;
}

function renderRows() {
  const body = $('body');
  body.replaceChildren();
  if (!S) return;
  S.rows.forEach((row, i) => {
    if (row.id === editingId) { body.append(inputRow(row, 'edit')); return; }
    const tr = el('tr', { tabindex: '0', dataset: { id: String(row.id) } });
    tr.append(el('td', { class: 'num muted' }, i + 1), el('td', {}, row.trial), el('td', {}, row.series));
    for (const q of rowColumns()) tr.append(el('td', { class: 'num ' + fieldClass(row.check, q) }, row[q] ?? ''));
    tr.append(el('td', { class: 'note' }, row.note));
    computedCells(tr, row.check);
    tr.append(typeof excludedCell === 'function' ? excludedCell(row) : el('td'));  // fit_toggle.js
    const actions = el('td', { class: 'actions' });
    const edit = el('button', { type: 'button', title: 'Edit this row (Enter)' }, 'Edit');
    edit.addEventListener('click', () => startEdit(row.id));
    const del = el('button', { type: 'button', title: 'Delete this row (Delete)' }, 'Delete');
    del.addEventListener('click', () => deleteRow(row.id));
    const video = el('button', { type: 'button', class: 'video-button', title: row.video || 'Attach a video to this trial' },
      row.video ? '▶ Video' : 'Video…');
    video.addEventListener('click', () => { if (typeof openVideoOf === 'function') openVideoOf(row.id); });
    actions.append(edit, del, video);
    tr.append(actions);
    tr.addEventListener('keydown', (ev) => {
      if (ev.target !== tr) return;
      if (ev.key === 'Enter') { ev.preventDefault(); startEdit(row.id); }
      if (ev.key === 'Delete') { ev.preventDefault(); deleteRow(row.id); }
    });
    body.append(tr);
  });
}

// A row of inputs: the entry row at the bottom (kind 'new') or a row being edited ('edit').
function inputRow(values, kind) {
  const tr = el('tr', { class: kind === 'edit' ? 'editing' : 'entry-row', dataset: { kind } });
  tr.append(el('td', { class: 'num muted' }, kind === 'edit' ? '✎' : '+'));
  const input = (name, cls, value) => {
    const td = el('td');
    const inp = el('input', { name, class: cls, 'aria-label': name, autocomplete: 'off', spellcheck: 'false' });
    if (cls.includes('num')) inp.setAttribute('inputmode', 'decimal');
    inp.value = value ?? '';
    td.append(inp);
    return td;
  };
  tr.append(input('trial', 'trial', values.trial), input('series', 'series', values.series));
  for (const q of rowColumns()) tr.append(input(q, 'num', values[q]));
  tr.append(input('note', 'note', values.note));
  computedCells(tr, kind === 'edit' ? values.check : null);
  tr.append(el('td', { class: 'fit-toggle' }, kind === 'edit' && values.excluded ? 'excluded' : ''));
  const actions = el('td', { class: 'actions' });
  const save = el('button', { type: 'button', class: 'primary' }, kind === 'edit' ? 'Save' : 'Add');
  save.addEventListener('click', () => submitRow(tr));
  actions.append(save);
  if (kind === 'edit') {
    const cancel = el('button', { type: 'button' }, 'Cancel');
    cancel.addEventListener('click', cancelEdit);
    actions.append(cancel);
  }
  tr.append(actions);
  tr.addEventListener('keydown', (ev) => {
    if (ev.key === 'Enter' && ev.target.tagName === 'INPUT') { ev.preventDefault(); submitRow(tr); }
    if (ev.key === 'Escape' && kind === 'edit') { ev.preventDefault(); cancelEdit(); }
  });
  tr.addEventListener('input', () => {
    if (kind === 'new') saveDraft(tr);
    scheduleCheck(tr);
  });
  return tr;
}

function rowFromInputs(tr) {
  const row = {};
  for (const inp of tr.querySelectorAll('input')) row[inp.name] = inp.value.trim();
  if (tr.dataset.kind === 'edit') {
    row.id = editingId;
    const stored = S.rows.find((r) => r.id === editingId) || {};
    for (const q of ['u_L', 'u_H', 'u_D', 'u_Y', 'video', 'scene', 'excluded']) if (stored[q]) row[q] = stored[q];  // kept as they were
  }
  return row;
}

// ---- draft: what is typed in the entry row survives a reload (localStorage) ---------------------
const draftKey = () => 'uphill-draft:' + (S ? S.directory : '');
function saveDraft(tr) { try { localStorage.setItem(draftKey(), JSON.stringify(rowFromInputs(tr))); } catch (e) { /* private mode */ } }
function loadDraft() { try { return JSON.parse(localStorage.getItem(draftKey()) || 'null'); } catch (e) { return null; } }
function clearDraft() { try { localStorage.removeItem(draftKey()); } catch (e) { /* ignore */ } }

let entryValues = null;  // kept across re-renders (a poll must not wipe what is being typed)
// values: start the entry row afresh with these (after a save); otherwise keep what is typed.
function renderEntry(values) {
  const entry = $('entry');
  const old = entry.querySelector('tr');
  if (values) entryValues = values; else if (old) entryValues = rowFromInputs(old);
  const focused = document.activeElement && old && old.contains(document.activeElement) ? document.activeElement.name : null;
  entry.replaceChildren();
  if (!S || !S.exists) return;
  if (!entryValues) entryValues = loadDraft() || { trial: nextTrial() };
  const tr = inputRow(entryValues, 'new');
  entry.append(tr);
  if (focused) { const f = tr.querySelector(`input[name="${focused}"]`); if (f) f.focus(); }
  scheduleCheck(tr);
}

function focusEntry() {
  const first = $('entry').querySelector('input');
  if (first) first.focus();
}

// The next trial label: the last label with its trailing number + 1 (t09 → t10), else "1".
function nextTrial(after) {
  const labels = S.rows.map((r) => r.trial);
  let base = after || labels[labels.length - 1];
  if (!base) return '1';
  for (let guard = 0; guard < 10000; guard++) {
    const m = /^(.*?)(\d+)$/.exec(base);
    base = m ? m[1] + String(Number(m[2]) + 1).padStart(m[2].length, '0') : base + '-2';
    if (!labels.includes(base)) return base;
  }
  return '';
}

// ---- live checks --------------------------------------------------------------------------------
function scheduleCheck(tr) {
  clearTimeout(checkTimer);
  checkTimer = setTimeout(() => checkRow(tr), 150);
}

async function checkRow(tr) {
  if (!tr.isConnected) return;
  const row = rowFromInputs(tr);
  const seq = ++checkSeq;
  let answer;
  try { answer = await api('POST', '/api/check', { row }); } catch (e) { return; }
  if (seq !== checkSeq || !tr.isConnected) return;
  const list = $('entry-flags');
  list.replaceChildren();
  const data = answer.data || {};
  let check = null;
  if (answer.status === 200 && data.complete) check = data;
  // Refresh the computed cells of this row.
  const cells = [...tr.children];
  const computedStart = 3 + rowColumns().length + 1;
  const tmp = el('tr');
  computedCells(tmp, check);
  [...tmp.children].forEach((td, i) => cells[computedStart + i].replaceWith(td));
  for (const inp of tr.querySelectorAll('input')) {
    inp.classList.remove('field-warn', 'field-error');
    const cls = fieldClass(check, inp.name);
    if (cls) inp.classList.add(cls);
  }
  if (check) {
    for (const f of check.flags) list.append(el('li', { class: f.severity === 'error' ? 'error' : '' }, f.message));
  } else if (data.error && Object.values(row).some((v) => v && v !== row.trial && v !== row.id)) {
    list.append(el('li', { class: 'info' }, 'Not complete yet: ' + data.error));
  }
  tr.dataset.checked = String(seq);
  renderPlot(check);
}

// ---- changes ------------------------------------------------------------------------------------
async function submitRow(tr) {
  if (busy) return;
  const row = rowFromInputs(tr);
  if (tr.dataset.kind === 'edit') {
    const id = row.id;
    delete row.id;
    const result = await change('PUT', `/api/rows/${id}`, { row });
    if (result && !result.error && !result.conflict) { editingId = null; renderRows(); focusRow(id); }
    else if (result && result.conflict) { editingId = null; renderRows(); }
    return;
  }
  delete row.id;
  let result = await change('POST', '/api/rows', { row });
  // Adding a row never overwrites anything: after a conflict (someone else saved meanwhile) the
  // page retries once against the new version.
  if (result && result.conflict) { showMessage('Another change was saved meanwhile; your row was added after it.', 'info'); result = await change('POST', '/api/rows', { row }); }
  if (result && !result.error && !result.conflict) {
    clearDraft();
    const fresh = { trial: nextTrial(row.trial), series: row.series };
    for (const q of rowColumns()) if (q !== 'Y') fresh[q] = row[q];  // the setting often repeats
    renderEntry(fresh);
    const y = $('entry').querySelector('input[name="Y"]');
    (y || $('entry').querySelector('input')).focus();
    $('entry').querySelector('input[name="Y"]')?.select();
    showMessage(`Row "${row.trial}" saved`, 'info');
  } else if (result && result.field) {
    const name = result.field.replace(/^row\./, '');
    const inp = tr.querySelector(`input[name="${name}"]`);
    if (inp) { inp.classList.add('field-error'); inp.focus(); }
  }
}

function startEdit(id) {
  if (editingId !== null) cancelEdit();
  editingId = id;
  renderRows();
  const tr = $('body').querySelector('tr.editing');
  if (tr) { tr.querySelector('input').focus(); scheduleCheck(tr); }
}

function cancelEdit() {
  const id = editingId;
  editingId = null;
  renderRows();
  focusRow(id);
}

function focusRow(id) {
  const tr = $('body').querySelector(`tr[data-id="${id}"]`);
  if (tr) tr.focus();
}

async function deleteRow(id) {
  const row = S.rows.find((r) => r.id === id);
  const result = await change('DELETE', `/api/rows/${id}`, {});
  if (result && !result.error && !result.conflict) showMessage(`Row "${row ? row.trial : id}" deleted — Undo (Ctrl+Z) brings it back`, 'info');
}

async function undo() {
  if (!S || !S.can_undo || busy) return;
  editingId = null;
  const result = await change('POST', '/api/undo', {});
  if (result && !result.error && !result.conflict) showMessage('Undone', 'info');
}

// ---- plot: Y against X, the fit line and y = x, drawn as SVG by hand (works offline) --------------
const SVG = 'http://www.w3.org/2000/svg';
const svg = (tag, attrs = {}, text) => {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  if (text !== undefined) e.textContent = text;
  return e;
};

function niceTicks(lo, hi, count) {
  const span = hi - lo;
  const step0 = span / Math.max(count, 1);
  const mag = Math.pow(10, Math.floor(Math.log10(step0)));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((s) => span / s <= count) || 10 * mag;
  const ticks = [];
  for (let t = Math.ceil(lo / step) * step, i = 0; t <= hi + step * 1e-9 && i < 50; t += step, i++) ticks.push(Number(t.toPrecision(12)));
  return ticks;
}

let lastDraftCheck = null;
function renderPlot(draftCheck) {
  if (draftCheck !== undefined) lastDraftCheck = draftCheck;
  const plot = $('plot');
  plot.replaceChildren();
  if (!S) return;
  const W = 640, H = 420, m = { l: 64, r: 16, t: 16, b: 48 };
  const pts = S.rows.filter((r) => r.check && r.check.x !== null && r.check.y !== null)
    .map((r) => ({ x: r.check.x, y: r.check.y, u: r.check.u_x, flagged: r.check.flags.length > 0, label: r.trial, excluded: !!r.excluded }));
  const draft = lastDraftCheck && lastDraftCheck.x !== null && lastDraftCheck.y !== null ? lastDraftCheck : null;
  const all = pts.concat(draft ? [{ x: draft.x, y: draft.y }] : []);
  if (all.length === 0) {
    plot.append(svg('text', { x: W / 2, y: H / 2, 'text-anchor': 'middle', class: 'empty' }, 'No rows with X and Y yet'));
    return;
  }
  let lo = Math.min(...all.map((p) => Math.min(p.x, p.y))), hi = Math.max(...all.map((p) => Math.max(p.x, p.y)));
  if (!(hi > lo)) { lo -= 1; hi += 1; }
  const pad = (hi - lo) * 0.08;
  lo -= pad; hi += pad;
  const sx = (x) => m.l + (x - lo) / (hi - lo) * (W - m.l - m.r);
  const sy = (y) => H - m.b - (y - lo) / (hi - lo) * (H - m.t - m.b);
  const d = lengthDecimals();
  for (const t of niceTicks(lo, hi, 8)) {
    plot.append(svg('line', { x1: sx(t), x2: sx(t), y1: m.t, y2: H - m.b, class: 'grid' }));
    plot.append(svg('line', { x1: m.l, x2: W - m.r, y1: sy(t), y2: sy(t), class: 'grid' }));
    plot.append(svg('text', { x: sx(t), y: H - m.b + 16, 'text-anchor': 'middle', class: 'tick' }, String(t)));
    plot.append(svg('text', { x: m.l - 6, y: sy(t) + 4, 'text-anchor': 'end', class: 'tick' }, String(t)));
  }
  plot.append(svg('line', { x1: m.l, x2: W - m.r, y1: H - m.b, y2: H - m.b, class: 'axis' }));
  plot.append(svg('line', { x1: m.l, x2: m.l, y1: m.t, y2: H - m.b, class: 'axis' }));
  plot.append(svg('text', { x: (W + m.l) / 2, y: H - 10, 'text-anchor': 'middle', class: 'label' }, `X, predicted equilibrium (${S.unit})`));
  plot.append(svg('text', { x: 16, y: (H - m.b) / 2, 'text-anchor': 'middle', class: 'label', transform: `rotate(-90 16 ${(H - m.b) / 2})` }, `Y, measured (${S.unit})`));
  const clip = svg('clipPath', { id: 'plot-area' });
  clip.append(svg('rect', { x: m.l, y: m.t, width: W - m.l - m.r, height: H - m.t - m.b }));
  plot.append(clip);
  const area = svg('g', { 'clip-path': 'url(#plot-area)' });
  plot.append(area);
  area.append(svg('line', { x1: sx(lo), y1: sy(lo), x2: sx(hi), y2: sy(hi), class: 'diag' }));
  if (S.fit && S.fit.slope !== undefined) {
    const k = S.fit.slope, c = S.fit.intercept;
    area.append(svg('line', { x1: sx(lo), y1: sy(k * lo + c), x2: sx(hi), y2: sy(k * hi + c), class: 'fit' }));
  }
  for (const p of pts) {
    if (p.u > 0) area.append(svg('line', { x1: sx(p.x - p.u), x2: sx(p.x + p.u), y1: sy(p.y), y2: sy(p.y), class: 'errbar' }));
    const dot = svg('circle', { cx: sx(p.x), cy: sy(p.y), r: 4.5, class: 'point' + (p.flagged ? ' flagged' : '') + (p.excluded ? ' excluded' : '') });
    if (p.excluded) { dot.style.fill = 'none'; dot.style.stroke = '#999'; }  // hollow grey: shown, not fitted
    dot.append(svg('title', {}, `${p.label}: X = ${fmt(p.x, d)}, Y = ${fmt(p.y, d)}${p.excluded ? ' (excluded from the fit)' : ''}`));
    area.append(dot);
  }
  if (draft) area.append(svg('circle', { cx: sx(draft.x), cy: sy(draft.y), r: 6, class: 'point draft' }));
}

function renderFit() {
  const dl = $('fit');
  dl.replaceChildren();
  if (!S) return;
  const f = S.fit || {}, d = lengthDecimals();
  const add = (k, v) => dl.append(el('dt', {}, k), el('dd', {}, v));
  add('rows used', String(f.n ?? 0) + (f.excluded ? ` (${f.excluded} excluded)` : ''));
  if (f.unavailable) { add('fit', f.unavailable.replace(/^fit: /, '')); return; }
  add('slope k', `${fmt(f.slope, 4)} ± ${f.u_slope === null ? '—' : fmt(f.u_slope, 4)}`);
  add(`intercept c (${S.unit})`, `${fmt(f.intercept, d)} ± ${f.u_intercept === null ? '—' : fmt(f.u_intercept, d)}`);
  add('R²', fmt(f.r_squared, 5));
  add(`residual SD (${S.unit})`, f.residual_sd === null ? '—' : fmt(f.residual_sd, d + 1));
}

function renderReport() {
  const link = $('report-link');
  if (S && S.report && S.report.exists) { link.href = S.report.url; link.hidden = false; } else link.hidden = true;
}

async function writeReport() {
  const button = $('report-button');
  button.disabled = true;
  $('report-status').textContent = 'Writing the report (fits, figures)…';
  try {
    const { status, data } = await api('POST', '/api/report', {});
    if (status === 200) {
      $('report-link').href = data.url;
      $('report-link').hidden = false;
      $('report-status').textContent = `written: ${data.files.length} files in report/`;
    } else {
      $('report-status').textContent = '';
      showMessage('Report not written: ' + data.error, 'error');
    }
  } finally {
    button.disabled = false;
  }
}

// ---- wiring -------------------------------------------------------------------------------------
$('experiment-form').addEventListener('submit', saveExperiment);
$('experiment-form').addEventListener('input', () => { formDirty = true; });
$('f-body').addEventListener('change', showBodyFields);
$('undo').addEventListener('click', undo);
$('report-button').addEventListener('click', writeReport);
document.addEventListener('keydown', (ev) => {
  const typing = ev.target.tagName === 'INPUT' || ev.target.tagName === 'TEXTAREA';
  if ((ev.ctrlKey || ev.metaKey) && ev.key === 'z' && !typing) { ev.preventDefault(); undo(); }
});
setInterval(poll, 3000);
load();
