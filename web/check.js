// "Check a G-code file": any program, ours or another tool's, checked by
// the core against the scan the worker holds (every straight move along
// its length), the verdict and the touching moves listed by line, and the
// program's moves drawn in the 3-D view on request.
import { checkGcodeSize } from '../pkg/pcpp.js';
import {
  $, cell, el, fmt, fmtPoint, hooks, num, pageText, profile, settings, state,
} from './page.js';
import { clearError, showError } from './status.js';
import { drawPlanPaths, setViewShows } from './view.js';

// A user's G-code (ours or another tool's) checked by the core against the
// scan the worker holds, with the nozzle and tol of the settings: the
// worker reads the File (as it reads a scan), after any plan in flight.
// `again`: checked again by the page because the scan changed, not by the
// user (see `checkAgainstSettled`).
export function checkGcodeFile(file, again = false) {
  try {
    checkGcodeSize(file.name, file.size);
  } catch (e) {
    showCheckError(file.name, e.message, again);
    return;
  }
  const s = settings;
  const id = ++state.checkId;
  const nozzle = { inner_diameter_mm: num(s.nozzle.id), outer_diameter_mm: num(s.nozzle.od) };
  const tol = num(s.process.tol);
  // What it is checked against: the scan as the worker will hold it, after
  // any plan in flight (see `checkAgainstSettled`).
  const frame = state.busy ? state.busy.checkFrame : state.workerFrame;
  state.checking = { id, name: file.name, file, nozzle, tol, again };
  state.checkSource = { file, name: file.name, frame };
  state.checkVerdictKept = null;
  state.checkMoves = null;
  $('check-draw').hidden = true;
  $('check-panel').hidden = false;
  $('check-verdict').textContent = `checking ${file.name}…`;
  $('check-verdict').className = 'verdict';
  $('check-details').replaceChildren();
  // Read for the profile chosen (a Grbl program as Grbl reads it), by its
  // name, which a pcpp program's header names too.
  state.worker.postMessage({ type: 'check', id, file, name: file.name, nozzle, tol, dialect: profile().name });
}

// `again`: the page checked the file again after the scan changed: its
// failure (most often: the program was planned on another scan) is said in
// the check panel only, not in the red panel kept for what the user just
// did (QA round 18 F7: it came back at the top on every scan opened).
function showCheckError(name, message, again = false) {
  state.checkMoves = null;
  state.checked = null;
  if (hooks.checkShown) hooks.checkShown();
  $('check-draw').hidden = true;
  if (state.viewShows === 'check') drawCheckedMoves(false);
  $('check-panel').hidden = false;
  $('check-verdict').textContent = `could not check ${name}`;
  $('check-verdict').className = 'verdict bad';
  // Why, under the verdict too: the error panel is shared, and the next
  // plan's outcome replaces it (QA round 16 F5: a program dropped with its
  // scan said only "could not check").
  $('check-details').replaceChildren(el('p', pageText(message), 'bad', 'check-why'));
  $('check-details').classList.remove('stale');
  if (again) clearError(['check']);
  else showError(`Could not check ${name}`, message, name, 'check');
}

// A plan sent to the worker (`frame`: its scan, how the scan is read and
// placed, nozzle, tol and profile): a verdict of another frame is no
// longer the scan's as it will be, and says so until checked again (QA
// round 16 F4: a green "clear" stayed after the scan was moved 5 mm, and
// the program cut 3.3 mm into the part as now placed).
export function checkFrameLeaving(frame) {
  const src = state.checkSource;
  if (!src || src.frame === frame || state.checking) return;
  // The verdict as it stood, back if the plan leaves the scan where it was
  // (QA round 17 F6: a scan file not read left "to be checked again" for
  // good, though nothing had moved and no check followed).
  if (!state.checkVerdictKept) {
    state.checkVerdictKept = { text: $('check-verdict').textContent, className: $('check-verdict').className };
  }
  $('check-verdict').textContent = `${src.name}: to be checked again against the scan as now read and placed, `
    + 'with the nozzle and tol now set…';
  $('check-verdict').className = 'verdict';
  $('check-details').classList.add('stale');
}

// A plan settled, leaving the worker's scan in `frame` (the one before
// for a scan file it could not read, null after a restart): the program
// last checked is checked again where the frame it was checked in is
// not this one (a scan moved, re-read, placed or registered otherwise,
// another nozzle, tol or profile), its file being still at hand.
export function checkAgainstSettled(frame) {
  state.workerFrame = frame;
  const src = state.checkSource;
  const kept = state.checkVerdictKept;
  state.checkVerdictKept = null;
  // (A restarted worker is checked against once it holds a scan again.)
  if (src && frame !== null && src.frame !== frame) {
    checkGcodeFile(src.file, true);
  } else if (src && kept && src.frame === frame && !state.checking) {
    $('check-verdict').textContent = kept.text;
    $('check-verdict').className = kept.className;
    $('check-details').classList.remove('stale');
  }
}

export function onCheck(m) {
  if (m.id !== state.checkId) return;
  const req = state.checking;
  state.checking = null;
  if (m.error) {
    showCheckError(m.name, m.error, !!(req && req.again));
    return;
  }
  // A new file read and checked: the error of the check before it (or of
  // a file the page could not read at all) no longer stands beside it.
  clearError(['check', 'file']);
  $('check-details').classList.remove('stale');
  // The file checked, for the preview.
  state.checked = req ? { file: req.file, name: m.name, nozzle: req.nozzle, tol: req.tol } : null;
  if (hooks.checkShown) hooks.checkShown();
  const c = m.result;
  const sum = c.summary;
  const verdict = $('check-verdict');
  const against = `${c.file.name} against ${m.scan} (nozzle outer diameter ${c.outer_diameter_mm} mm, tol ${c.tol_mm} mm)`;
  // Clear of what was scanned, not of what was not (QA round 8 F4).
  const off = c.off_scan_moves || 0;
  // A clear check's verdict in the core's words, as the CLI says it.
  verdict.textContent = c.clear
    ? `${c.clear_verdict}; ${against}`
    // Planned for a larger nozzle or tol than this check's (QA round 6 F1).
    : sum.touching_moves === 0 && c.unchecked_lines.length === 0 && !(c.planned_otherwise || []).length
      && c.planned_nozzle
      ? `not shown clear: no move comes closer than tol with this nozzle, but ${pageText(c.planned_nozzle)}; ${against}`
    : sum.touching_moves === 0 && c.unchecked_lines.length === 0
      ? `not shown clear: no move comes closer than tol to the scan as loaded, but the program was planned `
        + `on the scan read or placed another way (${(c.planned_otherwise || []).map(pageText).join('; ')}); ${against}`
    : sum.touching_moves === 0
      ? `not shown clear: ${c.unchecked_lines.length} move(s) could not be checked (the file does not `
        + `give where they start or end, and they come lower than tol above the scan's top); `
        + `${sum.moves === 0 ? 'no move could be checked' : sum.moves === 1 ? 'the 1 checked move does not come closer than tol'
          : `none of the ${sum.moves} checked moves comes closer than tol`}; ${against}`
      : `${sum.touching_moves} of ${sum.moves} moves touch: closer than tol`
        + `${sum.touching_from_previous ? `, ${sum.touching_from_previous} of them closest at their start, where the move before each ended too close` : ''}; ${against}`;
  verdict.className = !c.clear || c.written_at_risk ? 'verdict bad' : off ? 'verdict warn' : 'verdict good';
  const details = [];
  const p = (text, id, cls) => details.push(el('p', text, cls, id));
  p(sum.min_clearance_mm === null || sum.min_clearance_mm === undefined
    ? 'minimum clearance: no move passes near the scan'
    : `minimum clearance ${fmt(sum.min_clearance_mm)} mm`
      + `${sum.min_clearance_line ? ` at line ${sum.min_clearance_line}` : ''}`
      + `${sum.min_clearance_at ? ` ${fmtPoint(sum.min_clearance_at)}` : ''}`,
  'check-min', sum.min_clearance_mm !== null && sum.min_clearance_mm < c.tol_mm ? 'bad' : '');
  if (sum.touching.length) {
    const table = document.createElement('table');
    table.id = 'check-touching';
    table.className = 'num';
    const head = table.createTHead().insertRow();
    head.append(...['line', 'move from → to', 'worst at', 'clearance mm', 'higher by mm'].map((h) => el('th', h)));
    const body = table.createTBody();
    for (const t of sum.touching) {
      const tr = body.insertRow();
      cell(tr, t.line ? String(t.line) : '—', 'line');
      cell(tr, `${fmtPoint(t.from)} → ${fmtPoint(t.to)}`);
      // A move closest where the move before it ended too close (a retract
      // out of that contact): the same contact, said as such.
      cell(tr, t.from_previous
        ? `its start, where ${t.previous_line ? `line ${t.previous_line}` : 'the move before it'} ended`
        : fmtPoint(t.at));
      cell(tr, fmt(t.clearance_mm));
      cell(tr, fmt(t.rise_mm), 'bad');
    }
    details.push(table);
    if (sum.touching_moves > sum.touching.length) {
      p(`… and ${sum.touching_moves - sum.touching.length} more touching move(s)`);
    }
  }
  if (c.unchecked_lines.length) {
    p(`${c.unchecked_lines.length} move(s) not checked (their position is not in the file): lines `
      + `${c.unchecked_lines.slice(0, 10).join(', ')}${c.unchecked_lines.length > 10 ? ', …' : ''}`, 'check-unchecked');
  }
  if (c.notes.length) {
    const ul = el('ul', undefined, 'warnings small', 'check-notes');
    ul.append(...c.notes.map((n) => el('li', pageText(n))));
    details.push(ul);
  }
  $('check-details').replaceChildren(...details);
  state.checkMoves = c.moves ? { moves: c.moves, kinds: c.kinds } : null;
  $('check-draw').hidden = !state.checkMoves;
  if (state.viewShows === 'check') drawCheckedMoves(!!state.checkMoves);
  // A plan sent since will leave the scan in another frame.
  if (req && state.busy) checkFrameLeaving(state.busy.checkFrame);
}

// The view draws the checked program's moves (on) or the plan's paths.
export function drawCheckedMoves(on) {
  if (!state.viewer) return;
  try {
    if (on && state.checkMoves) {
      state.viewer.setMoves(state.checkMoves.moves, state.checkMoves.kinds);
      setViewShows('check');
    } else {
      drawPlanPaths();
    }
  } catch (e) {
    showError('Could not draw the moves', e.message);
  }
}

// The button follows what the view shows.
export function syncCheckButton() {
  const on = state.viewShows === 'check';
  const b = $('check-draw');
  b.setAttribute('aria-pressed', on ? 'true' : 'false');
  b.textContent = on ? 'Back to the plan in the 3-D view' : 'Draw in the 3-D view';
}
