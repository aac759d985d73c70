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
// A file's size as people read it: 812 B, 45 kB, 3.2 MB (powers of 1000, as file managers show).
const formatBytes = (n) => n < 1000 ? `${n} B` : n < 1e6 ? `${(n / 1e3).toFixed(n < 1e4 ? 1 : 0)} kB`
  : n < 1e9 ? `${(n / 1e6).toFixed(1)} MB` : `${(n / 1e9).toFixed(2)} GB`;
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
      setStatus('Not saved: the experiment changed meanwhile (another tab or person)', 'error');
      showMessage(data.error, 'error');
      return { conflict: true };
    }
    setStatus('Not saved: ' + (data.error || 'HTTP ' + status), 'error');
    if (!data.errors || data.errors.length < 2) showMessage(data.error || 'HTTP ' + status, 'error');
    return { error: data.error, field: data.field, errors: data.errors || [] };
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
    // Only a newer state: an answer that left before this page's own change arrives after it.
    if (status === 200 && data.version > S.version && !busy && editingId === null) { applyState(data); savedStatus(); }
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
  $('f-fit').value = (e.video_analysis || {}).fit === 'mu' ? 'mu' : 'g';
  showBodyFields();
  showFormErrors([]);
  formDirty = false;
}

function showBodyFields() {
  const type = $('f-body').value;
  for (const label of document.querySelectorAll('[data-body]')) label.hidden = !label.dataset.body.split(' ').includes(type);
  $('f-R-name').textContent = type === 'double-cone' ? 'cone radius R' : 'ball radius R';
}

// ---- the form's errors: all at once, each named as its label says and its field highlighted -----
function formFieldIds() {
  const ids = { 'experiment.notes': 'f-notes', 'experiment.body': 'f-body', 'experiment.body.type': 'f-body',
    'experiment.apparatus.L_convention': 'f-conv', 'experiment.video_analysis.fit': 'f-fit', unit: 'f-unit' };
  for (const [k, id] of Object.entries(FORM)) ids['experiment.' + k] = id;
  for (const [k, id] of Object.entries(BODY_DIMS)) ids['experiment.body.' + k] = id;
  for (const [k, id] of Object.entries(APPARATUS)) ids['experiment.apparatus.' + k] = id;
  for (const [k, id] of Object.entries(UNCERTAINTIES)) ids['experiment.uncertainties.' + k] = id;
  return ids;
}

// The words of a field's label, without its input ("ball radius R", "Square (mm)").
function labelText(input) {
  const label = input.closest('label');
  if (!label) return input.name || input.id;
  const copy = label.cloneNode(true);
  for (const c of copy.querySelectorAll('input, select, textarea')) c.remove();
  return copy.textContent.replace(/\s+/g, ' ').trim();
}

function showFormErrors(errors) {
  const list = $('experiment-error');
  list.replaceChildren();
  for (const f of $('experiment-form').querySelectorAll('.field-error')) f.classList.remove('field-error');
  const ids = formFieldIds();
  let first = null;
  for (const e of errors) {
    const input = ids[e.field] ? $(ids[e.field]) : null;
    if (input) { input.classList.add('field-error'); first = first || input; }
    list.append(el('li', { class: 'error' }, `${input ? labelText(input) : e.field}: ${e.error}`));
  }
  if (first) first.focus();
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
  // What the motion fit measures, from the form (video_analysis.fit; "g" is the default).
  const analysis = Object.assign({}, e.video_analysis || {});
  if ($('f-fit').value === 'mu') analysis.fit = 'mu'; else delete analysis.fit;
  if (Object.keys(analysis).length) e.video_analysis = analysis; else delete e.video_analysis;
  return e;
}

async function saveExperiment(event) {
  event.preventDefault();
  showFormErrors([]);
  const wasNew = !S.exists;
  const result = await change('PUT', '/api/experiment', { experiment: experimentFromForm(), unit: $('f-unit').value });
  if (result && result.error) {
    showFormErrors(result.errors.length ? result.errors : [{ field: result.field || '', error: result.error }]);
    return;
  }
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
    el('th', { class: 'num' }, `X${S && S.rows.some((r) => r.check && r.check.u_x > 0) ? ' ± u(X)' : ''} (${u})`), el('th', { class: 'num' }, `Y − X (${u})`),
    el('th', {}, 'flags'), el('th', {}, 'fit'), el('th', {}, ''));
}

function computedCells(tr, check) {
  const d = lengthDecimals();
  const c = check || {};
  tr.append(el('td', { class: 'num' }, fmt(c.theta_deg, 3)), el('td', { class: 'num' }, fmt(c.alpha_deg, 3)));
  // Without any uncertainty set, X is exact for the page: shown without "± 0".
  const x = c.x === null || c.x === undefined ? '' : c.u_x > 0 ? `${fmt(c.x, d)} ± ${fmt(c.u_x, d + 1)}` : fmt(c.x, d);
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
  // What is typed in the row being edited survives a re-render (a new state, a conflict).
  const editing = body.querySelector('tr.editing');
  const typed = editing && Number(editing.dataset.id) === editingId ? rowFromInputs(editing) : null;
  body.replaceChildren();
  if (!S) return;
  S.rows.forEach((row, i) => {
    if (row.id === editingId) {
      const tr = inputRow(typed ? Object.assign({ check: row.check }, typed) : row, 'edit');
      tr.dataset.id = String(row.id);
      if (typeof markTheirs === 'function') markTheirs(tr, row);  // rows.js: a conflict's values
      body.append(tr);
      return;
    }
    const tr = el('tr', { tabindex: '0', dataset: { id: String(row.id) } });
    tr.append(el('td', { class: 'num muted' }, i + 1), el('td', {}, row.trial), el('td', {}, row.series));
    for (const q of rowColumns()) tr.append(valueCell(row, q));
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

// A saved value; an empty one is asked for (a trial created from its video has no setting yet),
// except a Y that the row's video gives: such a row is fitted once its Y comes from the video.
function valueCell(row, q) {
  const v = row[q] ?? '';
  if (v !== '') return el('td', { class: 'num ' + fieldClass(row.check, q) }, v);
  if (q === 'Y' && row.video) return el('td', { class: 'num muted', title: 'Y comes from the video: Track, then accept the rest position' }, 'from video');
  return el('td', { class: 'num field-error missing', title: `${q} is missing: Edit the row (Enter) and type it` }, `${q}?`);
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
  // A draft whose setting is complete has its check (X, where to look) before Y is typed.
  let check = null;
  if (answer.status === 200 && (data.complete || (data.x !== undefined && data.x !== null))) check = data;
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
  if (check) for (const f of check.flags) list.append(el('li', { class: f.severity === 'error' ? 'error' : '' }, f.message));
  if (!data.complete && data.error && Object.values(row).some((v) => v && v !== row.trial && v !== row.id)) {
    list.append(el('li', { class: 'info' }, (check ? `X = ${fmt(check.x, lengthDecimals())} ${S.unit}: look for the body there. ` : '') +
      'Not complete yet: ' + data.error));
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
    else if (result && result.conflict) editConflict(id, row);  // rows.js: kept, with theirs beside it
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
  if (typeof clearConflict === 'function') clearConflict();
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
