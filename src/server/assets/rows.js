// Rows of `uphill serve` that arrive other than by typing one: an edit that met another tab's
// change (409), and blocks of rows pasted from a spreadsheet or imported from a CSV file.
// Loaded after app.js (its state S and helpers). The server checks everything: every pasted or
// imported row goes through the same /api/check as a typed one, and the rows are added in one
// change (POST /api/rows/import), all or none.
'use strict';

// ---- a conflict keeps the edit -------------------------------------------------------------------
// {id, mine: the row as typed here, theirs: the row as saved meanwhile (null: deleted)}
let conflict = null;
const CONFLICT_FIELDS = () => ['trial', 'series', ...rowColumns(), 'note'];

function conflictDiffs() {
  if (!conflict || !conflict.theirs) return [];
  return CONFLICT_FIELDS().filter((k) => (conflict.mine[k] ?? '') !== (conflict.theirs[k] ?? ''));
}

// The edit of row `id` was refused (409): the state is now theirs; what was typed stays in the
// row being edited, their values beside it, and two ways on.
function editConflict(id, mine) {
  conflict = { id, mine, theirs: S.rows.find((r) => r.id === id) || null };
  editingId = conflict.theirs ? id : null;
  renderRows();
  renderConflict();
  const tr = $('body').querySelector('tr.editing');
  if (tr) scheduleCheck(tr);  // the computed cells of what is typed, not of the saved row
}

function clearConflict() {
  conflict = null;
  renderConflict();
}

// Beside each field of the edited row that differs: the value saved meanwhile.
function markTheirs(tr, row) {
  if (!conflict || conflict.id !== row.id) return;
  for (const k of conflictDiffs()) {
    const input = tr.querySelector(`input[name="${k}"]`);
    if (!input) continue;
    input.classList.add('field-warn');
    input.after(el('div', { class: 'theirs' }, `saved: ${conflict.theirs[k] || '(empty)'}`));
  }
}

function renderConflict() {
  const box = $('conflict');
  box.replaceChildren();
  box.hidden = !conflict;
  if (!conflict) return;
  const label = conflict.mine.trial || conflict.id;
  const mine = (k) => `${k} = ${conflict.mine[k] || '(empty)'}`;
  if (!conflict.theirs) {
    box.append(el('p', {}, `Trial "${label}" was deleted meanwhile (another tab or person); your edit was not saved.`));
    const add = el('button', { type: 'button', class: 'primary', id: 'conflict-mine' }, 'Add mine as a new row');
    add.addEventListener('click', async () => {
      const row = Object.assign({}, conflict.mine);
      delete row.id;
      const result = await change('POST', '/api/rows', { row });
      if (result && !result.error && !result.conflict) clearConflict();
    });
    const drop = el('button', { type: 'button', id: 'conflict-theirs' }, 'Leave it deleted');
    drop.addEventListener('click', clearConflict);
    box.append(add, drop);
    return;
  }
  const diffs = conflictDiffs();
  const theirs = diffs.map((k) => `${k} = ${conflict.theirs[k] || '(empty)'}`).join(', ');
  box.append(el('p', {}, `Trial "${label}" was changed meanwhile (another tab or person): saved now ${theirs || 'the same values'}. ` +
    `Yours, ${diffs.map(mine).join(', ') || 'the same'}, is kept in the row above and not saved.`));
  const again = el('button', { type: 'button', class: 'primary', id: 'conflict-mine' },
    `Re-apply my ${diffs.map((k) => conflict.mine[k] || '(empty)').join(', ') || 'values'}`);
  again.addEventListener('click', reapplyMine);
  const take = el('button', { type: 'button', id: 'conflict-theirs' }, 'Take theirs');
  take.addEventListener('click', cancelEdit);
  box.append(again, take);
}

async function reapplyMine() {
  const { id, mine } = conflict;
  const row = Object.assign({}, mine);
  delete row.id;
  const result = await change('PUT', `/api/rows/${id}`, { row });
  if (result && result.conflict) { editConflict(id, mine); return; }
  if (result && !result.error) { editingId = null; clearConflict(); renderRows(); focusRow(id); showMessage(`Row "${row.trial}" saved`, 'info'); }
}

// ---- paste and import ------------------------------------------------------------------------------
// The columns a pasted block has when it has no header: the table's, in its order.
const tableColumns = () => ['trial', 'series', ...rowColumns(), 'note'];
const KNOWN_COLUMNS = ['trial', 'series', 'note', 'video', 'scene', 'L', 'H', 'D', 'Y', 'u_L', 'u_H', 'u_D', 'u_Y'];

// RFC 4180: quoted fields may hold the separator, quotes ("") and line breaks.
function parseDelimited(text, sep) {
  const records = [];
  let record = [], cell = '', quoted = false, line = 1, start = 1;
  for (let i = 0; i < text.length; i++) {
    const c = text[i];
    if (quoted) {
      if (c === '"' && text[i + 1] === '"') { cell += '"'; i++; } else if (c === '"') quoted = false; else cell += c;
      if (c === '\n') line++;
    } else if (c === '"' && cell === '') quoted = true;
    else if (c === sep) { record.push(cell); cell = ''; }
    else if (c === '\n' || c === '\r') {
      if (c === '\r' && text[i + 1] === '\n') i++;
      record.push(cell);
      if (record.some((v) => v.trim() !== '')) records.push({ line: start, cells: record });
      record = []; cell = ''; start = ++line;
    } else cell += c;
  }
  record.push(cell);
  if (record.some((v) => v.trim() !== '')) records.push({ line: start, cells: record });
  return records;
}

// A header cell as measurements.csv names it ("D_mm", "trial") → the row's field, or an error.
function headerField(name) {
  const m = /^(u_[LHDY]|[LHDY])(?:_(mm|cm|m|in))?$/.exec(name.trim());
  if (m) {
    if (m[2] && m[2] !== S.unit) return { error: `is in ${m[2]}, the rows of this experiment are in ${S.unit}` };
    return { field: m[1] };
  }
  return KNOWN_COLUMNS.includes(name.trim()) ? { field: name.trim() } : { error: 'is not a column of measurements.csv' };
}

// Records → rows: with a header (needed in a file; a pasted block may have one) or in the table's
// column order. Returns {rows: [{where, row}], refused: [text]}.
function recordsToRows(records, header, source) {
  const refused = [];
  let fields;
  if (header) {
    const head = records.shift();
    fields = head.cells.map((name) => {
      const h = headerField(name);
      if (h.error) refused.push(`${source}, line ${head.line}, column "${name}": ${h.error}`);
      return h.field;
    });
  } else fields = tableColumns();
  const rows = records.map((r) => {
    const row = {};
    if (r.cells.length > fields.length)
      refused.push(`${source}, line ${r.line}: ${r.cells.length} cells, but ${header ? 'the header names' : 'the table has'} ${fields.length} columns`);
    fields.forEach((f, i) => { if (f && r.cells[i] !== undefined && r.cells[i].trim() !== '') row[f] = r.cells[i].trim(); });
    return { where: `${source}, line ${r.line}`, row };
  });
  return { rows, refused };
}

// A first line with a cell "trial" names the columns (a trial labelled "trial" is not plausible).
const looksLikeHeader = (cells) => cells.some((c) => c.trim() === 'trial');

// Checks every row as a typed one is checked (/api/check), then adds them all in one change, or
// none: the report lists every refused row by line and column, and every flag of the added rows.
async function importRows(rows, refused) {
  const report = $('import-report');
  const out = [];
  const fieldName = (field) => (field || '').replace(/^row\./, '');
  for (const { where, row } of rows) {
    const { status, data } = await api('POST', '/api/check', { row });
    if (status !== 200) refused.push(`${where}: ${data.error}`);
    else if (!data.complete) refused.push(`${where}, column ${fieldName(data.field)}: ${data.error.replace(/^row\.\w+: /, '')}`);
    else for (const f of data.flags) out.push({ where, f });
  }
  report.replaceChildren();
  report.hidden = false;
  const item = (text, cls) => report.append(el('li', { class: cls }, text));
  if (refused.length) {
    item(`Nothing was added: ${refused.length} problem${refused.length === 1 ? '' : 's'} (fix them and paste or import again).`, 'error');
    for (const r of refused) item(r, 'error');
    return false;
  }
  // Adding rows overwrites nothing: after another change meanwhile, once more at the new version.
  let result = await change('POST', '/api/rows/import', { rows: rows.map((r) => r.row) });
  if (result && result.conflict) result = await change('POST', '/api/rows/import', { rows: rows.map((r) => r.row) });
  if (!result || result.conflict) { item('Nothing was added: the experiment changed meanwhile; try again.', 'error'); return false; }
  if (result.error) {
    item('Nothing was added:', 'error');
    for (const e of result.errors) {
      const m = /^rows\[(\d+)\]\.(.*)$/.exec(e.field);
      item(m ? `${rows[Number(m[1])].where}, column ${m[2]}: ${e.error}` : `${e.field}: ${e.error}`, 'error');
    }
    return false;
  }
  item(`Added ${rows.length} row${rows.length === 1 ? '' : 's'} (Undo removes them all).`, 'info');
  for (const { where, f } of out) item(`${where}, column ${f.field || '—'}: ${f.message}`, f.severity === 'error' ? 'error' : '');
  return true;
}

// A block pasted into the entry row: tab-separated rows (a spreadsheet's copy), one per line.
async function pasteRows(event) {
  const text = event.clipboardData ? event.clipboardData.getData('text/plain') : '';
  if (!/[\t\n]/.test(text.replace(/\r?\n$/, ''))) return;  // one value: an ordinary paste
  event.preventDefault();
  const records = parseDelimited(text, '\t');
  if (!records.length) return;
  const { rows, refused } = recordsToRows(records, looksLikeHeader(records[0].cells), 'pasted');
  if (await importRows(rows, refused)) { renderEntry({ trial: nextTrial() }); clearDraft(); }
}

async function importCsv() {
  const input = $('import-csv');
  const file = input.files[0];
  input.value = '';
  if (!file) return;
  const records = parseDelimited(await file.text(), ',');
  if (!records.length || !looksLikeHeader(records[0].cells)) {
    const report = $('import-report');
    report.hidden = false;
    report.replaceChildren(el('li', { class: 'error' }, `${file.name}: nothing was added: the first line must name the columns as measurements.csv does (trial,series,L_${S.unit},…)`));
    return;
  }
  const { rows, refused } = recordsToRows(records, true, file.name);
  await importRows(rows, refused);
}

$('entry').addEventListener('paste', pasteRows);
$('import-csv').addEventListener('change', importCsv);
