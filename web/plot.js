// The error plot (the paper's Figure 3d): predicted filament error against
// surface slope and against curvature, one dot per point, for every planner
// (one colour each) or for one planner (coloured by the predicted defect).
// Drawn on a 2-D canvas from the plan's per-point arrays.

// The planner's defect codes (src/wasm.rs, defect_code).
const DEFECT_NAMES = ['good', 'contact', 'flattening', 'floating'];

const COLORS = {
  good: '#28d246',
  contact: '#e62828',
  flattening: '#ff9614',
  floating: '#2878ff',
};

// Loops, not Math.min(...xs): a long path would overflow the argument list.
function extent(values, lo = Infinity, hi = -Infinity) {
  for (const v of values) {
    if (Number.isFinite(v)) {
      if (v < lo) lo = v;
      if (v > hi) hi = v;
    }
  }
  return [lo, hi];
}

function niceRange(lo, hi) {
  if (!Number.isFinite(lo) || !Number.isFinite(hi)) { lo = 0; hi = 0; }
  if (!(hi > lo)) { lo -= 1; hi += 1; }
  const pad = 0.05 * (hi - lo);
  return [lo - pad, hi + pad];
}

// Planner colours in the every-planner plot (not the defect colours).
const PLANNER_COLORS = {
  constant: '#8a8f99',
  slope: '#e08a00',
  pcpp: '#b03fd1',
  'pcpp-guarded': '#1f6fe0',
  even: '#14a04a',
};

export function plannerColor(name) {
  return PLANNER_COLORS[name] || '#333a48';
}

// One panel: `xs` the abscissa per point; `series` [{error, defects, color}]
// (color null: each point in its defect's colour).
function panel(ctx, box, xs, series, xLabel, d) {
  const { x, y, w, h } = box;
  const [x0, x1] = niceRange(...extent(xs));
  // Contacts carry no error estimate: they are drawn on the top edge.
  let [lo, hi] = [-d, d];
  for (const sr of series) [lo, hi] = extent(sr.error, lo, hi);
  const [y0, y1] = niceRange(lo, hi);
  const px = (v) => x + ((v - x0) / (x1 - x0)) * w;
  const py = (v) => y + h - ((v - y0) / (y1 - y0)) * h;
  ctx.strokeStyle = '#c8ccd4';
  ctx.strokeRect(x, y, w, h);
  ctx.fillStyle = '#667085';
  ctx.font = '11px system-ui, sans-serif';
  ctx.textAlign = 'center';
  ctx.fillText(xLabel, x + w / 2, y + h + 26);
  for (const t of [x0, (x0 + x1) / 2, x1]) ctx.fillText(t.toFixed(2), px(t), y + h + 13);
  ctx.textAlign = 'right';
  for (const t of [y0, 0, y1]) ctx.fillText(t.toFixed(3), x - 4, py(t) + 4);
  ctx.save();
  ctx.translate(x - 40, y + h / 2);
  ctx.rotate(-Math.PI / 2);
  ctx.textAlign = 'center';
  ctx.fillText('error e (mm)', 0, 0);
  ctx.restore();
  ctx.strokeStyle = '#9aa3b2';
  ctx.setLineDash([3, 3]);
  ctx.beginPath();
  ctx.moveTo(x, py(0));
  ctx.lineTo(x + w, py(0));
  ctx.stroke();
  ctx.setLineDash([]);
  for (const sr of series) {
    const one = sr.color;
    for (let i = 0; i < xs.length; i++) {
      if (!Number.isFinite(xs[i])) continue;
      const e = sr.error[i];
      ctx.fillStyle = one || COLORS[DEFECT_NAMES[sr.defects[i]]] || COLORS.good;
      const vy = Number.isNaN(e) ? y + 3 : py(e);
      ctx.fillRect(px(xs[i]) - 1.5, vy - 1.5, 3, 3);
    }
  }
}

// Draws both panels: `view` (the plan's per-point arrays: slope and kappa,
// shared by every planner, since they plan on one surface path) and
// `series` ([{planner, error (NaN at contacts), defects}], each as long as
// the view's arrays), one colour per planner when `byPlanner`, else by
// predicted defect. A null view clears.
export function drawPlot(canvas, view, series, byPlanner, nozzleD) {
  const dpr = window.devicePixelRatio || 1;
  const cw = canvas.clientWidth || 900;
  const ch = canvas.clientHeight || 260;
  canvas.width = Math.round(cw * dpr);
  canvas.height = Math.round(ch * dpr);
  const ctx = canvas.getContext('2d');
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, cw, ch);
  if (!view || view.defects.length === 0 || !series.length) return;
  const shown = series.map((sr) => ({ ...sr, color: byPlanner ? plannerColor(sr.planner) : null }));
  const w = (cw - 130) / 2;
  panel(ctx, { x: 55, y: 10, w, h: ch - 50 }, view.slope, shown, 'slope (deg)', nozzleD);
  panel(ctx, { x: 55 + w + 65, y: 10, w, h: ch - 50 }, view.kappa, shown, 'curvature κ (1/mm)', nozzleD);
}

