// The report: the scan's line, the plan's statistics and warnings, its
// quality and safe motion, the planners compared in a table and the plot
// of every planner's error against slope and curvature.
import { clearanceCapAboveTolMm } from '../pkg/pcpp.js';
import { showFiducials } from './fiducials.js';
import {
  $, cell, el, fmt, fmtPoint, pageText, state, swatch,
} from './page.js';
import { showScanPlacement } from './placement.js';
import { drawPlot, plannerColor } from './plot.js';
import { showError } from './status.js';
import {
  requestDraw, setViewShows, updateDragOffset, updateMarkers,
} from './view.js';

// A file's size as people read it: a 120 KB glTF was "0.0 MiB".
const sizeText = (bytes) => (bytes >= (1 << 20) ? `${(bytes / (1 << 20)).toFixed(1)} MiB`
  : bytes >= 1024 ? `${(bytes / 1024).toFixed(1)} KiB` : `${bytes} bytes`);

export function showScan(info, positions, indices, seconds) {
  state.info = info;
  state.regFailed = false;
  $('scan-name').textContent = info.name;
  const [lo, hi] = info.bbox_mm;
  $('scan-info').textContent = `${info.format.toUpperCase()}, ${info.triangles.toLocaleString('en')} triangles, `
    + `${fmt(hi[0] - lo[0], 1)} × ${fmt(hi[1] - lo[1], 1)} × ${fmt(hi[2] - lo[2], 1)} mm (${info.units}); `
    // (A .gltf's buffers in their own files count: QA saw "993 bytes read"
    // for a .gltf whose .bin held 674 KB.)
    + `${sizeText(info.bytes + (info.external_files || []).reduce((sum, f) => sum + f.bytes, 0))} read in ${fmt(seconds, 1)} s; `
    + `planner memory ${(state.memory / (1 << 30)).toFixed(2)} of 4 GiB`
    + (info.cloud_text ? `; ${info.cloud_text}` : '');
  if (state.viewer) {
    try {
      state.viewer.setMesh(positions, indices);
    } catch (e) {
      showError('Could not draw the scan', e.message);
    }
  }
  showFiducials();
  updateMarkers();
  showScanPlacement();
  requestDraw();
}

export function showPlan(plan) {
  const { summary, view } = plan;
  if (state.viewer) {
    try {
      state.viewer.setPathArrays(view.pieces, view.ta, view.tool, view.defects);
    } catch (e) {
      showError('Could not draw the paths', e.message);
    }
    setViewShows('plan');
    updateDragOffset();
    requestDraw();
  }
  // Which drawing on which scan the figures and warnings are of: after a
  // failed plan they stay on screen, and say so.
  labelPlan(plan, false);
  const st = summary.stats;
  const pl = summary.settings.placement;
  const rows = [
    ['placement', `(${pl.offset_mm[0]}, ${pl.offset_mm[1]}) mm, ${pl.rotation_deg}°, × ${pl.scale}`, 'shown-placement'],
    ['pieces', st.subpaths],
    ['points', st.points],
    ['tool-path length', `${fmt(st.length_mm, 2)} mm`],
    ['height change', `${fmt(st.height_change_mm)} mm`],
    ['max inclination', `${fmt(st.max_inclination_deg, 1)}°`],
    ['min radius of curvature', `${fmt(st.min_radius_mm)} mm`],
    ['print time', `${fmt(st.print_time_s, 1)} s`],
    ['registration RMS', `${fmt(summary.registration_rms_mm, 4)} mm`],
  ];
  const body = $('stats-table').tBodies[0];
  body.replaceChildren(...rows.map(([k, v, id]) => {
    const tr = el('tr');
    tr.append(el('td', k), el('td', String(v), '', id));
    return tr;
  }));
  $('warnings').replaceChildren(...summary.warnings.map((w) => el('li', pageText(w))));
  showMotion(summary);
  // A long path's plot waits for the end of a drag.
  if (!state.interacting || view.defects.length < 20000) showErrorPlot();
}

// The figures of the plan on screen, greyed when they are a previous
// plan's, and their labels.
const PLAN_FIGURES = ['motion-table', 'motion-touches', 'stats-table', 'warnings', 'plot'];
const PLAN_LABELS = ['motion-of', 'plan-of', 'plot-of'];

// Labels the figures and warnings on screen with the drawing and scan of
// `plan`; when a plan failed and this, the previous one, stays on screen
// (`previous`), they are greyed and said to be that plan's (QA round 2
// F6: the demo drawing's warnings stood under the user's drawing that
// failed, with nothing to say whose they were; round 4 F3: each panel
// says it).
export function labelPlan(plan, previous) {
  const text = `${previous ? 'the previous plan, not the one that failed: ' : ''}${plan.svgName} on ${plan.scanName}`;
  for (const id of PLAN_LABELS) $(id).textContent = text;
  for (const id of PLAN_FIGURES) $(id).classList.toggle('stale', previous);
}

// Labels the planners' comparison on screen (`state.lastComparison`, its
// drawing and scan): of the plan on screen ('current'), of a plan that
// failed ('failed': for a refusal of its motion it shows why), or of the
// previous plan, greyed, after
// one that failed without a comparison ('previous').
const COMPARISON_OF = {
  current: '',
  failed: 'the plan that failed, compared: ',
  previous: 'the previous plan, not the one that failed: ',
};
export function labelComparison(mode) {
  const c = state.lastComparison;
  if (!c) return;
  $('compare-of').textContent = `${COMPARISON_OF[mode]}${c.svgName} on ${c.scanName}`;
  $('compare-table').classList.toggle('stale', mode === 'previous');
  $('compare-notes').classList.toggle('stale', mode === 'previous');
}

// No comparison on screen (the last one was of another scan).
export function clearComparison() {
  $('compare-table').tBodies[0].replaceChildren();
  $('compare-notes').replaceChildren();
  $('compare-table').classList.remove('stale');
  $('compare-notes').classList.remove('stale');
  $('compare-of').textContent = '';
}

// No plan on screen (the last one was for another scan, or another frame
// of this one): its tables, warnings and plot emptied, not shown under the
// new scan's name.
export function clearPlan() {
  clearComparison();
  for (const id of ['motion-table', 'stats-table']) $(id).tBodies[0].replaceChildren();
  for (const id of ['motion-touches', 'warnings', 'plot-legend']) $(id).replaceChildren();
  $('plot-note').textContent = '';
  $('plan-time').textContent = '';
  for (const id of PLAN_LABELS) $(id).textContent = '';
  for (const id of PLAN_FIGURES) $(id).classList.remove('stale');
  const plot = $('plot');
  plot.getContext('2d').clearRect(0, 0, plot.width, plot.height);
}

// With no plan on screen (the plan on a new scan failed), the scan's own
// warnings (degenerate triangles, points left out of a cloud...): they
// were shown only with a plan's, so a failed one hid them. The units
// doubt is left to its banner.
export function showScanWarnings() {
  const info = state.info;
  if (!info || state.lastPlan) return;
  const doubt = info.units_doubt ? info.units_doubt.message : null;
  $('warnings').replaceChildren(...(info.warnings || []).filter((w) => w !== doubt)
    .map((w) => el('li', pageText(w))));
}

// The plot of the plan on screen: every planner's errors (the last
// comparison, if it was made for this plan), or one planner's coloured by
// defect. During a drag only the plan being dragged is drawn.
export function showErrorPlot() {
  const plan = state.lastPlan;
  if (!plan) return;
  const { view, summary } = plan;
  const c = state.lastComparison;
  const n = view.defects.length;
  const series = c && c.gen === plan.gen && c.series && c.series.every((x) => x.error.length === n)
    ? c.series
    : [{ planner: plan.planner, error: view.error, defects: view.defects }];
  const choice = $('plot-series').value;
  let shown;
  if (choice === 'all') {
    // The planner on screen last, on top of the others.
    shown = [...series.filter((x) => x.planner !== plan.planner), ...series.filter((x) => x.planner === plan.planner)];
  } else {
    shown = series.filter((x) => x.planner === choice);
  }
  $('plot-legend').replaceChildren(...(choice === 'all' ? series : [])
    .map((x) => swatch(plannerColor(x.planner), x.planner)));
  $('plot-note').textContent = shown.length === 0
    ? `${choice}: compared after the drag or change ends`
    : choice === 'all' ? `${shown.length} planner(s), one colour each` : `${choice}, coloured by predicted defect`;
  drawPlot($('plot'), view, shown, choice === 'all', summary.settings.nozzle.inner_diameter_mm);
}

// A clearance as the tables show it: null is "more than tol + the cap"
// (the planners' check finds the smallest clearance only that far).
function fmtClearance(c, tol) {
  return c === null || c === undefined ? `>${fmt(tol + clearanceCapAboveTolMm())}` : fmt(c);
}

export function showComparison(rows, selected, tol, notes) {
  $('compare-table').classList.remove('stale');
  $('compare-notes').classList.remove('stale');
  // The core's notes on the table, as `pcpp compare` prints them under it:
  // a planner with fewer defects whose moves come closer than tol.
  $('compare-notes').replaceChildren(...(notes || []).map((n) => el('li', n)));
  const body = $('compare-table').tBodies[0];
  body.replaceChildren(...rows.map((r) => {
    const q = r.quality;
    const mo = r.motion;
    const tr = el('tr');
    tr.dataset.planner = r.planner;
    if (r.planner === selected) tr.className = 'selected';
    for (const v of [r.planner, fmt(q.mean_abs_error_mm, 4), fmt(q.mean_negative_error_mm, 4),
      fmt(q.mean_positive_error_mm, 4), `${fmt(q.contact_pct, 1)}%`, `${fmt(q.flattening_pct, 1)}%`,
      `${fmt(q.floating_pct, 1)}%`, `${fmt(q.contact_pct + q.flattening_pct + q.floating_pct, 1)}%`]) {
      cell(tr, v);
    }
    cell(tr, String(mo.backward_moves), 'backward');
    const t = mo.tol_mm ?? tol;
    // Below tol the nozzle touches (or comes too close to) the surface.
    const touching = mo.touching_moves > 0 || (mo.min_clearance_mm !== null && mo.min_clearance_mm < t);
    cell(tr, fmtClearance(mo.min_clearance_mm, t), touching ? 'clearance bad' : 'clearance',
      touching ? `${mo.touching_moves} print move(s) closer than tol = ${t} mm` : `tol = ${t} mm`);
    cell(tr, String(mo.waypoints), 'waypoints');
    return tr;
  }));
}

// The plan's quality and safe motion (spec section 6f): the check of every
// move its G-code commands, next to the predicted quality.
function showMotion(summary) {
  const q = summary.quality;
  const m = summary.motion;
  const p = m.program;
  const touching = p.touching_moves > 0;
  let clear = 'no move passes near the scan';
  if (p.min_clearance_mm !== null && p.min_clearance_mm !== undefined) {
    const at = p.min_clearance_at ? ` at (${p.min_clearance_at.map((v) => fmt(v, 2)).join(', ')})` : '';
    const line = p.min_clearance_line ? `, G-code line ${p.min_clearance_line}` : '';
    clear = `${fmt(p.min_clearance_mm)} mm${at}${line}`;
  }
  const rows = [
    ['planner', summary.planner],
    ['predicted quality', `mean |e| ${fmt(q.mean_abs_error_mm, 4)} mm; defects `
      + `${fmt(q.contact_pct + q.flattening_pct + q.floating_pct, 1)}% (contact ${fmt(q.contact_pct, 1)}%, `
      + `flattening ${fmt(q.flattening_pct, 1)}%, floating ${fmt(q.floating_pct, 1)}%); `
      // What the figures describe, in the G-code header's words (QA round 6 F4, F5).
      + summary.quality_scope,
    'motion-quality'],
    ['min clearance, all moves', clear, 'motion-min-clear', touching ? 'bad' : ''],
    ['moves too close (< tol)', `${p.touching_moves} of ${p.moves} (tol ${m.tol_mm} mm)`, 'motion-touching',
      touching ? 'bad' : ''],
    ['waypoints added', `${m.waypoints} (+${fmt(m.extra_length_mm)} mm)`, 'motion-waypoints'],
    ['backward moves', String(m.backward_moves), 'motion-backward'],
    ['max sideways offset', `${fmt(m.max_sideways_mm)} mm`],
  ];
  if (m.risk_accepted) {
    const risks = [...(touching ? ['G-code with moves closer than tol'] : []), ...(m.accepted_risks || [])];
    rows.push(['risk', `accepted: ${risks.join('; ')}`, 'motion-risk', 'bad']);
  }
  const body = $('motion-table').tBodies[0];
  body.replaceChildren(...rows.map(([k, v, id, cls]) => {
    const tr = el('tr');
    tr.append(el('td', k), el('td', v, cls, id));
    return tr;
  }));
  $('motion-touches').replaceChildren(...p.touching.slice(0, 5).map((t) => el('li', fmtTouch(t))));
}

// A touching move in the core's words (motion::Touch's Display).
function fmtTouch(t) {
  return `${t.line ? `line ${t.line}: ` : ''}the move ${fmtPoint(t.from)} -> ${fmtPoint(t.to)} comes too close at `
    + `${fmtPoint(t.at)}: the nozzle would have to be ${fmt(t.rise_mm)} mm higher there`;
}
