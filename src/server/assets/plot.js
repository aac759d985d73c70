// The page's plot of `uphill serve`: Y against X, the fit line and y = x, drawn as SVG by hand (the
// page works offline), and the fit's numbers. Loaded before app.js; it uses app.js's state (S) and
// helpers only when called.
'use strict';

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

