// The fiducials panel's lists: the holes the core found that could be dots
// of the expected diameter (ranked by its score of size and roundness;
// border loops and holes far from a dot left out), numbered, each chosen or
// dropped as a scan point Sr with one click; the pairing of holes with the
// printer points P; the registration's residual per fiducial and its RMS.
// The registration itself runs in the core (the worker's Session).
import { parsePoints } from '../pkg/pcpp.js';
import {
  $, fmt, pageText, settings, state,
} from './page.js';

// How many of the best candidates are listed.
export const BEST = 8;
// Two points closer than this (mm) are the same hole's centre.
const SAME_MM = 1e-3;

// Set by initFiducials: {saveSettings, writeForm, schedulePlan,
// updateMarkers} (modules that import this one).
let ctx = null;

export function initFiducials(c) {
  ctx = c;
}

export const fmtPoints = (pts) => pts.map((p) => p.map((v) => +v.toFixed(4)).join(', ')).join('\n');

// The points of a text field, or none while it does not parse (the plan
// request names the error).
export function safePoints(text) {
  try {
    return parsePoints(text || '');
  } catch {
    return [];
  }
}

const near = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);

// The holes that could be dots, best first: the core sorts by score, so
// they lead the list.
function candidates(info) {
  return info.holes.filter((h) => h.candidate);
}

export function showFiducials() {
  const info = state.info;
  const holes = $('fid-holes');
  const res = $('fid-residuals');
  holes.replaceChildren();
  res.replaceChildren();
  if (!info) return;
  const s = settings;
  const cands = candidates(info);
  const list = cands.slice(0, BEST);
  if (list.length) {
    const p = document.createElement('p');
    p.textContent = `${cands.length} of ${info.holes.length} hole(s) could be ${fmt(Number(s.dotDiameter), 2)} mm `
      + `dots${cands.length > BEST ? `; the best ${BEST}` : ''} (scan frame; border loops and holes far from the `
      + 'dot\'s size or roundness left out). Click to choose 3 or more as scan points Sr:';
    holes.append(p);
    holes.append(holeList(list, info));
  } else {
    holes.textContent = info.holes.length
      ? `None of the ${info.holes.length} hole(s) looks like a ${fmt(Number(s.dotDiameter), 2)} mm dot: check the dot diameter.`
      : 'No holes found in the scan.';
  }
  const r = info.registration;
  if (state.regFailed) {
    // The last registration's residuals are not this one's (a perfect
    // 0.0000 beside "fiducials 1, 2, 3 are collinear"; found by a QA run).
    res.textContent = 'No residuals: the registration failed (see the error).';
  } else if (r.residuals_mm.length === 0) {
    res.textContent = 'No registration by fiducials.';
  } else {
    const d = Number(s.nozzle.id);
    const p = document.createElement('p');
    p.textContent = `Residuals: ${r.residuals_mm.map((v) => fmt(v, 4)).join(', ')} mm; RMS `;
    const rms = document.createElement('span');
    rms.className = 'rms';
    rms.id = 'rms';
    rms.textContent = `${fmt(r.rms_mm, 4)} mm`;
    // Above d/2 the path lands off by more than half a filament width.
    if (r.rms_mm > d / 2) {
      rms.classList.add('bad');
      rms.title = `above d/2 = ${fmt(d / 2)} mm`;
    }
    p.append(rms);
    res.append(p);
    for (const n of r.notes) {
      const q = document.createElement('p');
      q.textContent = pageText(n);
      res.append(q);
    }
  }
  showPairs(list);
  chooseNote();
}

// The candidates, numbered, with size, roundness and score; a click
// chooses one as the next scan point Sr or drops it. A chosen hole shows
// its Sr number and, once registered by these points, its residual.
function holeList(list, info) {
  const s = settings;
  const scanPts = safePoints(s.fidScanText);
  const r = info.registration;
  const byPoints = s.fidSource === 'points' && r.residuals_mm.length === scanPts.length;
  const ol = document.createElement('ol');
  ol.className = 'holes-list';
  list.forEach((h, k) => {
    const li = document.createElement('li');
    li.id = `fid-hole-${k}`;
    const at = scanPts.findIndex((p) => near(p, h.scan) < SAME_MM);
    const b = document.createElement('button');
    b.type = 'button';
    b.className = 'hole-choose';
    b.setAttribute('aria-pressed', at >= 0 ? 'true' : 'false');
    b.textContent = at >= 0 ? `Sr${at + 1}` : 'choose';
    b.title = at >= 0 ? 'Drop this hole from the scan points' : 'Add this hole as the next scan point Sr';
    b.addEventListener('click', () => toggleHole(h));
    const text = document.createElement('span');
    text.textContent = `${k + 1}. Ø ${fmt(h.diameter_mm)} mm, roundness ${fmt(h.roundness, 2)}, `
      + `score ${fmt(h.score, 2)} at (${h.scan.map((v) => fmt(v, 2)).join(', ')})`;
    li.append(b, text);
    if (at >= 0) {
      li.classList.add('chosen');
      if (byPoints) {
        const res = document.createElement('span');
        res.className = 'residual';
        res.textContent = `residual ${fmt(r.residuals_mm[at], 4)} mm`;
        li.append(res);
      }
    }
    ol.append(li);
  });
  return ol;
}

// Adds the hole as the last scan point Sr, or drops it.
function toggleHole(h) {
  const s = settings;
  const pts = safePoints(s.fidScanText);
  const at = pts.findIndex((p) => near(p, h.scan) < SAME_MM);
  if (at >= 0) pts.splice(at, 1);
  else pts.push(h.scan);
  s.fidScanText = fmtPoints(pts);
  pointsEdited();
  ctx.saveSettings();
  ctx.writeForm();
  showFiducials();
  ctx.updateMarkers();
}

// The scan points Sr or the printer points P changed: once there are as
// many of each, at least three, the scan is registered by them; with the
// scan already registered by typed points, the change re-plans (a count
// that does not match is the core's message).
export function pointsEdited() {
  const s = settings;
  const nScan = safePoints(s.fidScanText).length;
  const nPrinter = safePoints(s.fidPrinterText).length;
  if (s.fidSource !== 'points' && nScan >= 3 && nScan === nPrinter) {
    s.fidSource = 'points';
    // Not the whole form: the user may be typing in one of its fields.
    $('fid-source').value = 'points';
    ctx.schedulePlan(0);
  } else if (s.fidSource === 'points') {
    ctx.schedulePlan(300);
  }
  chooseNote();
}

// What the chosen holes still need.
function chooseNote() {
  const s = settings;
  const nScan = safePoints(s.fidScanText).length;
  const nPrinter = safePoints(s.fidPrinterText).length;
  let text = '';
  if (s.fidSource !== 'auto' && (nScan > 0 || nPrinter > 0)) {
    if (nScan < 3) text = `${nScan} scan point(s) Sr chosen: choose at least 3.`;
    else if (nPrinter !== nScan) {
      text = `${nScan} scan points Sr chosen, ${nPrinter} printer point(s) P: type or paste the printer `
        + `coordinates of the same ${nScan} fiducials, in the same order (x, y, z, one per line).`;
    }
  }
  $('fid-choose-note').textContent = text;
}

// Which hole is matched with which printer point P: one select per P row
// (the holes in the list above), the residual of each pair beside it.
// Choosing holes here types their centres as the scan points Sr.
function showPairs(list) {
  const box = $('fid-pairs');
  box.replaceChildren();
  const { info } = state;
  const s = settings;
  const printer = safePoints(s.fidPrinterText);
  if (!info || !list.length || !printer.length || s.fidSource === 'none') return;
  const scanPts = s.fidSource === 'points' ? safePoints(s.fidScanText) : [];
  const r = info.registration;
  const closest = (p, key, tol) => {
    let best = -1;
    let bd = tol;
    list.forEach((h, i) => {
      const dd = near(h[key], p);
      if (dd < bd) { bd = dd; best = i; }
    });
    return best;
  };
  const head = document.createElement('p');
  head.textContent = 'Pairs (hole → printer point P), residual:';
  const table = document.createElement('table');
  table.className = 'num pairs';
  const selects = [];
  printer.forEach((pp, i) => {
    // Preselected: the hole typed for this row, or (auto) the hole that
    // lands nearest to P after the registration.
    let chosen = -1;
    if (s.fidSource === 'points') {
      if (scanPts[i]) chosen = closest(scanPts[i], 'scan', SAME_MM);
    } else if (r.residuals_mm.length) {
      chosen = closest(pp, 'printer', Infinity);
    }
    const tr = document.createElement('tr');
    const sel = document.createElement('select');
    sel.id = `fid-pair-${i}`;
    sel.className = 'pair-select';
    sel.setAttribute('aria-label', `hole for printer point ${i + 1}`);
    sel.add(new Option('—', ''));
    list.forEach((h, k) => sel.add(new Option(`hole ${k + 1}`, String(k))));
    sel.value = chosen >= 0 ? String(chosen) : '';
    sel.addEventListener('change', () => choosePairs(list, selects));
    selects.push(sel);
    const cells = [sel, `P${i + 1} (${pp.map((v) => fmt(v, 2)).join(', ')})`,
      r.residuals_mm.length === printer.length ? `${fmt(r.residuals_mm[i], 4)} mm` : ''];
    for (const c of cells) {
      const td = document.createElement('td');
      if (typeof c === 'string') td.textContent = c;
      else td.append(c);
      tr.append(td);
    }
    table.append(tr);
  });
  box.append(head, table);
}

function choosePairs(list, selects) {
  const chosen = selects.map((sel) => (sel.value === '' ? null : list[Number(sel.value)]));
  // Registration needs a hole for every P; wait until each row has one.
  if (chosen.some((h) => !h)) return;
  const s = settings;
  s.fidScanText = fmtPoints(chosen.map((h) => h.scan));
  s.fidSource = 'points';
  ctx.saveSettings();
  ctx.writeForm();
  ctx.schedulePlan(0);
}
