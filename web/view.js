// The 3-D view's controls: orbit, pan and zoom, picking scan points on
// the mesh, dragging the path over the scan, the fiducial markers, and
// which lines the view draws (the plan, a checked program or the preview).
// The drawing itself is the wasm Viewer's (src/render.rs).
import { Viewer } from '../pkg/pcpp.js';
import { BEST, fmtPoints, safePoints } from './fiducials.js';
import { $, fmt, hooks, num, settings, state } from './page.js';
import { userPlaced } from './placement.js';
import { saveSettings, syncVisibility, writeField, writeForm } from './settings.js';
import { showError } from './status.js';

// G (the registration, row-major 4 x 4) applied to a scanner-frame point.
function applyG(m, p) {
  return [0, 1, 2].map((r) => m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3]);
}

// Holes, printer points P and the typed or picked scan points Sr, drawn in
// the view's (printer) frame.
export function updateMarkers() {
  const info = state.info;
  if (state.viewer && info) {
    const printer = settings.fidSource === 'none' ? [] : safePoints(settings.fidPrinterText);
    const showScan = settings.fidSource === 'points' || state.picking;
    const picked = showScan
      ? safePoints(settings.fidScanText).map((p) => applyG(info.registration.matrix, p)) : [];
    try {
      // The holes listed (the best candidates), not every scanner hole.
      const holes = info.holes.filter((h) => h.candidate).slice(0, BEST);
      state.viewer.setMarkers(holes.map((h) => h.printer), printer, picked);
    } catch (e) {
      showError('Could not draw the fiducials', e.message);
    }
    requestDraw();
  }
}

// ---------- picking scan points on the mesh ----------

export function setPicking(on) {
  state.picking = on;
  if (on && state.moving) setMoving(false);
  const b = $('pick-btn');
  b.setAttribute('aria-pressed', on ? 'true' : 'false');
  b.textContent = on ? 'Picking: click the scan (Esc stops)' : 'Pick on mesh';
  $('view').classList.toggle('picking', on);
  $('pick-status').textContent = on ? 'Click the 3-D view where a scan point Sr is; drag still turns the view.' : '';
  syncVisibility();
  updateMarkers();
}

// Asks the worker (which holds the scan) where the camera ray through the
// clicked pixel first meets the mesh.
function pickAt(x, y) {
  let ray;
  try {
    ray = state.viewer.pickRay(x, y);
  } catch (e) {
    $('pick-status').textContent = e.message;
    return;
  }
  if (!state.info) {
    $('pick-status').textContent = 'No scan read yet.';
    return;
  }
  state.worker.postMessage({ type: 'pick', id: ++state.pickId, origin: ray.slice(0, 3), direction: ray.slice(3, 6) });
}

export function onPick(m) {
  if (m.id !== state.pickId) return;
  if (m.error) {
    $('pick-status').textContent = m.error;
    return;
  }
  if (!m.hit) {
    $('pick-status').textContent = 'That click missed the scan.';
    return;
  }
  const pts = safePoints(settings.fidScanText);
  pts.push(m.hit.scan);
  settings.fidScanText = fmtPoints(pts);
  const nPrinter = safePoints(settings.fidPrinterText).length;
  $('pick-status').textContent = `Picked Sr${pts.length} (${m.hit.scan.map((v) => fmt(v)).join(', ')}); `
    + `${pts.length} of ${nPrinter} printer point(s) P.`;
  // Register as soon as every P has its scan point (not before: fewer
  // points cannot register).
  const ready = pts.length === nPrinter && pts.length >= 3;
  if (ready) settings.fidSource = 'points';
  saveSettings();
  writeForm();
  updateMarkers();
  if (ready) hooks.schedulePlan(0);
}

// ---------- moving the path on the scan ----------

export function setMoving(on) {
  state.moving = on;
  $('move-btn').setAttribute('aria-pressed', on ? 'true' : 'false');
  $('view').classList.toggle('moving', on);
  if (on && state.picking) setPicking(false);
}

// The device pixel of a pointer event on the canvas.
export function canvasPixel(canvas, e) {
  const rect = canvas.getBoundingClientRect();
  return [(e.clientX - rect.left) * (canvas.width / rect.width),
    (e.clientY - rect.top) * (canvas.height / rect.height)];
}

// The device pixel of a pointer event during a drag, measured against the
// canvas as it lay at the press (`rect`): the pointer's movement since the
// press, not wherever the canvas is now. A layout change mid-drag (the
// status line, a warning or an error appearing above the view) moves the
// canvas under a still pointer; measured against the new rect, the drawing
// jumped by as much (QA round 19 F5). Scaled by the canvas's size now, so a
// resize mid-drag keeps the pointer at the same fraction of the view.
function dragPixel(canvas, rect, e) {
  return [(e.clientX - rect.left) * (canvas.width / rect.width),
    (e.clientY - rect.top) * (canvas.height / rect.height)];
}

// Where the camera ray through a pixel meets the plane z = zPlane (printer
// frame): the point of the scan the pointer holds during a drag. Null when
// the ray runs parallel to the plane or away from it.
function groundPoint([px, py], zPlane) {
  let r;
  try {
    r = state.viewer.pickRay(px, py);
  } catch {
    return null;
  }
  const [ox, oy, oz, dx, dy, dz] = r;
  if (Math.abs(dz) < 1e-9) return null;
  const t = (zPlane - oz) / dz;
  if (!(t > 0)) return null;
  return [ox + t * dx, oy + t * dy];
}

// The height a drag moves the path at: the mean of the surface path on
// screen, else the scan's middle (in the top view any height gives the
// same XY).
function dragPlaneZ() {
  const v = shownPaths() && shownPaths().view;
  if (v && v.ta.length >= 3) {
    let z = 0;
    for (let i = 2; i < v.ta.length; i += 3) z += v.ta[i];
    return z / (v.ta.length / 3);
  }
  const [lo, hi] = state.info.bbox_mm;
  return (lo[2] + hi[2]) / 2;
}

// Offsets are kept to 0.01 mm: what the fields show is what is planned.
const round2 = (v) => Math.round(v * 100) / 100;

function movePlacementTo(x, y) {
  const nx = round2(x);
  const ny = round2(y);
  if (nx === num(settings.placement.x) && ny === num(settings.placement.y)) return;
  settings.placement.x = nx;
  settings.placement.y = ny;
  userPlaced();
  writeField('pl-x');
  writeField('pl-y');
  state.interacting = true;
  updateDragOffset();
  hooks.planNow();
}

// While the placement differs from that of the plan on screen by a shift
// only, the view draws that plan shifted, so the path follows the pointer
// at the frame rate while the plan at the new placement is computed.
export function updateDragOffset() {
  if (!state.viewer) return;
  const p = shownPaths() && shownPaths().placement;
  const s = settings.placement;
  let dx = 0;
  let dy = 0;
  if (p && p.rotation_deg === num(s.rot) && p.scale === num(s.scale)) {
    dx = num(s.x) - p.offset_mm[0];
    dy = num(s.y) - p.offset_mm[1];
    if (!Number.isFinite(dx) || !Number.isFinite(dy)) {
      dx = 0;
      dy = 0;
    }
  }
  state.viewer.setPathOffset(dx, dy, 0);
  requestDraw();
}

// ---------- 3-D view ----------

export function requestDraw() {
  if (!state.viewer || state.redraw) return;
  state.redraw = requestAnimationFrame(() => {
    state.redraw = 0;
    state.frames++;
    state.viewer.draw();
  });
}

export function bindView() {
  const canvas = $('view');
  try {
    state.viewer = new Viewer(canvas);
  } catch (e) {
    showError('No 3-D view', e.message);
    return;
  }
  const resize = () => {
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
    const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== w || canvas.height !== h) {
      canvas.width = w;
      canvas.height = h;
    }
    state.viewer.resize(w, h);
    requestDraw();
  };
  new ResizeObserver(resize).observe(canvas);
  resize();
  let drag = null;
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('pointerdown', (e) => {
    drag = {
      x: e.clientX, y: e.clientY, x0: e.clientX, y0: e.clientY,
      pan: e.button === 2 || e.button === 1 || e.shiftKey,
      move: null,
    };
    // Move mode, or Ctrl/Alt/Cmd-drag in any mode: the drag moves the path.
    const wantMove = e.button === 0 && !e.shiftKey && (state.moving || e.ctrlKey || e.altKey || e.metaKey);
    if (wantMove && state.info) {
      const z = dragPlaneZ();
      const r = canvas.getBoundingClientRect();
      const rect = { left: r.left, top: r.top, width: r.width, height: r.height };
      const g = rect.width > 0 && rect.height > 0 ? groundPoint(dragPixel(canvas, rect, e), z) : null;
      if (g) {
        drag.move = { z, g0: g, rect, px: num(settings.placement.x), py: num(settings.placement.y), moved: false };
      }
    }
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    if (drag.move) {
      const g = groundPoint(dragPixel(canvas, drag.move.rect, e), drag.move.z);
      if (!g) return;
      drag.move.moved = true;
      movePlacementTo(drag.move.px + g[0] - drag.move.g0[0], drag.move.py + g[1] - drag.move.g0[1]);
      return;
    }
    const dpr = window.devicePixelRatio || 1;
    const dx = (e.clientX - drag.x) * dpr;
    const dy = (e.clientY - drag.y) * dpr;
    drag.x = e.clientX;
    drag.y = e.clientY;
    if (drag.pan) state.viewer.pan(dx, dy);
    else state.viewer.orbit(dx, dy);
    requestDraw();
  });
  const end = () => {
    if (drag && drag.move && drag.move.moved) hooks.endInteraction();
    drag = null;
  };
  canvas.addEventListener('pointerup', (e) => {
    // In pick mode a click (no drag) picks; a drag still turns the view.
    // Otherwise a click on the previewed path jumps the preview there.
    if (drag && !drag.move && !drag.pan && Math.hypot(e.clientX - drag.x0, e.clientY - drag.y0) < 4) {
      const [px, py] = canvasPixel(canvas, e);
      if (state.picking) pickAt(px, py);
      else if (hooks.viewClick) hooks.viewClick(px, py);
    }
    end();
  });
  canvas.addEventListener('pointercancel', end);
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    state.viewer.zoom(e.deltaMode === 1 ? e.deltaY * 20 : e.deltaY);
    requestDraw();
  }, { passive: false });
  // In move mode the arrow keys nudge the path: 0.5 mm, 5 mm with Shift.
  const ARROWS = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, 1], ArrowDown: [0, -1] };
  canvas.addEventListener('keydown', (e) => {
    const d = ARROWS[e.key];
    if (!state.moving || !d) return;
    e.preventDefault();
    const step = e.shiftKey ? 5 : 0.5;
    movePlacementTo(num(settings.placement.x) + d[0] * step, num(settings.placement.y) + d[1] * step);
  });
  canvas.addEventListener('keyup', (e) => { if (ARROWS[e.key]) hooks.endInteraction(); });
  $('reset-view').addEventListener('click', () => { state.viewer.resetView(); requestDraw(); });
  $('top-view').addEventListener('click', () => { state.viewer.topView(); requestDraw(); });
  $('move-btn').addEventListener('click', () => setMoving(!state.moving));
}


// What the view draws as its lines: the plan's paths, a checked program's
// moves or the previewed program (with its nozzle); the panels' buttons
// follow (hooks.viewShowsChanged).
export function setViewShows(mode) {
  state.viewShows = mode;
  if (mode !== 'preview' && state.viewer) state.viewer.setNozzle(0, 0, 0, 0);
  if (hooks.viewShowsChanged) hooks.viewShowsChanged();
  requestDraw();
}

// The paths the view shows: a refused plan's where its drawing lay, else
// the last plan's (none before the first plan).
const shownPaths = () => state.refused || state.lastPlan;

// A refused plan's paths (`view`, planned at `placement` on the mesh
// `mesh`, from the settings `inputs` when they were the page's), shown
// where they lay instead of the last plan's: what the refusal names can
// be seen, and the drawing dragged off it (QA round 7 F3). Drawn now if
// the view shows the plan (a checked program or the preview stays).
export function showRefused(view, placement, mesh, inputs) {
  state.refused = { view, placement, mesh, inputs };
  if (state.viewShows === 'plan') drawPlanPaths();
}

// The refused plan's paths go (the next plan's, or the last plan's again,
// are the view's), redrawn unless `redraw` is false (a plan about to be
// drawn).
export function dropRefused(redraw = true) {
  if (!state.refused) return;
  state.refused = null;
  if (redraw && state.viewShows === 'plan') drawPlanPaths();
}

// The paths on screen (see shownPaths) in the view.
export function drawPlanPaths() {
  if (!state.viewer) return;
  const v = shownPaths() && shownPaths().view;
  if (v) {
    state.viewer.setPathArrays(v.pieces, v.ta, v.tool, v.defects);
    updateDragOffset();
  } else {
    state.viewer.setPathArrays(new Uint32Array(0), new Float32Array(0), new Float32Array(0), new Uint8Array(0));
  }
  setViewShows('plan');
}
