// The page's entry and its planning loop: the wasm module and the planning
// Worker, requests coalesced so only the newest settings are planned, the
// worker's messages routed to the modules that show them. Planning happens
// only in Rust (the worker's wasm Session, the same `job` code as the CLI).
// The page's other concerns have a module each: settings.js (settings,
// form, storage), inputs.js (files, uploads, demo parts, kept inputs),
// view.js (the 3-D view's controls), report.js (tables and plots),
// downloads.js, check.js (checking a G-code file), preview.js (the print
// preview), placement.js, fiducials.js, status.js; page.js holds what they
// share. Text from files and errors is set with textContent.
import { edgeOn, pageLimits, version } from '../pkg/pcpp.js';
import {
  checkAgainstSettled, checkFrameLeaving, onCheck, syncCheckButton,
} from './check.js';
import {
  bindDownloads, downloadFollows, dropPress, hideDownloads, offerDownloads, pressReplans,
} from './downloads.js';
import { initFiducials, showFiducials } from './fiducials.js';
import { loadWasm, startWorker } from './engine.js';
import {
  acceptScan, adoptPendingProfile, bindFiles, demoScanEntry, dropCentre, dropPendingProfile, dropPendingScan, dropPendingSvg,
  endRestoring, isScanName, keep, loadDemo, restoreInputs,
} from './inputs.js';
import {
  $, fmt, hooks, profile, settings, state,
} from './page.js';
import {
  bannerOffers, cancelCentre, capital, centreRequest, initPlacement, noteDefaultUnits, noteDefaultUp, onCarried, onCentred, planOutcome,
  requestCentre, showFitNote,
  showScanPlacement, toolPathOutside, unitsBannerShown, userPlacements, volumeCause,
} from './placement.js';
import {
  bindPreview, onPreview, previewCheckShown, previewClick, previewPlanDropped, previewPlanShown, syncPreviewButton,
} from './preview.js';
import {
  clearComparison, clearPlan, labelComparison, labelPlan, showComparison, showErrorPlot, showPlan, showScan, showScanWarnings,
} from './report.js';
import {
  bindForm, currentSvg, jobSettings, loadSettings, pathSourceBefore, saveSettings, writeForm,
} from './settings.js';
import {
  clearError, endProgress, laterProgress, setStatus, showError, showProgress,
} from './status.js';
import {
  bindView, drawPlanPaths, dropRefused, onPick, requestDraw, setPicking, showRefused, updateDragOffset, updateMarkers,
} from './view.js';

const decoder = new TextDecoder();

// ---------- planning ----------

// Something the plan depends on changed: the G-code on offer is stale from
// this moment, not from when the new plan starts.
function markChanged() {
  state.gen++;
  hideDownloads();
  if (pressReplans()) setStatus('re-planning for the new value: the download follows', true);
  else if (state.lastPlan) setStatus('settings changed: re-planning…', true);
}

function schedulePlan(delay) {
  markChanged();
  clearTimeout(state.debounce);
  state.debounce = setTimeout(requestPlan, delay);
}

// A live change (drag, slider): planned at once if the worker is free,
// else right after the plan in flight (the newest settings only).
function planNow() {
  markChanged();
  requestPlan();
}

function endInteraction() {
  if (!state.interacting) return;
  state.interacting = false;
  saveSettings();
  // Once more with the comparison of every planner (the surface path is
  // kept by the worker, so this only plans).
  requestPlan();
}

function requestPlan() {
  clearTimeout(state.debounce);
  if (state.busy) {
    state.queued = true;
    return;
  }
  runPlan();
}

// Whether `scan` is the user's and the drawing the demo's, not placed by
// the user since the scan's first plan: its refusal is then a notice
// about the demo drawing (`onPlanError`). After a reload the scan is read
// again, and where the user had placed the demo drawing is the settings'
// `demoMoved` (QA round 5 N6: it got the notice again).
function demoOnUserScan(scan) {
  if (!scan.blob || settings.pathSource !== 'demo') return false;
  const placed = scan.placementsAtFirstPlan
    ??= scan.restored && settings.demoMoved ? -1 : userPlacements();
  const untouched = userPlacements() === placed;
  if (settings.demoMoved === untouched) {
    settings.demoMoved = !untouched;
    saveSettings();
  }
  return untouched;
}

function runPlan() {
  const scan = state.pendingScan || state.scan;
  let job;
  let svg;
  try {
    job = jobSettings(scan);
    svg = currentSvg();
  } catch (e) {
    showError('Cannot plan', e.message);
    if (state.lastPlan) labelPlan(state.lastPlan, true);
    setStatus(state.lastPlan ? 'plan failed: showing the previous plan' : 'plan failed', true);
    return;
  }
  if (state.busy) state.stats.overlapped++;
  const id = ++state.planId;
  const compare = !state.interacting;
  const centre = centreRequest();
  // The status it replaces, for a request that ends with nothing new (a
  // scan file not read).
  const was = [$('plan-status').textContent, $('plan-status').classList.contains('stale')];
  const { dialect, file: profileFile } = profile();
  state.busy = {
    id, gen: state.gen, scan, svg, job, planner: job.plan.planner, compare, centre, t0: performance.now(), was,
    // What a G-code check made after this plan is made against.
    checkFrame: JSON.stringify([scan.key, job.scan, job.registration, job.plan.nozzle,
      job.plan.process.tolerance_mm, dialect, profileFile || null]),
    // The demo drawing on a user's scan, not placed by the user since the
    // scan's first plan (see `onPlanError`).
    demoOnUserScan: demoOnUserScan(scan),
    // The machine profile on trial, if this plan writes with it (see
    // `profileRefused`).
    trial: profileOnTrial(),
    // The error on screen says why a profile was not taken: kept.
    keepProfileError: state.keepProfileError,
  };
  state.keepProfileError = false;
  state.queued = false;
  checkFrameLeaving(state.busy.checkFrame);
  laterProgress('starting');
  if (!state.interacting) setStatus('planning…');
  // The worker keeps the last drawing it was sent: its bytes go only when
  // the drawing changes, as a copy whose buffer is transferred.
  const msgSvg = { key: svg.key, name: svg.name };
  const transfer = [];
  if (state.sentSvgKey !== svg.key) {
    msgSvg.bytes = svg.bytes.slice();
    transfer.push(msgSvg.bytes.buffer);
    state.sentSvgKey = svg.key;
  }
  // A user's file is hashed by a second worker beside its import.
  const hashBeside = !!scan.blob;
  if (hashBeside) hashScan(scan);
  state.worker.postMessage({
    type: 'plan',
    id,
    // A File is a handle: posting it copies no bytes (the worker reads it).
    scan: {
      key: scan.key, name: scan.name, blob: scan.blob, part: scan.part, external: scan.external,
      hashBeside, sha256: state.digests.get(scan.key) || null,
    },
    scanSettings: job.scan,
    registration: job.registration,
    svg: msgSvg,
    plan: job.plan,
    // A built-in name, or the user's profile as JSON text (named by its file).
    dialect,
    profileFile,
    acceptRisk: !!settings.acceptRisk,
    compare,
    // Centre the drawing on the scan before planning (a new scan or drawing).
    centre,
  }, transfer);
}

// The machine profile on trial (inputs.js openProfile) if it is the one
// plans are written with now.
function profileOnTrial() {
  const trial = state.pendingProfile;
  return trial && settings.dialect === 'custom' && settings.customProfile === trial.profile ? trial : null;
}

// What a plan is planned from, as one string: the scan, the drawing, the
// settings the core reads and the profile (null when a setting is not
// valid). A plan whose inputs equal the current ones is still good.
function currentInputs() {
  try {
    const { dialect, file } = profile();
    return JSON.stringify([state.scan.key, currentSvg().key, jobSettings(state.scan), dialect, file || null,
      !!settings.acceptRisk]);
  } catch {
    return null;
  }
}

// The core's projection warnings for a drawing path that leaves the scan
// (spec section 4: not printed there), naming the path.
const OFF_SCAN = /^path '(.*)'(?:: its .* lies off the scan; not printed| misses the scan entirely|: \d+ of its pieces miss the scan entirely)/;

// The status line of a plan offered for download. Paths of the drawing
// that leave the scan are said there too, where the user looks after a
// plan, not only in the list under Path statistics: a drawing placed
// partly off the part was "planned" while most of it was not printed.
function plannedStatus(plan) {
  const touching = plan.summary.motion.program.touching_moves;
  // A drawing the page shrank to fit the scan is printed at that size: a
  // trace or an antenna 6.7 times smaller is another part, said here, not
  // only in the Placement panel's note.
  const fit = settings.fit ? ` (the drawing scaled ×${Number(settings.placement.scale).toPrecision(3)} to fit `
    + 'the scan; Placement sets its scale)' : '';
  const head = `planned ${plan.svgName} on ${plan.scanName} with ${plan.planner}${fit}`;
  const off = new Set(plan.summary.warnings.map((w) => OFF_SCAN.exec(w)).filter(Boolean).map((m) => m[1])).size;
  const offText = off
    ? `${off} path(s) of the drawing leave the scan and are not printed there (listed under Path statistics)` : '';
  if (touching > 0) {
    return [`${head}: ${touching} move(s) touch the part; the G-code downloads only after a confirmation`
      + (off ? `; ${offText}` : ''), true];
  }
  // Written only because another refusal was overridden (the box that
  // accepts the risk): named here too, not as touching.
  const risks = plan.summary.motion.accepted_risks || [];
  if (risks.length > 0) {
    return [`${head}: written only because the risk was accepted (${risks.join('; ')}); `
      + 'the G-code downloads only after a confirmation' + (off ? `; ${offText}` : ''), true];
  }
  return off ? [`${head}: ${offText}`, true] : [head, false];
}

// After a request that failed without changing anything the plan on
// screen was planned from (a file that could not be read, the previous
// one kept): that plan is current again, offered as before.
function restorePlan() {
  const plan = state.lastPlan;
  if (!plan || !plan.inputs || state.queued || currentInputs() !== plan.inputs) return false;
  const c = state.lastComparison;
  if (c && c.gen === plan.gen) {
    c.gen = state.gen;
    labelComparison('current');
  }
  plan.gen = state.gen;
  dropRefused();
  offerDownloads(plan);
  labelPlan(plan, false);
  setStatus(...plannedStatus(plan));
  updateDragOffset();
  return true;
}

// The mesh a request plans on: the scan and how it is read and placed
// (as the worker keys its session).
const meshOf = (busy) => JSON.stringify([busy.scan.key, busy.job.scan, busy.job.registration]);

// The planners' comparison of the request `busy` (message `m`), as kept.
const comparisonOf = (m, busy, series) => ({
  rows: m.comparison, series, gen: busy.gen, mesh: meshOf(busy), svgName: busy.svg.name, scanName: busy.scan.name,
});

// A scan read for the request `busy` (another file, or the same in another
// frame: units, up axis, registration, placement on the bed): a plan on
// screen planned on another mesh goes, its figures and paths not shown as
// this scan's; the next plan fills them.
function dropPlan(busy) {
  if (state.refused && state.refused.mesh !== meshOf(busy)) dropRefused();
  // A comparison of another mesh goes too (QA round 4 F3: a refused plan's
  // comparison stayed under the next scan while its units were asked).
  const c = state.lastComparison;
  if (c && c.mesh !== meshOf(busy)) {
    state.lastComparison = null;
    clearComparison();
  }
  if (!state.lastPlan || state.lastPlan.mesh === meshOf(busy)) return;
  state.lastPlan = null;
  state.lastComparison = null;
  hideDownloads();
  clearPlan();
  previewPlanDropped();
  if (state.viewShows === 'plan') drawPlanPaths();
}

// The plan in flight ended, leaving the worker's scan in `frame` (see
// `checkAgainstSettled`).
function finish(frame) {
  state.busy = null;
  endProgress();
  checkAgainstSettled(frame);
  if (state.queued) runPlan();
}

// The JSON report of the plan `reportId` from the worker that made it
// (generation `worker`), written there now: a promise of its bytes.
function askReport(reportId, worker) {
  if (worker !== state.workerGen) {
    return Promise.reject(new Error('the planner was restarted since this plan: plan again to get its report'));
  }
  const id = ++state.reportId;
  return new Promise((resolve, reject) => {
    state.reportAsks.set(id, { resolve, reject });
    state.worker.postMessage({ type: 'report', id, reportId });
  });
}

function onReport(m) {
  const ask = state.reportAsks.get(m.id);
  if (!ask) return;
  state.reportAsks.delete(m.id);
  if (m.error) ask.reject(new Error(m.error));
  else ask.resolve(m.bytes);
}

// The SHA-256 of a scan file, found by a second worker while the planning
// worker imports it (as the CLI hashes on a second thread): the G-code's
// header names the scan by it, and the planning worker waits for it once
// the scan is indexed, before it shows it. Asked once per file; the answer
// goes to the planning worker (a restarted one gets it with its next plan).
function hashScan(scan) {
  if (state.digests.has(scan.key) || state.hashing.has(scan.key)) return;
  if (!state.hashWorker) {
    const w = startWorker(state.module);
    // It failed (or its wasm did not start): every file it was hashing is
    // answered with why, so no plan waits for it, and the next file gets a
    // new one.
    const failed = (why) => {
      for (const key of state.hashing.keys()) {
        state.worker.postMessage({ type: 'sha256', key, error: `the hashing worker failed (${why || 'no reason given'})` });
      }
      state.hashing.clear();
      if (state.hashWorker === w) state.hashWorker = null;
      w.terminate();
    };
    w.onmessage = (e) => {
      const m = e.data;
      if (m.type === 'error') {
        failed(m.message);
        return;
      }
      if (m.type !== 'hashed') return;
      state.hashing.delete(m.key);
      if (m.digest) state.digests.set(m.key, m.digest);
      state.worker.postMessage({ type: 'sha256', key: m.key, digest: m.digest, error: m.error });
    };
    w.onerror = (e) => failed(e.message);
    state.hashWorker = w;
  }
  state.hashing.set(scan.key, true);
  state.hashWorker.postMessage({ type: 'hash', key: scan.key, name: scan.name, blob: scan.blob });
}

// What the page keeps of a plan: the bytes to download (decoded to text
// only when asked; the report written by the worker only when asked), what
// the tables show and the per-point arrays.
function keptPlan(m, busy) {
  let gcode = null;
  let report = null;
  const worker = state.workerGen;
  return {
    gcodeBytes: m.gcode,
    // A promise of the report's bytes, asked once.
    reportBytes() {
      report ??= askReport(m.reportId, worker);
      report.catch(() => { report = null; });
      return report;
    },
    // A promise of the report's text.
    async report() { return decoder.decode(await this.reportBytes()); },
    get gcode() { gcode ??= decoder.decode(m.gcode); return gcode; },
    summary: m.summary,
    view: m.view,
    svgName: busy.svg.name,
    // The user's drawing planned on a demo part (no scan of theirs is
    // loaded: one that failed to read leaves the demo's): its download
    // says so (QA round 12 L2).
    onDemoPart: !busy.scan.blob && settings.pathSource !== 'demo',
    planner: busy.planner,
    // What the worker planned (it may have centred the drawing).
    placement: m.summary.settings.placement,
    gen: busy.gen,
    // The worker that made it (and holds its report).
    worker,
    compared: !!m.comparison,
    scanName: busy.scan.name,
    mesh: meshOf(busy),
    // Only a plan of the settings as they are now knows its inputs.
    inputs: busy.gen === state.gen ? currentInputs() : null,
  };
}

function onWorkerMessage(e) {
  const m = e.data;
  const busy = state.busy;
  if (m.type === 'ready') return;
  if (m.type === 'pick') {
    onPick(m);
    return;
  }
  if (m.type === 'check') {
    onCheck(m);
    return;
  }
  if (m.type === 'preview') {
    onPreview(m);
    return;
  }
  if (m.type === 'report') {
    onReport(m);
    return;
  }
  if (!busy || m.id !== busy.id) {
    if (m.type === 'error' && m.stage === 'init') showError('Could not start the planner', m.message);
    return;
  }
  switch (m.type) {
    case 'progress':
      if (m.stage === 'scan') {
        if (m.first) state.progressLog = [];
        state.progressLog.push(m.label);
        // Reading a scan takes a while: shown at once.
        $('cancel-btn').hidden = false;
        showProgress(m.step === 'done' ? 'plan' : m.step, m.label, m.fraction);
      } else {
        if ($('progress').hidden) laterProgress(m.label);
        else showProgress('plan', m.label);
      }
      break;
    case 'scan':
      if (state.pendingScan && state.pendingScan.key === m.key) {
        acceptScan(m.info);
      }
      if (busy && busy.job && busy.job.scan && !busy.job.scan.units) noteDefaultUnits(m.key, m.info.units);
      if (busy && busy.job && busy.job.scan && !busy.job.scan.up_axis) noteDefaultUp(m.key, m.info.up_axis);
      dropPlan(busy);
      state.memory = m.memory;
      showScan(m.info, m.positions, m.indices, m.seconds);
      break;
    case 'centred':
      onCentred(m, busy);
      break;
    case 'carried':
      onCarried(m, busy);
      break;
    case 'result': {
      if (settings.pathSource === 'file' && state.pendingSvg && busy.svg === state.pendingSvg) adoptPendingSvg();
      // The profile on trial wrote this plan's G-code: taken.
      if (busy.trial && busy.trial === state.pendingProfile) adoptPendingProfile();
      state.lastPlan = keptPlan(m, busy);
      const latency = performance.now() - busy.t0;
      const st = state.stats;
      st.plans++;
      st.planMs.push(m.planMs);
      st.latencyMs.push(latency);
      if (st.planMs.length > 1000) { st.planMs.shift(); st.latencyMs.shift(); }
      $('plan-time').textContent = `plan ${Math.round(m.planMs)} ms, on screen ${Math.round(latency)} ms after the change`;
      // (Not the error saying why a profile was not taken, by the plan
      // with the profile kept.)
      clearError(busy.keepProfileError ? [null, 'file', 'check'] : undefined);
      planOutcome(null, busy.gen);
      state.lastRefusal = null;
      // Planned: the worker's scan is registered by the settings now (a
      // failed registration leaves the one before, which these are again).
      if (state.regFailed) {
        state.regFailed = false;
        showScanPlacement();
        if (state.info) showFiducials();
      }
      if (m.comparison) state.lastComparison = comparisonOf(m, busy, m.series);
      dropRefused(false);
      showPlan(state.lastPlan);
      if (busy.gen === state.gen) {
        offerDownloads(state.lastPlan);
        setStatus(...plannedStatus(state.lastPlan));
      } else {
        // Shown while the user goes on changing things; not offered.
        setStatus(downloadFollows() ? 're-planning for the new value: the download follows'
          : 'settings changed: re-planning…', true);
      }
      if (m.comparison) {
        showComparison(m.comparison, busy.planner, m.summary.settings.process.tolerance_mm, m.comparisonNotes);
        labelComparison('current');
      } else {
        $('compare-table').classList.add('stale');
        $('compare-notes').classList.add('stale');
      }
      // A settled plan (compared, current) is what the preview plays.
      if (m.comparison && busy.gen === state.gen) previewPlanShown();
      break;
    }
    case 'done':
      finish(busy.checkFrame);
      break;
    case 'error':
      onPlanError(m, busy);
      // A scan file not read leaves the worker's scan as it was; a
      // restarted worker holds none.
      finish(busy.notRead ? state.workerFrame : m.kind === 'crash' ? null : busy.checkFrame);
      break;
    default:
      break;
  }
}

// `text` ended as a sentence, before the page's own line after it.
// (A closing parenthesis ends no sentence: "... at (23.0, 50.3, 30.2)".)
const ended = (text) => (/[.!?]$/.test(text.trim()) ? text : `${text.trimEnd()}.`);

// The refusals that accepting the risk lifts, by the core's error kind,
// with the error panel's title for each.
const RISKS = {
  'whole-object': 'The scan is a point cloud of a whole object: no G-code',
  'far-above': 'The nozzle would dispense far above the surface: no G-code',
  'below-bed': 'The scan is moved below the bed: no G-code',
  'too-large': 'The scan is larger than the printer: no G-code',
  'mostly-off': 'Most of the drawing lies beside the scan: no G-code',
};

// The drawing read for this plan becomes the user's drawing, kept in the
// browser with its placement (saveSettings kept the previous drawing's
// while this one was pending): once planned, or refused (onPlanError).
function adoptPendingSvg() {
  state.svgFile = state.pendingSvg;
  state.pendingSvg = null;
  keep('svg', { name: state.svgFile.name, bytes: state.svgFile.bytes });
  saveSettings();
}

// Whether the plan `busy`, written with the machine profile on trial,
// failed (error `m`) because of that profile: the core names the
// profile's file and field (its end block homes, or moves into the part:
// the error's `profile`, src/wasm.rs core_err), or nothing but the
// profile changed since a plan that wrote its G-code (its travel height or
// build volume does not fit this job, its moves touch the part...). A
// failure of something else (the drawing misses the scan) is not the
// profile's; nor is a crash.
function profileRefused(m, busy) {
  const trial = busy.trial;
  if (!trial || trial !== state.pendingProfile || m.kind === 'crash') return false;
  if (m.profile && m.profile.file === trial.profile.file) return true;
  return busy.gen === state.gen && !state.queued && currentInputs() === trial.inputs && trial.before.planned;
}

// The machine profile on trial cannot write this job's G-code (error `m`
// of the plan `busy`): it is not taken, as a profile that fails validation
// is not (inputs.js openProfile). The profile used before comes back, and
// with it its plan and G-code, or its refusal; otherwise the plan with it
// is made again (the error stays on screen).
function profileNotTaken(m, busy) {
  const file = busy.trial.profile.file;
  const label = dropPendingProfile();
  const r = state.lastRefusal;
  const kept = r && r.inputs && r.inputs === currentInputs() ? r : null;
  let message = `${ended(m.message)}\nStill using ${label}.`;
  if (kept) message += `\nIts plan ${kept.refused ? 'stays refused' : 'still fails'}: ${kept.title}.`;
  showError(`Could not use the machine profile ${file}`, message, file, 'profile');
  if (busy.gen === state.gen && restorePlan()) return;
  if (state.lastPlan) labelPlan(state.lastPlan, true);
  hideDownloads();
  if (kept && busy.gen === state.gen && !state.queued) {
    setStatus(...kept.status);
    return;
  }
  state.keepProfileError = true;
  schedulePlan(0);
}

function onPlanError(m, busy) {
  dropPress();
  if (profileRefused(m, busy)) {
    profileNotTaken(m, busy);
    return;
  }
  // Failed for something else than the profile on trial: it is the user's
  // profile (a failure of settings since changed says nothing yet).
  if (busy.trial && busy.trial === state.pendingProfile && busy.gen === state.gen && m.kind !== 'crash') {
    adoptPendingProfile();
  }
  // The worker holds another drawing than the page thinks: the next plan
  // sends it again.
  if (/did not reach the planner/.test(m.message)) state.sentSvgKey = null;
  // A drawing read whose plan failed (nothing printable, refused) is the
  // user's drawing all the same: kept as a planned one is, with where it
  // lies, so a reload reopens it (QA round 7 F7: the demo drawing or an
  // older one came back, its G-code offered) and a file opened after it
  // that cannot be read goes back to it (QA: it went back to the demo
  // drawing). A drawing too long for the page is not kept.
  if (state.pendingSvg && busy.svg === state.pendingSvg && m.kind !== 'svg' && m.kind !== 'crash'
    && m.kind !== 'limit' && m.stage !== 'scan' && settings.pathSource === 'file') {
    adoptPendingSvg();
  }
  let title = 'Planning failed';
  let message = m.message;
  let file; // the file the title names
  let topic = null; // what the error is about (status.js)
  let notRead = false; // a scan file not read: the previous scan's state stands
  // A drawing not read: the page went back to the one before, whose
  // plan's state stands as well (QA round 16 F2: the status of a units
  // refusal became "plan failed" and a refusal's comparison was emptied).
  let svgNotRead = false;
  // The refusal on screen before the file came, if the inputs are again
  // the ones it was planned from.
  const r = state.lastRefusal;
  const keptRefusal = () => (r && r.inputs && r.inputs === currentInputs() ? r : null);
  let kept = keptRefusal();
  if (m.kind === 'crash') {
    // The wasm instance trapped (most likely out of memory): a new worker.
    restartWorker();
    title = m.stage === 'scan' ? `The planner ran out of memory or failed reading ${busy.scan.name}` : 'The planner stopped';
    message += '\nThe planner was restarted';
    if (state.pendingScan && busy.scan === state.pendingScan) {
      if (state.pendingScan.restored) {
        endRestoring();
        keep('scan', null);
      }
      state.pendingScan = null;
      dropCentre();
      message += `; still using the previous scan, ${state.scan.name}`;
    }
    message += '.';
    $('scan-name').textContent = state.scan.name;
  } else if (m.stage === 'scan' && (m.kind === 'mesh' || m.kind === 'limit' || m.kind === 'other')
    && state.pendingScan && busy.scan === state.pendingScan) {
    // The file could not be read: keep working with the previous scan.
    notRead = true;
    busy.notRead = true;
    file = state.pendingScan.name;
    title = `Could not read the scan ${file}`;
    if (state.pendingScan.restored) {
      endRestoring();
      keep('scan', null);
    }
    state.pendingScan = null;
    dropCentre();
    $('scan-name').textContent = state.scan.name;
    message += `\nStill using the previous scan, ${state.scan.name}.`;
    if (kept) message += `\nIts plan ${kept.refused ? 'stays refused' : 'still fails'}: ${kept.title}.`;
    // A file of no kind the page reads (a dropped picture): the next file
    // accepted supersedes it.
    if (m.kind === 'mesh' && !isScanName(file)) topic = 'file';
  } else if (m.stage === 'scan') {
    // (The registration's messages start 'registration needs ...'.)
    title = m.kind === 'mesh' ? 'Could not read the scan' : `Could not register ${busy.scan.name}`;
    if (m.kind !== 'mesh') {
      state.regFailed = true;
      if (state.info) showFiducials();
    }
    if (state.pendingScan && busy.scan === state.pendingScan) {
      // Readable but not registered: it stays loaded until the fiducials fit.
      acceptScan();
      $('scan-name').textContent = state.scan.name;
      dropPlan(busy);
    }
    showScanPlacement();
  } else if (m.kind === 'svg' && state.pendingSvg && busy.svg === state.pendingSvg) {
    file = state.pendingSvg.name;
    title = `Could not read the SVG ${file}`;
    // Back to the path planned before it (an antenna, the demo, or the
    // previous file), where it was.
    const was = pathSourceBefore(state.pendingSvg);
    state.pendingSvg = null;
    cancelCentre();
    settings.pathSource = was;
    saveSettings();
    writeForm();
    message += settings.pathSource === 'file'
      ? `\nStill using the previous SVG, ${state.svgFile.name}.`
      : `\nStill using ${$('path-source').selectedOptions[0].textContent}.`;
    svgNotRead = true;
    // (The inputs are the drawing before's again.)
    kept = keptRefusal();
    if (kept) message += `\nIts plan ${kept.refused ? 'stays refused' : 'still fails'}: ${kept.title}.`;
  } else if (m.kind === 'limit') {
    title = 'The path is too long for the page';
  } else if (m.kind === 'touching') {
    title = `The nozzle would touch the part with ${busy.planner}: no G-code`;
    message = ended(message) + '\nThe settings and the drawing stay as they were; the view shows the refused tool path, '
      + `coloured by its defects${state.lastPlan ? ', and the figures are the previous plan\'s' : ''}.`;
  } else if (RISKS[m.kind]) {
    // Refused unless the risk is accepted: the box that accepts it.
    title = RISKS[m.kind];
    // (Not where accepting it would write no G-code either: QA round 11 L1.)
    if (!m.blocked) message = ended(message) + '\nTo write it anyway, tick "write G-code even where it is refused (at my risk)" (Nozzle and process).';
  } else if (m.kind === 'volume') {
    // (QA round 5 N3: "Planning failed" for a scan larger than the volume;
    // QA round 8 F5: the tool path blamed for the scan's place or size.)
    title = {
      scan: 'The scan lies outside the printer\'s build volume: no G-code',
      travel: 'The travel height over the scan would leave the printer\'s build volume: no G-code',
      'tool-path': 'The tool path would leave the printer\'s build volume: no G-code',
    }[volumeCause(m.message)];
  } else if (m.kind === 'units' && m.stray) {
    // (QA round 14: a vertex at z = 1e300 in a 1.5 mm model was offered
    // "It is in mm", which planned into "points 0 and 1 coincide".)
    title = 'The scan has stray vertices far from the rest: no G-code';
    message = ended(message) + '\nMend the file (remove the stray vertices and their triangles), then open it again.';
  } else if (m.kind === 'units') {
    // (QA round 16 F2: a scan read in metres, 3.3 m tall, was "too small".)
    title = `The scan is too ${/larger than any printer/.test(message) ? 'large' : 'small'} for its units: no G-code`;
    message = ended(message) + '\nChoose its units in the Scan panel (Units).';
  } else if (m.kind === 'registration') {
    // Refused at planning: fiducials far off their printer points, or the
    // scan turned upside down (printer points in the other order).
    title = 'The registration puts the scan where the part is not: no G-code';
    message = ended(message) + '\nCheck the printer points (their order and values)'
      + (m.blocked ? '.' : '; to write it anyway, tick "write G-code even where it is refused (at my risk)" (Nozzle and process).');
  }
  // A plan refused for its motion still compared the planners on the
  // settings that failed: the table shows why.
  if (m.comparison) {
    state.lastComparison = { ...comparisonOf(m, busy, null), failed: true };
    showComparison(m.comparison, busy.planner, busy.job.plan.process.tolerance_mm, m.comparisonNotes);
    labelComparison('failed');
  }
  // A scan outside the build volume, with the banner on screen offering to
  // place it: the banner says it, with its button; a red panel repeating
  // it would only bury it.
  if (m.stage === 'plan') planOutcome(message, busy.gen);
  const unitsOffered = m.kind === 'units' && unitsBannerShown();
  const offered = m.stage === 'plan' && (bannerOffers(message) || unitsOffered);
  // A scan seen edge-on from above (a plate lying on its side in the
  // file) is the scan's to mend, whatever the refusal: said under it, and
  // never the demo drawing's notice below (QA round 5 N4).
  const info = state.info;
  // (Not one made tall by stray vertices: they are the cause; nor for a
  // drawing that could not be read, the drawing's to mend: QA round 14
  // had both.)
  const strayScan = m.stray || !!(info && info.units_doubt && info.units_doubt.stray);
  const sideways = m.stage === 'plan' && m.kind !== 'svg' && !strayScan && !!info && edgeOn([...info.bbox_mm[0], ...info.bbox_mm[1]]);
  if (sideways && !/edge-on/.test(message)) {
    const [lo, hi] = info.bbox_mm;
    message = `${ended(message)}\nThe scan is seen edge-on from above (${fmt(hi[0] - lo[0], 1)} × ${fmt(hi[1] - lo[1], 1)} mm, `
      + `${fmt(hi[2] - lo[2], 1)} mm tall): if it lies on its side in the file, choose its up axis (Up axis, Scan panel).`;
  }
  // The demo drawing on a user's scan, not yet placed by the user (the
  // page plans whatever drawing it holds on a new scan, and again as the
  // scan is placed or re-read), refused for something of the drawing's
  // (its motion, where it lies, how high it dispenses, a gap): the refusal
  // is of a drawing the user never chose, so it is said as that, with
  // what to do next, not as a failure and not with the box that accepts
  // the risk (QA round 2 F6: a red panel was the first thing seen of one's
  // own scan; QA round 4 F2, F5). The scan's own refusals (its units, the
  // build volume, a whole object, the registration) stay errors (QA round
  // 4 F1), and a banner offering the fix says it as it is.
  const demoTried = busy.demoOnUserScan && m.stage === 'plan' && busy.gen === state.gen && !offered && !sideways
    && ['touching', 'far-above', 'mostly-off', 'other'].includes(m.kind);
  if (demoTried) {
    const why = m.kind === 'other' ? '' : `${ended(title.replace(/: no G-code$/, ''))}\n`;
    // (Without the core's offer to accept the risk, nor the other risks
    // that would take: QA round 5 N2.)
    const reason = m.message.replace(/;? accepting the risk would also accept: [^\n]*/, '')
      .replace(/,? or accept the risk[^.;\n]*/g, '');
    message = `${why}${capital(ended(reason))}\nThe demo drawing only shows the page at work: `
      + 'open your drawing (SVG) to plan it on this scan.';
    title = `${busy.scan.name} is open; the demo drawing does not print on it`;
  }
  // What the plan would have warned of (the drawing's skipped text, the
  // parts off the scan...), said with its refusal: the figures on screen
  // are the previous plan's (QA round 15 F2). Not the demo drawing's.
  // (Shown only: the tests of the message below read the core's words.)
  const shown = m.warnings && m.warnings.length && !demoTried
    ? `${ended(message)}\nThis plan also warned:${m.warnings.map((w) => `\n• ${w}`).join('')}` : message;
  if (offered) clearError();
  else showError(title, shown, file, topic, demoTried);
  if (busy.gen === state.gen && restorePlan()) return;
  if (state.lastPlan) labelPlan(state.lastPlan, true);
  // Without a comparison of its own, the one on screen is the previous
  // plan's; one of an earlier failed plan says nothing of this one.
  // (A scan file not read changes nothing the comparison was made from.)
  if (notRead || svgNotRead) {
    if (!kept && state.lastComparison && state.lastComparison.failed) labelComparison('previous');
  } else if (!m.comparison && state.lastComparison && state.lastComparison.failed) {
    state.lastComparison = null;
    clearComparison();
  } else if (!m.comparison) labelComparison('previous');
  showScanWarnings();
  // Nothing stale on offer. A plan refused for what it planned (its
  // motion, where it lies, how high it dispenses, the volume) is shown
  // where its drawing lay, its points coloured by their defects, so what
  // the refusal names can be seen and the drawing moved off it (QA round
  // 7 F3: the view showed the bare scan, or the previous plan elsewhere);
  // otherwise the previous plan stays on screen, where it was planned.
  hideDownloads();
  // (Not a refusal of the scan's: its units, size, place, travel height
  // or registration, which the drawing does not change.) Shown whatever
  // the request's generation, as a plan is: while the drawing is dragged,
  // most answers are of a placement already left.
  const ofScan = ['units', 'below-bed', 'too-large', 'whole-object', 'registration'].includes(m.kind)
    || (m.kind === 'volume' && volumeCause(m.message) !== 'tool-path');
  const refusedShown = m.stage === 'plan' && !!m.view && !ofScan;
  if (refusedShown) {
    showRefused(m.view, m.placement, meshOf(busy), busy.gen === state.gen ? currentInputs() : null);
  } else {
    // An earlier refusal's paths are not this failure's (QA round 8 F1),
    // unless nothing they were planned from changed (a file that could not
    // be read, the one before kept).
    const r = state.refused;
    if (r && (!r.inputs || r.inputs !== currentInputs())) dropRefused();
    if (!state.refused && state.viewer) {
      state.viewer.setPathOffset(0, 0, 0);
      requestDraw();
    }
  }
  // The previous plan on screen is said to be that, whichever the failure,
  // and a refused tool path too (this one's, or one kept).
  const refusedOnScreen = !!state.refused;
  const showing = refusedOnScreen ? '; the refused tool path is shown where it lies'
    : state.lastPlan ? '; showing the previous plan' : '';
  if (demoTried) {
    setStatus(`${busy.scan.name} open: the demo drawing does not print on it; open your drawing (SVG)`, false);
  } else if (unitsOffered) {
    setStatus(`no G-code: ${m.stray ? 'the scan has stray vertices' : "choose the scan's units"} (see above)${showing}`, true);
  } else if (offered) {
    setStatus(`no G-code: the ${toolPathOutside(message) ? 'tool path' : 'scan'} lies outside the build volume (see above)${
      showing}`, true);
  } else if (notRead || svgNotRead) {
    // The scan (or drawing) still used, and its status, stand (it said "plan failed"
    // where nothing had been planned), a refusal's too (its status was
    // replaced by "re-planning" when the file was picked).
    setStatus(...(kept ? kept.status : busy.was));
  } else if (refusedOnScreen) {
    setStatus('no G-code: the refused tool path is shown where the drawing lies (see above)', true);
  } else if (RISKS[m.kind]) {
    // A refusal, not a failure (QA round 17 F11: a whole object's cloud
    // read "plan failed", as if something broke).
    const why = RISKS[m.kind].replace(/: no G-code$/, '');
    setStatus(`no G-code: ${why.charAt(0).toLowerCase()}${why.slice(1)} (see above)${showing}`, true);
  } else setStatus(state.lastPlan ? 'plan failed: showing the previous plan, no download' : 'plan failed', true);
  // (Not a drawing that could not be read: the page went back to the
  // one before, whose plan this is not; nor a crash. Neither clears one
  // kept: the inputs say whether it is still theirs.)
  if (m.stage === 'plan' && busy.gen === state.gen && m.kind !== 'svg' && m.kind !== 'crash') {
    state.lastRefusal = {
      inputs: currentInputs(), title, refused: REFUSALS.has(m.kind),
      status: [$('plan-status').textContent, $('plan-status').classList.contains('stale')],
    };
  }
}

// The kinds of plan failure that are refusals of G-code (the others fail).
const REFUSALS = new Set(['touching', 'volume', 'units', 'registration', ...Object.keys(RISKS)]);

function cancelPlan() {
  const busy = state.busy;
  if (!busy) return;
  // The only way to stop wasm mid-computation: end the worker.
  restartWorker();
  state.busy = null;
  state.queued = false;
  clearTimeout(state.debounce);
  endProgress();
  dropPress();
  // What the cancelled request was bringing in goes with it: a scan being
  // read (the next request would read it again and replace the scan kept)
  // and a drawing not yet planned (back to the one before, where it was).
  const dropped = [];
  if (state.pendingScan && busy.scan === state.pendingScan) {
    dropped.push(`reading ${state.pendingScan.name}`);
    stopHashing(state.pendingScan.key);
    dropPendingScan();
  }
  if (state.pendingSvg && busy.svg === state.pendingSvg) {
    dropped.push(state.pendingSvg.name);
    dropPendingSvg();
  }
  // A machine profile on trial, too: the one before it comes back.
  if (busy.trial && busy.trial === state.pendingProfile) {
    dropped.push(busy.trial.profile.file);
    dropPendingProfile();
  }
  // The plan on screen is that of the inputs as they are again: offered
  // (its G-code; its report went with the worker).
  if (dropped.length && restorePlan()) {
    const [text, stale] = plannedStatus(state.lastPlan);
    setStatus(`cancelled ${dropped.join(' and ')}: ${text}`, stale);
    return;
  }
  hideDownloads();
  setStatus('cancelled', true);
}

// The hashing worker is finding the SHA-256 of the scan `key`, no longer
// wanted: it ends (a 50 MB file is read to its end otherwise); a new one
// starts for the next file.
function stopHashing(key) {
  if (!state.hashing.has(key) || !state.hashWorker) return;
  state.hashWorker.terminate();
  state.hashWorker = null;
  // The planning worker that waited for these was just restarted.
  state.hashing.clear();
}

function restartWorker() {
  state.worker.terminate();
  state.worker = makeWorker();
  // Its reports went with it.
  for (const ask of state.reportAsks.values()) ask.reject(new Error('the planner was restarted: plan again to get the report'));
  state.reportAsks.clear();
  if (state.checking) {
    // The new worker never got the check in flight.
    $('check-verdict').textContent = `${state.checking.name} was not checked: the planner was restarted; check it again`;
    $('check-verdict').className = 'verdict bad';
    state.checking = null;
  }
}

function makeWorker() {
  const w = startWorker(state.module);
  // A new worker holds no scan, no drawing and no report.
  state.sentSvgKey = null;
  state.workerGen++;
  w.onmessage = onWorkerMessage;
  w.onerror = (e) => {
    showError('The planner stopped', e.message || 'the worker failed to load');
    state.busy = null;
    endProgress();
  };
  return w;
}

// ---------- start ----------

async function start() {
  try {
    state.module = await loadWasm();
  } catch (e) {
    showError('Could not load the planner (WebAssembly)', e.message);
    return;
  }
  $('version').textContent = `v${version()}`;
  $('scan-limit').textContent = `${pageLimits().scan_bytes / (1 << 20)} MiB`;
  Object.assign(settings, loadSettings());
  Object.assign(hooks, {
    schedulePlan, planNow, requestPlan, endInteraction, loadDemo, showErrorPlot, currentInputs,
    viewShowsChanged: () => { syncCheckButton(); syncPreviewButton(); },
    viewClick: previewClick,
    checkShown: previewCheckShown,
  });
  // Calls into modules that import placement.js and fiducials.js.
  const page = {
    saveSettings, writeForm, schedulePlan, updateMarkers,
  };
  initPlacement(page);
  initFiducials(page);
  bindForm();
  writeForm();
  bindFiles();
  bindView();
  $('plan-btn').addEventListener('click', requestPlan);
  $('cancel-btn').addEventListener('click', cancelPlan);
  $('demo-btn').addEventListener('click', () => loadDemo($('demo-part').value));
  bindDownloads();
  bindPreview();
  $('center-btn').addEventListener('click', () => {
    // The core centres it on the scan's footprint, scaled down to fit.
    requestCentre();
    schedulePlan(0);
  });
  $('error-close').addEventListener('click', () => clearError());
  $('pick-btn').addEventListener('click', () => setPicking(!state.picking));
  $('clear-scan-btn').addEventListener('click', () => {
    settings.fidScanText = '';
    $('pick-status').textContent = '';
    saveSettings();
    writeForm();
    updateMarkers();
    if (settings.fidSource === 'points') schedulePlan(0);
  });
  window.addEventListener('keydown', (e) => { if (e.key === 'Escape' && state.picking) setPicking(false); });
  state.worker = makeWorker();
  state.scan = demoScanEntry(settings.demoPart);
  $('scan-name').textContent = state.scan.name;
  await restoreInputs();
  writeForm();
  // The note of a fit kept from the last visit.
  showFitNote();
  // For tests and the curious: read-only access to the page's state.
  window.pcpp = { state, get settings() { return settings; } };
  requestPlan();
}

start();
