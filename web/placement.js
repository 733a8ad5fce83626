// Where the scan and the drawing go in the printer frame, on the page: the
// banner offering to place an unregistered scan on the bed (shown when the
// core finds it outside the profile's build volume), the fields that move
// and turn it there by hand (the drawing goes with it), the registration
// status in the header, and the centring of a new drawing on the scan. Every
// number comes from the core (volumeFit, bedOf, carryDrawing and the
// worker's Session.centreDrawing); this module keeps the settings and the
// elements in step.
import { bedOf, carryDrawing, volumeFit } from '../pkg/pcpp.js';
import {
  $, num, pageText, profile, settings, state,
} from './page.js';
import { clearError, showError } from './status.js';

// The scan placement the settings start with (and a new scan is read with).
export const SCAN_PLACE_DEFAULT = Object.freeze({ on: false, rot: 0, dx: 0, dy: 0, dz: 0 });

// [element id, settings key, name in messages].
const FIELDS = [
  ['bed-dx', 'dx', 'move X (mm)'],
  ['bed-dy', 'dy', 'move Y (mm)'],
  ['bed-dz', 'dz', 'move Z (mm)'],
  ['bed-rot', 'rot', 'rotate (°)'],
];

// Set by initPlacement: {saveSettings, writeForm, schedulePlan} (modules
// that import this one).
let ctx = null;
let centreTokens = 0;
const beds = new Map(); // profile key -> its bed (wasm bedOf)
// The core's sentence the banner shows, while it is shown.
let banner = null;
// The last plan's refusal for a tool path beside the scan out of the
// volume, the scan lying inside it (a drawing up to the edge of a scan in
// the bed's corner): {key: the scan's, text: the core's sentence}, until a
// plan succeeds or another scan is read.
let besideOut = null;
const BESIDE = /the scan lies inside the build volume, but beside it the tool path passes .*$/;
// The last plan's outcome, {key: its scan's, gen: its settings', written:
// whether it wrote G-code}: the banner of a scan out of the volume says
// which (QA round 4 F6: it read the same whether G-code was refused or
// written, for a scan partly below the bed whose tool path is inside).
let outcome = null;

const finite = (v) => typeof v === 'number' && Number.isFinite(v);

// The scan placement of the settings, checked: every number typed.
function scanPlace() {
  const sp = { ...SCAN_PLACE_DEFAULT, ...(settings.scanPlace || {}) };
  for (const [, key, name] of FIELDS) {
    if (!finite(sp[key])) throw new Error(`scan placement: ${name} must be a number`);
  }
  return sp;
}

function bed() {
  const { dialect, file } = profile();
  const key = `${file || ''}\u0000${dialect}`;
  let b = beds.get(key);
  if (!b) {
    b = bedOf(dialect, file);
    beds.clear();
    beds.set(key, b);
  }
  return b;
}

// Whether the scan is placed on the bed: asked for, and no fiducials (a
// scan is either registered or placed, never both; a new scan is read as
// it is until the user places it).
function placed(scan) {
  const s = settings;
  return !!(s.scanPlace && s.scanPlace.on) && s.fidSource === 'none' && !(scan && scan.asScanned);
}

// The registration's `scan_placement` (job::RegistrationSettings) for
// planning on `scan`; throws a message naming the field that is not a
// number.
export function scanPlacementFor(scan) {
  if (!placed(scan)) return { mode: 'as-scanned' };
  const sp = scanPlace();
  return { mode: 'on-bed', bed: bed(), rotation_deg: sp.rot, offset_mm: [sp.dx, sp.dy, sp.dz] };
}

// The drawing's placement as the core reads it, or null if a field is not
// a number.
function drawingPlacement() {
  const p = settings.placement;
  const v = [p.x, p.y, p.rot, p.scale].map(Number);
  if (!v.every(Number.isFinite)) return null;
  return { offset_mm: [v[0], v[1]], rotation_deg: v[2], scale: v[3] };
}

const round4 = (v) => Math.round(v * 1e4) / 1e4;

// Runs `change` (which edits the settings) and moves the drawing with the
// scan if that moved it: the drawing stays on the same part of the scan.
// Before the loaded scan was read (or while its drawing is still to be
// centred) the drawing is centred on it afterwards instead.
export function moveScan(change) {
  let before = null;
  try {
    before = scanPlacementFor(state.scan);
  } catch {
    // A field was not a number: nothing to carry from.
  }
  change();
  let after = null;
  try {
    after = scanPlacementFor(state.scan);
  } catch {
    // Shown by the plan request.
  }
  if (!before || !after || JSON.stringify(before) === JSON.stringify(after)) return;
  // The placements kept for the scan's other readings were where the scan
  // lay before: not brought back after it moved.
  readings.clear();
  const info = state.info;
  const drawing = drawingPlacement();
  if (state.centre || state.pendingScan || !info || !drawing) {
    // A centring in flight was for the scan where it was: centre again.
    if (state.centre) requestCentre(state.centre.fresh);
    return;
  }
  const [lo, hi] = info.scan_bbox_mm;
  try {
    const c = carryDrawing(drawing, [...lo, ...hi], before, after);
    const s = settings;
    s.placement.x = round4(c.offset_mm[0]);
    s.placement.y = round4(c.offset_mm[1]);
    s.placement.rot = round4(c.rotation_deg);
    // The centring's note named places where the scan lay before (QA
    // round 7 F10: a gap "at (58.739, 48.205)" 70 mm off the placed
    // scan): only the fit's stays.
    showFitNote();
    // The fields show what is planned: a nudge of one moves the drawing
    // from where it now is, not from where it was on the other bed.
    ctx.writeForm();
  } catch (e) {
    showError('Could not move the drawing with the scan', e.message);
  }
}

// The next plan centres the drawing on the scan (a new scan or drawing was
// opened, or "Centre on scan"): a fresh token, so the answer to an older
// request cannot be taken for it. A new drawing (`drawing`) starts at its
// own size: the scale set for the previous one does not carry over; the
// core scales it down if it does not fit.
// `keepScale`: centred again at the user's own scale, not fitted to the
// scan (a Scale or Rotation typed while the drawing lies where the page
// centred it: `pcpp plan --place centre,ROT,SCALE`).
export function requestCentre(drawing = false, keepScale = false) {
  const fresh = drawing || !!(state.centre && state.centre.fresh);
  state.centre = { token: ++centreTokens, fresh, keepScale: keepScale && !fresh };
}

// The drawing's placement in each reading of the scan (its units and up
// axis) the user left: read back in that way, the scan is that scan again,
// and the drawing goes back where it was (found by QA: typed at (70, 150),
// switched to cm and back to mm, it was centred anew at (45.2, 154.8)).
// Kept per scan and drawing: another file is another placement.
const readings = new Map();
// The units and up axis each scan was read with by default ("file
// default" and the units or axis it stands for are one reading: QA round
// 7 F6, +Z to +Y and back to +Z lost the drawing's place, the file's
// default being +Z).
const defaultUnits = new Map();
const defaultUp = new Map();

function readingKey() {
  const scan = state.pendingScan || state.scan;
  const key = scan ? scan.key : null;
  const drawing = settings.pathSource === 'file'
    ? (state.pendingSvg || state.svgFile || {}).key : settings.pathSource;
  const units = settings.scanUnits || defaultUnits.get(key) || '';
  const up = settings.scanUp || defaultUp.get(key) || '';
  return JSON.stringify([key, drawing, units, up]);
}

// Before the scan's units or up axis change: where the drawing lies in
// this reading (not while a centring is on its way: that one is stale).
export function leaveReading() {
  if (state.centre) readings.delete(readingKey());
  else readings.set(readingKey(), { placement: { ...settings.placement }, fit: settings.fit });
}

// The units a scan was read in when none were asked (its file's
// default): told by the worker's answer to that request (review: taken
// from the scan on screen, it could be another reading's).
export function noteDefaultUnits(key, units) {
  defaultUnits.set(key, units);
}

// The same for the up axis.
export function noteDefaultUp(key, up) {
  defaultUp.set(key, up);
}

// After they changed: the placement this reading had, or the drawing
// centred on the scan as now read (the scale fitted to another reading
// says nothing of this one).
export function enterReading() {
  const kept = readings.get(readingKey());
  if (!kept) {
    requestCentre();
    return;
  }
  settings.placement = { ...kept.placement };
  settings.fit = kept.fit;
  cancelCentre();
  showFitNote();
}

// The user placed the drawing: nothing is centred over it.
export function cancelCentre() {
  state.centre = null;
}

// The scale the user gave the drawing: the one a scan is fitted from.
// A scale the page chose to fit one scan would otherwise carry over to
// every later scan and only ever shrink.
function userScale() {
  if (settings.fit) return settings.fit.userScale;
  const v = num(settings.placement.scale);
  return v > 0 && Number.isFinite(v) ? v : 1;
}

// What a plan request carries: {token, fresh, scale, fit} (the scale to
// centre from: 1 for a new drawing, else the user's; `fit`: scaled down
// if it does not fit the scan), or null.
export function centreRequest() {
  if (!state.centre) return null;
  const { token, fresh, keepScale } = state.centre;
  return { token, fresh, scale: fresh ? 1 : userScale(), fit: !keepScale };
}

// The worker centred the drawing for the request `busy` (its token): taken
// into the settings unless the user placed it since, with the core's note
// when it was scaled to fit.
export function onCentred(m, busy) {
  if (!state.centre || !busy || !busy.centre || busy.centre.token !== state.centre.token) return;
  state.centre = null;
  const s = settings;
  // The core's numbers as they are: what the worker plans.
  s.placement = {
    x: m.placement.offset_mm[0],
    y: m.placement.offset_mm[1],
    rot: m.placement.rotation_deg,
    scale: m.placement.scale,
  };
  // The core scales only down, only to fit: a scale other than the one
  // sent is the page's choice, not the user's.
  const from = busy.centre.scale;
  s.fit = m.placement.scale !== from ? { userScale: from, note: m.note || '' } : null;
  // Where the page centred it: a Rotation or Scale typed while it is still
  // there keeps it centred (settings.js, `centredStill`).
  state.centredAt = { x: s.placement.x, y: s.placement.y };
  // What was sent is what the worker plans: the request matches again.
  busy.job.plan.placement = m.placement;
  setNote(m.note || '');
  ctx.saveSettings();
  ctx.writeForm();
}

// The scan was registered anew (its fiducials' printer points changed) and
// the worker carried the drawing with it (core carry_drawing_by): taken
// into the settings unless the user placed the drawing since the request.
export function onCarried(m, busy) {
  if (!busy) return;
  const s = settings;
  const sent = busy.job.plan.placement;
  const shown = [s.placement.x, s.placement.y, s.placement.rot].map(Number);
  if (shown[0] !== sent.offset_mm[0] || shown[1] !== sent.offset_mm[1] || shown[2] !== sent.rotation_deg) return;
  s.placement = { ...s.placement, x: m.placement.offset_mm[0], y: m.placement.offset_mm[1], rot: m.placement.rotation_deg };
  // What was sent is what the worker plans: the request matches again.
  busy.job.plan.placement = m.placement;
  ctx.saveSettings();
  ctx.writeForm();
}

// How many times the user placed the drawing: a drawing read meanwhile is
// not centred over their placement (inputs.js).
let placedByUser = 0;
export const userPlacements = () => placedByUser;

// The user moved or turned the drawing, or set its scale: nothing is
// centred over it; the note stays while the scale is still the one the
// page fitted (a move or turn leaves it so).
export function userPlaced() {
  placedByUser++;
  cancelCentre();
  showFitNote();
}

// The note under the drawing's placement (the core's, when it scaled the
// drawing to fit).
export function setNote(text) {
  $('pl-note').textContent = pageText(text);
}

// The note of the page's fit of the drawing, or none while the scale is
// the user's.
export function showFitNote() {
  setNote(settings.fit ? settings.fit.note : '');
}

// A fit kept in the browser's storage, checked: the user's scale a
// positive number, the note text.
export function sanitizeFit(fit) {
  if (!fit || typeof fit !== 'object') return null;
  const u = fit.userScale;
  if (typeof u !== 'number' || !(u > 0) || !Number.isFinite(u)) return null;
  return { userScale: u, note: typeof fit.note === 'string' ? fit.note : '' };
}

// Banner, the placement panel and the header's status, for the scan on
// screen and the settings now.
export function showScanPlacement() {
  const s = settings;
  const info = state.info;
  const status = $('reg-status');
  const line = status.parentElement;
  if (info) {
    // A registration that failed since: not the last one's sentence.
    status.textContent = state.regFailed ? 'not registered: the fiducials do not fit (see the error)'
      : info.registration.status_text;
    const registered = !state.regFailed && info.registration.status.kind === 'registered';
    line.classList.toggle('registered', registered);
    line.classList.toggle('unregistered', !registered);
  }
  const on = placed(state.pendingScan || state.scan);
  let fit = null;
  if (info) {
    const [lo, hi] = info.bbox_mm;
    const { dialect, file } = profile();
    try {
      fit = volumeFit([...lo, ...hi], dialect, file, info.units);
    } catch {
      fit = null; // a bad profile: its own error is shown when planning
    }
  }
  const outside = !!fit && !fit.inside;
  const beside = !outside && !!besideOut && !!state.scan && besideOut.key === state.scan.key;
  // The units come first: a scan read in the wrong ones is in the wrong
  // place too, and both banners at once asked two questions.
  const unitsAsked = !!info && !!info.units_doubt && !info.units_doubt.given;
  // Offered only where it helps: a scan larger than the volume does not fit
  // on the bed either (a 1 m cube was offered it, and the click failed).
  $('place-banner').hidden = !(((outside && fit.fits_on_bed) || beside) && !on && s.fidSource === 'none'
    && !state.pendingScan && !unitsAsked);
  const sentence = outside ? fit.message : beside ? besideOut.text : null;
  banner = !$('place-banner').hidden ? sentence : null;
  const known = outside && !!outcome && !!state.scan && outcome.key === state.scan.key && outcome.gen === state.gen;
  const said = !known ? '' : outcome.written
    ? ' G-code was written: the tool path itself lies inside the volume (its header carries this warning).'
    : ' No G-code was written.';
  const text = sentence ? pageText(capital(sentence)) : '';
  $('place-banner-text').textContent = !said ? text : `${text}${/[.!?]$/.test(text) ? '' : '.'}${said}`;
  $('scan-place').hidden = !on;
  if (on) {
    $('bed-name').textContent = `profile ${profile().name}`;
    const note = $('bed-note');
    const shown = info && info.registration.status.kind === 'placed-on-bed';
    // Placed already: the way back in is the placement's own offsets.
    note.textContent = shown && outside ? pageText(capital(fit.placed_message)) : '';
    note.classList.toggle('bad-note', shown && outside);
  }
  writeFields(null);
  showUnitsBanner(info);
}

// The units the Units list names.
const UNIT_NAMES = { mm: 'mm', cm: 'cm', m: 'metres', in: 'inches', ft: 'feet' };
const sizeText = (s, d) => s.map((v) => v.toFixed(d)).join(' × ');

// A scan so small in the units it was read in that they are likely wrong
// (a file in metres read as mm, which would print the drawing a thousand
// times too small): the core writes no G-code until the user gives its
// units (job::refuse_unit_doubt), and this banner offers them. Choosing
// one is choosing it in the Units list.
function showUnitsBanner(info) {
  const d = info && info.units_doubt;
  const shown = !!d && !d.given && !state.pendingScan;
  $('units-banner').hidden = !shown;
  const btns = $('units-banner-btns');
  btns.replaceChildren();
  if (!shown) {
    $('units-banner-text').textContent = '';
    return;
  }
  // A few stray vertices make it large: the core's words, and no units
  // to choose, none mend it (QA round 14: "It is in mm" was offered).
  if (d.stray) {
    $('units-banner-text').textContent = `${d.message}. No units mend this: no G-code until the file is mended.`;
    return;
  }
  $('units-banner-text').textContent = d.too_large
    ? `${info.name} is ${sizeText(d.size_mm, 1)} mm read in ${UNIT_NAMES[d.units]}, larger than any `
      + 'printer: it was most likely saved in other units. No G-code until you choose them.'
    : `${info.name} is only ${sizeText(d.size_mm, 3)} mm read in `
      + `${UNIT_NAMES[d.units]}: it was most likely saved in other units. No G-code until you choose them.`;
  const offer = (units, text, primary) => {
    const b = document.createElement('button');
    b.type = 'button';
    b.textContent = text;
    b.dataset.units = units;
    if (primary) b.className = 'primary';
    b.addEventListener('click', () => {
      const sel = $('scan-units');
      sel.value = units;
      sel.dispatchEvent(new Event('change'));
    });
    btns.append(b);
  };
  // A reading larger than the printer's build volume comes last and is
  // not the highlighted one, and says so (QA round 7 F3: metres, 1.8 m
  // across, came first for a 1.8 mm file whose inches fit, and gave a red
  // error when chosen).
  const { dialect, file } = profile();
  const fits = (o) => {
    try {
      return volumeFit([0, 0, 0, ...o.size_mm], dialect, file).fits_on_bed;
    } catch {
      return true; // a bad profile: its own error is shown when planning
    }
  };
  const offers = d.offers.map((o) => ({ ...o, fits: fits(o) })).sort((a, b) => Number(b.fits) - Number(a.fits));
  offers.forEach((o, i) => offer(o.units, `Read in ${UNIT_NAMES[o.units]} (${sizeText(o.size_mm, 1)} mm${
    o.fits ? '' : ', larger than the printer'})`, i === 0 && o.fits));
  offer(d.units, `It is in ${UNIT_NAMES[d.units]}`, false);
}

// Whether the units banner is on screen (a plan refused for the scan's
// units says no more than it does).
export function unitsBannerShown() {
  return !$('units-banner').hidden;
}

export const capital = (t) => t.charAt(0).toUpperCase() + t.slice(1);

// A plan's outcome for the banner: the error message of a refused plan,
// or null for a plan that succeeded, and the settings' `gen` it was
// planned for.
export function planOutcome(message, gen) {
  outcome = state.scan ? { key: state.scan.key, gen, written: message === null } : null;
  const m = message === null ? null : String(message).match(BESIDE);
  const next = m && state.scan ? { key: state.scan.key, text: m[0] } : null;
  if (!next && !besideOut && $('place-banner').hidden) return;
  besideOut = next;
  showScanPlacement();
}

// Whether a refusal's `message` is the tool path's, beside a scan inside
// the build volume (not the scan's own).
export const toolPathOutside = (message) => BESIDE.test(String(message));

// What a build-volume refusal's `message` is of: 'tool-path' (beside a
// scan inside the volume), 'travel' (the travel height over a scan inside
// it: the core says to lower the scan) or 'scan' (its place or size).
export function volumeCause(message) {
  if (toolPathOutside(message)) return 'tool-path';
  return /the travel height over it does not/.test(String(message)) ? 'travel' : 'scan';
}

// Whether the banner on screen offers the fix for the planning error
// `message` (the core's sentence on the scan outside the build volume is
// part of it): the banner says it better, with its button.
export function bannerOffers(message) {
  return !!banner && String(message).includes(banner);
}

// The fields from the settings (except the one being typed in).
function writeFields(except) {
  const sp = { ...SCAN_PLACE_DEFAULT, ...(settings.scanPlace || {}) };
  for (const [id, key] of FIELDS) {
    if (id === except || document.activeElement === $(id)) continue;
    $(id).value = finite(sp[key]) ? String(sp[key]) : '';
  }
}

function placeOnBed() {
  const s = settings;
  moveScan(() => {
    s.scanPlace = { ...SCAN_PLACE_DEFAULT, on: true };
    // The registration the page would otherwise read the scan with.
    s.fidSource = 'none';
  });
  clearError();
  ctx.saveSettings();
  ctx.writeForm();
  showScanPlacement();
  ctx.schedulePlan(0);
}

function backToScannerFrame() {
  const s = settings;
  moveScan(() => {
    s.scanPlace = { ...SCAN_PLACE_DEFAULT };
  });
  ctx.saveSettings();
  ctx.writeForm();
  showScanPlacement();
  ctx.schedulePlan(0);
}

// A typed move or turn: a number moves the scan (and the drawing with it);
// anything else is named under the fields and changes nothing.
function onField(id, key, name) {
  const el = $(id);
  const v = el.value.trim() === '' ? NaN : Number(el.value);
  const note = $('bed-note');
  if (!Number.isFinite(v)) {
    note.textContent = `${capital(name)}: type a number (the scan stays where it is).`;
    note.classList.add('bad-note');
    return;
  }
  note.textContent = '';
  note.classList.remove('bad-note');
  const s = settings;
  if (s.scanPlace[key] === v) return;
  moveScan(() => {
    s.scanPlace = { ...s.scanPlace, [key]: v };
  });
  ctx.saveSettings();
  ctx.writeForm();
  ctx.schedulePlan(250);
}

// `c`: the page's callbacks (see `ctx` above).
export function initPlacement(c) {
  ctx = c;
  $('place-bed-btn').addEventListener('click', placeOnBed);
  $('bed-undo').addEventListener('click', backToScannerFrame);
  for (const [id, key, name] of FIELDS) {
    $(id).addEventListener('input', () => onField(id, key, name));
  }
}

// Settings saved before scan placements existed, or edited by hand: a
// usable scan placement.
export function sanitizeScanPlace(sp) {
  const out = { ...SCAN_PLACE_DEFAULT };
  if (sp && typeof sp === 'object') {
    out.on = sp.on === true;
    for (const [, key] of FIELDS) if (finite(sp[key])) out[key] = sp[key];
  }
  return out;
}
