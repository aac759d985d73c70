// The page's "fit" column, loaded after app.js (its helpers el, change, showMessage, busy).
'use strict';

// The row's "fit" box: unticking asks why and saves the reason in measurements.csv's `excluded` column, which
// the live fit, `uphill fit`, `report` and Python honour; an ordinary PUT of the row, so Undo reverts it.
function excludedCell(row) {
  const td = el('td', { class: 'fit-toggle' });
  const box = td.appendChild(el('input', { type: 'checkbox', 'aria-label': `fit trial ${row.trial}`,
    title: row.excluded ? `Excluded from the fit: ${row.excluded}` : 'Fitted: untick to exclude it (asks why)' }));
  box.checked = !row.excluded;
  box.addEventListener('change', async () => {
    let reason = '';
    if (!box.checked) {
      reason = window.prompt(`Why leave trial "${row.trial}" out of the fit?`, row.check?.flags?.[0]?.message || '');
      if (reason === null || busy) { box.checked = true; return; }
      reason = reason.trim() || 'excluded on the page';
    }
    const { id, check, excluded, ...stored } = row;
    const result = await change('PUT', `/api/rows/${id}`, { row: reason ? { ...stored, excluded: reason } : stored });
    if (result && !result.error && !result.conflict) showMessage(reason ? `Trial "${row.trial}" excluded from the fit — Undo (Ctrl+Z) takes it back` : `Trial "${row.trial}" is fitted again`, 'info');
    else if (box.isConnected) box.checked = !reason;
  });
  return td;
}
