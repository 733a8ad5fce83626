// The print preview: a G-code program (the plan's, or a file being
// checked) played over the scan. A time slider and play/pause move the
// nozzle, drawn to scale, along the program's moves at its feed rates
// (times a speed-up); the path is coloured by each move's clearance (the
// motion check's) or by the predicted defect it prints; beside it the
// current G-code line, position, clearance and elapsed/total time; a click
// on the path in the 3-D view jumps there. The worker times the moves and
// finds their clearances (Session.previewGcode); the timeline on this
// thread (PreviewTimeline) places the nozzle; the view moves only its
// transform per frame.
import { PreviewTimeline, Viewer } from '../pkg/pcpp.js';
import {
  $, fmt, num, profile, settings, state, swatch,
} from './page.js';
import { drawPlanPaths, requestDraw, setViewShows } from './view.js';

// Speed-ups offered (real print speed first).
const SPEEDS = [1, 2, 5, 10, 30, 100];
// A click this many pixels from the path still picks it.
const CLICK_PX = 12;
// Colour codes of the view (src/render.rs preview_rgb8): clearance 0-2,
// defects 10 + their code, 255 prints nothing.
const NO_DEFECT = 255;
const CLASS_NAMES = ['clear', 'near', 'closer than tol'];

const pv = {
  on: false, // the user wants the preview in the view
  source: 'plan', // 'plan' or 'check' (the last checked file)
  id: 0, // the request in flight (stale answers are dropped)
  pending: null, // what that request previews: {id, source, name, ...}
  data: null, // the previewed program: see onPreview
  t: 0, // the moment shown, s
  index: 0, // the move shown at that moment
  playing: false,
  raf: 0,
  last: 0, // the frame time play last advanced from
};

// For tests and the curious: window.pcpp.state.preview.
state.preview = pv;

function setStatus(text, bad) {
  const el = $('preview-status');
  el.textContent = text;
  el.classList.toggle('bad', !!bad);
}

// mm:ss.s, or s.s under a minute.
function fmtTime(s) {
  if (!Number.isFinite(s)) return '—';
  if (s < 60) return `${s.toFixed(1)} s`;
  const m = Math.floor(s / 60);
  return `${m}:${(s - 60 * m).toFixed(1).padStart(4, '0')}`;
}

export function syncPreviewButton() {
  const b = $('preview-btn');
  b.setAttribute('aria-pressed', pv.on ? 'true' : 'false');
  b.textContent = pv.on ? 'Back to the plan in the 3-D view' : 'Preview the print';
}

function syncControls() {
  const d = pv.data;
  for (const id of ['preview-play', 'preview-time']) $(id).disabled = !d;
  $('preview-play').textContent = pv.playing ? 'Pause' : 'Play';
  const colour = $('preview-colour');
  const defectOpt = colour.querySelector('option[value="defect"]');
  defectOpt.disabled = !(d && d.defectCodes);
  if (defectOpt.disabled && colour.value === 'defect') colour.value = 'clearance';
  $('preview-source').querySelector('option[value="check"]').disabled = !state.checked;
}

// Asks the worker for the program of the chosen source.
function request() {
  const id = ++pv.id;
  const { dialect, file: profileFile } = profile();
  const msg = { type: 'preview', id, dialect, profileFile };
  const transfer = [];
  let job;
  if (pv.source === 'check') {
    const c = state.checked;
    if (!c) {
      setStatus('No G-code file checked yet: check one below, then preview it.', true);
      return;
    }
    job = { source: 'check', name: c.name, file: c.file, od: c.nozzle.outer_diameter_mm };
    Object.assign(msg, { name: c.name, file: c.file, nozzle: c.nozzle, tol: c.tol, speed: num(settings.process.speed) });
  } else {
    const plan = state.lastPlan;
    if (!plan) {
      setStatus('No plan yet.', true);
      return;
    }
    const s = plan.summary.settings;
    const name = `${plan.svgName.replace(/\.[^.]*$/, '') || 'path'}-${plan.planner}.gcode`;
    job = { source: 'plan', name, plan, od: s.nozzle.outer_diameter_mm };
    const bytes = plan.gcodeBytes.slice();
    transfer.push(bytes.buffer);
    Object.assign(msg, {
      name, bytes, nozzle: s.nozzle, tol: s.process.tolerance_mm, speed: s.process.speed_mm_s,
    });
  }
  pv.pending = { id, ...job };
  setStatus(`timing the moves of ${job.name} and finding their clearances…`);
  state.worker.postMessage(msg, transfer);
}

const decoder = new TextDecoder();

// The worker's answer: the moves, their times and clearances, and the
// program's bytes it read (for the line readout).
export function onPreview(m) {
  const job = pv.pending;
  if (!job || m.id !== pv.id) return;
  pv.pending = null;
  if (m.error) {
    dropData();
    setStatus(`Could not preview ${m.name}: ${m.error}`, true);
    if (state.viewShows === 'preview') drawPlanPaths();
    syncControls();
    return;
  }
  const r = m.result;
  const text = job.source === 'plan' ? job.plan.gcode : decoder.decode(m.bytes);
  const timeline = new PreviewTimeline(r.moves, r.starts, r.durations, r.lines, r.rapid);
  let defectCodes = null;
  if (job.source === 'plan') {
    // Each print move takes the defect of the planned point beside it.
    const v = job.plan.view;
    const d = timeline.moveDefects(v.tool, v.defects, 2 * job.od);
    defectCodes = d.map((c) => (c === NO_DEFECT ? NO_DEFECT : 10 + c));
  }
  const keepTime = pv.data && pv.data.source === job.source && pv.data.name === job.name;
  dropData();
  pv.data = {
    ...job,
    r,
    timeline,
    total: timeline.totalS,
    lines: text.split(/\r\n|\r|\n/),
    moves32: Float32Array.from(r.moves),
    defectCodes,
  };
  const slider = $('preview-time');
  slider.max = String(pv.data.total);
  if (!keepTime) pv.t = 0;
  const n = r.starts.length;
  const touching = r.classes.filter((c) => c === 2).length;
  const near = r.classes.filter((c) => c === 1).length;
  setStatus(`${job.source === 'plan' ? 'the plan\'s G-code' : 'checked file'} ${job.name}: ${n} moves, `
    + `${fmtTime(pv.data.total)} at its feeds; ${touching} closer than tol (${fmt(r.tol_mm)} mm), `
    + `${near} near (within ${fmt(r.near_mm)} mm more)`, touching > 0);
  syncControls();
  if (pv.on) show();
  setTime(pv.t);
}

function dropData() {
  stop();
  if (pv.data) pv.data.timeline.free();
  pv.data = null;
}

// The previewed program's path, coloured as chosen, in the view.
function show() {
  const d = pv.data;
  if (!d || !state.viewer) return;
  const byDefect = $('preview-colour').value === 'defect' && d.defectCodes;
  try {
    state.viewer.setPreviewPath(d.moves32, byDefect ? d.defectCodes : d.r.classes);
  } catch (e) {
    setStatus(`Could not draw the preview: ${e.message}`, true);
    return;
  }
  state.viewer.setPathOffset(0, 0, 0);
  setViewShows('preview');
  setTime(pv.t);
}

// Shows the moment `t` (s): the nozzle, the slider and the readouts.
function setTime(t) {
  const d = pv.data;
  if (!d) {
    for (const id of ['preview-line-no', 'preview-line-text', 'preview-pos', 'preview-clear', 'preview-elapsed']) {
      $(id).textContent = '';
    }
    return;
  }
  pv.t = Math.min(Math.max(Number.isFinite(t) ? t : 0, 0), d.total);
  const c = d.timeline.at(pv.t);
  $('preview-time').value = String(pv.t);
  $('preview-elapsed').textContent = `${fmtTime(pv.t)} of ${fmtTime(d.total)}`;
  if (!c) return;
  const [x, y, z] = c.position;
  $('preview-line-no').textContent = `line ${c.line}`;
  $('preview-line-text').textContent = d.lines[c.line - 1] ?? '';
  $('preview-pos').textContent = `(${fmt(x)}, ${fmt(y)}, ${fmt(z)}) mm`;
  const gap = d.r.clearance[c.index];
  const cls = d.r.classes[c.index];
  const clear = $('preview-clear');
  clear.textContent = `${Number.isNaN(gap) ? `> ${fmt(d.r.cap_mm)}` : fmt(gap)} mm along this move `
    + `(${CLASS_NAMES[cls]}; tol ${fmt(d.r.tol_mm)} mm)`;
  clear.className = cls === 2 ? 'bad' : cls === 1 ? 'near' : '';
  pv.index = c.index;
  if (state.viewer && state.viewShows === 'preview') {
    state.viewer.setNozzle(x, y, z, d.od);
    requestDraw();
  }
}

function speed() {
  return Number($('preview-speed').value) || 1;
}

function frame(now) {
  pv.raf = 0;
  if (!pv.playing || !pv.data) return;
  const dt = Math.max(0, now - pv.last) / 1000;
  pv.last = now;
  setTime(pv.t + dt * speed());
  if (pv.t >= pv.data.total) {
    stop();
    return;
  }
  pv.raf = requestAnimationFrame(frame);
}

function play() {
  if (!pv.data) return;
  if (!pv.on) setOn(true);
  if (pv.t >= pv.data.total) setTime(0);
  pv.playing = true;
  pv.last = performance.now();
  if (!pv.raf) pv.raf = requestAnimationFrame(frame);
  syncControls();
}

function stop() {
  pv.playing = false;
  if (pv.raf) cancelAnimationFrame(pv.raf);
  pv.raf = 0;
  if (pv.data) syncControls();
}

function setOn(on) {
  pv.on = on;
  syncPreviewButton();
  if (on) {
    const fresh = pv.data && pv.data.source === pv.source
      && (pv.source !== 'plan' || pv.data.plan === state.lastPlan);
    if (fresh) show();
    else request();
  } else {
    stop();
    if (state.viewShows === 'preview') drawPlanPaths();
  }
}

// A click in the 3-D view: the preview jumps to the path's point under it
// (true), or the click is not the preview's (false).
export function previewClick(px, py) {
  const d = pv.data;
  if (!pv.on || !d || state.viewShows !== 'preview' || !state.viewer) return false;
  let pick;
  try {
    const ray = state.viewer.pickRay(px, py);
    pick = d.timeline.nearestToRay(ray, CLICK_PX * state.viewer.pixelAngle());
  } catch {
    return false;
  }
  if (!pick) return false;
  stop();
  setTime(pick.time_s);
  return true;
}

// A new plan is on screen (compared, current): the plan's preview follows.
export function previewPlanShown() {
  if (pv.source !== 'plan') return;
  if (pv.on) request();
  else if (pv.data) {
    dropData();
    syncControls();
  }
}

// The plan on screen was dropped (a new scan): its preview goes with it.
export function previewPlanDropped() {
  if (pv.source !== 'plan' || (!pv.data && !pv.pending)) return;
  pv.pending = null;
  dropData();
  setTime(0);
  syncControls();
  setStatus(pv.on ? 'No plan for this scan yet.' : '');
  if (state.viewShows === 'preview') drawPlanPaths();
}

// A G-code file was checked (or failed): it can be previewed.
export function previewCheckShown() {
  syncControls();
  if (pv.source !== 'check') return;
  if (pv.on && state.checked) request();
  else if (!state.checked) {
    dropData();
    setTime(0);
    syncControls();
    if (state.viewShows === 'preview') drawPlanPaths();
  }
}

export function bindPreview() {
  const sp = $('preview-speed');
  for (const s of SPEEDS) sp.add(new Option(`${s}×`, String(s)));
  const legend = $('preview-legend');
  legend.replaceChildren(...[[0, 'clear'], [1, 'near: within 0.1 mm over tol'], [2, 'closer than tol'], [NO_DEFECT, 'travel']]
    .map(([code, label]) => swatch(`rgb(${Viewer.previewColor(code).join(',')})`, label)));
  $('preview-btn').addEventListener('click', () => setOn(!pv.on));
  $('preview-play').addEventListener('click', () => (pv.playing ? stop() : play()));
  $('preview-time').addEventListener('input', (e) => {
    stop();
    if (!pv.on) setOn(true);
    setTime(Number(e.target.value));
  });
  $('preview-colour').addEventListener('change', () => { if (pv.on) show(); });
  $('preview-source').addEventListener('change', (e) => {
    pv.source = e.target.value;
    dropData();
    setTime(0);
    syncControls();
    if (pv.on) request();
    else setStatus('');
  });
  syncPreviewButton();
  syncControls();
}
