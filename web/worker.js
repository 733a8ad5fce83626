// The planning Worker: all planning runs here, so the page never freezes;
// cancelling terminates this worker. It keeps one wasm Session (the scan
// imported, registered and indexed) while the scan and its registration
// settings stay the same, so a placement or nozzle change re-plans without
// re-importing.
import { initSync, initPanicHook, Session } from '../pkg/pcpp.js';

let session = null;
let sessionKey = null;

const post = (msg, transfer) => self.postMessage(msg, transfer || []);

function errorOf(err) {
  return {
    message: String((err && err.message) || err),
    kind: (err && err.kind) || 'other',
  };
}

function plan(m) {
  const { id } = m;
  const key = JSON.stringify([m.scan.key, m.settings.scan, m.settings.registration]);
  let stage = 'scan';
  try {
    if (key !== sessionKey) {
      post({ type: 'progress', id, stage, label: 'reading and registering the scan' });
      const s = new Session(m.scan.bytes, m.scan.name, m.settings.scan, m.settings.registration);
      if (session) session.free();
      session = s;
      sessionKey = key;
      const positions = s.meshPositions();
      const indices = s.meshIndices();
      post({ type: 'scan', id, key: m.scan.key, info: s.info(), positions, indices },
        [positions.buffer, indices.buffer]);
    }
    stage = 'plan';
    post({ type: 'progress', id, stage, label: 'projecting and planning the tool path' });
    const r = session.plan(m.svg.bytes, m.svg.name, m.settings.plan, m.dialect, m.acceptRisk,
      m.profileFile);
    post({ type: 'result', id, gcode: r.gcode, reportJson: r.report_json });
    if (m.compare) {
      stage = 'compare';
      post({ type: 'progress', id, stage, label: 'comparing the four planners' });
      post({ type: 'comparison', id, rows: session.compare(m.svg.bytes, m.svg.name, m.settings.plan) });
    }
    post({ type: 'done', id });
  } catch (err) {
    post({ type: 'error', id, stage, ...errorOf(err) });
  }
}

self.onmessage = (e) => {
  const m = e.data;
  if (m.type === 'init') {
    try {
      initSync({ module: m.module });
      initPanicHook();
      post({ type: 'ready' });
    } catch (err) {
      post({ type: 'error', id: -1, stage: 'init', ...errorOf(err) });
    }
  } else if (m.type === 'plan') {
    plan(m);
  } else if (m.type === 'pick') {
    // The first surface point along the view's ray, on the session's scan.
    if (!session) {
      post({ type: 'pick', id: m.id, error: 'No scan read yet.' });
      return;
    }
    try {
      post({ type: 'pick', id: m.id, hit: session.pick(m.origin, m.direction) });
    } catch (err) {
      post({ type: 'pick', id: m.id, error: errorOf(err).message });
    }
  }
};
