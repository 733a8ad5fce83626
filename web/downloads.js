// The downloads: the G-code and the report as the planner wrote them, and
// the two clicks a G-code that touches the part needs.
import { $, state } from './page.js';
import { showError } from './status.js';

// A press on a download link that ends the edit of a field re-planning on
// change: the field's change hides the link under the pointer and the
// click is lost. The press is kept ({id, at, replanned}) and the link is
// clicked for the user once the plan for the new value is offered.
let press = null;
const PRESS_KEPT_MS = 30_000;

const GCODE_LABEL = 'Download G-code';
// G-code written only because the risk was accepted: the labels name the
// risk, moves that touch the part or another refusal (dispensing far above
// the surface, a scan below the bed, ...: the report's accepted risks).
const RISKY = {
  touching: { head: 'The nozzle touches the part.', words: 'the nozzle touches the part' },
  other: { head: 'Written only because you accepted the risk.', words: 'at your risk' },
};
// The labels of a risky G-code's button: before and after the first click.
// A plan on the demo part says so first, as the plain button does.
function riskOf(plan) {
  const risk = RISKY[plan.summary.motion.program.touching_moves > 0 ? 'touching' : 'other'];
  const words = plan.onDemoPart ? `for the demo part; ${risk.words}` : risk.words;
  return { head: risk.head, label: `${GCODE_LABEL} (${words})…`, confirm: `Download anyway (${words})` };
}
const REPORT_LABEL = 'Download report';
const WRITING_LABEL = 'Writing the report…';

// The report offered {plan, name, writing}: the worker writes its JSON
// when the link is first clicked (tens of MB for a large drawing, not
// written at every re-plan).
let reportOffer = null;

export function hideDownloads() {
  const g = $('dl-gcode');
  g.hidden = true;
  $('dl-report').hidden = true;
  for (const u of state.urls) URL.revokeObjectURL(u);
  state.urls = [];
  g.removeAttribute('href');
  $('dl-report').removeAttribute('href');
  g.textContent = GCODE_LABEL;
  g.classList.remove('risky', 'armed');
  g.removeAttribute('tabindex');
  state.risky = null;
  const r = $('dl-report');
  r.textContent = REPORT_LABEL;
  r.removeAttribute('tabindex');
  reportOffer = null;
  $('risk-warning').hidden = true;
}

function linkBytes(el, bytes, type, name) {
  const url = URL.createObjectURL(new Blob([bytes], { type }));
  state.urls.push(url);
  el.href = url;
  el.download = name;
  el.hidden = false;
}

// The G-code and report as the planner wrote them (bytes, no string copy).
// G-code whose moves touch the part (written because the risk was accepted)
// has no link until the user confirms: the first click turns the button
// into "Download anyway", the second downloads.
export function offerDownloads(plan) {
  hideDownloads();
  const drawing = plan.svgName.replace(/\.[^.]*$/, '') || 'path';
  // A user's drawing on a demo part is named so, in the file and on the
  // button: not for the user's own part.
  const stem = plan.onDemoPart ? `${drawing}-on-the-demo-part` : drawing;
  const gcodeName = `${stem}-${plan.planner}.gcode`;
  const motion = plan.summary.motion;
  if (motion.risk_accepted) {
    const g = $('dl-gcode');
    const risk = riskOf(plan);
    state.risky = { plan, name: gcodeName, confirm: risk.confirm };
    g.textContent = risk.label;
    g.classList.add('risky');
    g.tabIndex = 0;
    g.hidden = false;
    $('risk-warning-head').textContent = risk.head;
    $('risk-warning-text').textContent = `safe motion: ${plan.summary.motion_line}`;
    $('risk-warning').hidden = false;
  } else {
    linkBytes($('dl-gcode'), plan.gcodeBytes, 'text/plain', gcodeName);
    if (plan.onDemoPart) $('dl-gcode').textContent = `${GCODE_LABEL} (for the demo part)`;
  }
  // No link until the report is written: focusable and pressed as one.
  // A plan whose worker has ended since (a cancel offers the plan on
  // screen again) has no report to write: none is offered.
  if (plan.worker === undefined || plan.worker === state.workerGen) {
    const r = $('dl-report');
    reportOffer = { plan, name: `${stem}-${plan.planner}.json`, writing: false };
    r.download = reportOffer.name;
    r.tabIndex = 0;
    r.hidden = false;
  }
  const p = press;
  if (p && p.replanned) {
    press = null;
    // A touching plan's G-code still needs its own two clicks.
    const risky = p.id === 'dl-gcode' && state.risky;
    if (!risky && performance.now() - p.at < PRESS_KEPT_MS) $(p.id).click();
  }
}

// Something the plan depends on changed (downloads hidden): whether it was
// the press on a link that ended a field's edit. Returns true if so.
export function pressReplans() {
  if (press && !press.replanned && performance.now() - press.at < 1000) press.replanned = true;
  else if (press && !press.replanned) press = null;
  return !!press;
}

// Whether a download follows the plan being made.
export function downloadFollows() {
  return !!(press && press.replanned);
}

// The plan for the new value failed or was cancelled: no download follows.
export function dropPress() {
  press = null;
}

// The first click on a touching plan's G-code asks for the second.
export function onGcodeClick(e) {
  const r = state.risky;
  const g = $('dl-gcode');
  if (!r || g.classList.contains('armed')) return;
  e.preventDefault();
  linkBytes(g, r.plan.gcodeBytes, 'text/plain', r.name);
  g.textContent = r.confirm;
  g.classList.add('armed');
}


// A click on the report before it is written: the worker writes it, then
// the link downloads it (a later click downloads the same bytes).
async function onReportClick(e) {
  const r = $('dl-report');
  if (r.getAttribute('href')) return;
  e.preventDefault();
  const offer = reportOffer;
  if (!offer || offer.writing) return;
  offer.writing = true;
  r.textContent = WRITING_LABEL;
  try {
    const bytes = await offer.plan.reportBytes();
    // Another plan offered meanwhile: its own report is asked for.
    if (reportOffer !== offer) return;
    linkBytes(r, bytes, 'application/json', offer.name);
    r.textContent = REPORT_LABEL;
    r.click();
  } catch (err) {
    if (reportOffer === offer) r.textContent = REPORT_LABEL;
    showError('Could not write the report', String((err && err.message) || err));
  } finally {
    offer.writing = false;
  }
}

export function bindDownloads() {
  for (const id of ['dl-gcode', 'dl-report']) {
    const a = $(id);
    a.addEventListener('mousedown', (e) => {
      if (e.button === 0) press = { id, at: performance.now(), replanned: false };
    });
    a.addEventListener('click', () => { press = null; });
  }
  // A press that did not end an edit ends with its own click (or none).
  window.addEventListener('mouseup', () => setTimeout(() => {
    if (press && !press.replanned) press = null;
  }, 0), true);
  $('dl-gcode').addEventListener('click', onGcodeClick);
  $('dl-report').addEventListener('click', onReportClick);
  $('dl-report').addEventListener('keydown', (e) => {
    if (e.key === 'Enter' || e.key === ' ') {
      e.preventDefault();
      $('dl-report').click();
    }
  });
  $('dl-gcode').addEventListener('keydown', (e) => {
    // A touching plan's button has no link until confirmed: keys click it.
    if ((e.key === 'Enter' || e.key === ' ') && state.risky && !$('dl-gcode').classList.contains('armed')) {
      onGcodeClick(e);
    }
  });
}
