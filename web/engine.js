// Loads the wasm module once on the main thread (the renderer needs it) and
// hands the compiled module to the planning Worker, in both builds: served
// (files next to each other) and single-file (wasm base64-inlined, worker
// source inlined and started from a Blob URL).
import { initSync, initPanicHook } from '../pkg/pcpp.js';

function inlined(id) {
  const el = typeof document !== 'undefined' ? document.getElementById(id) : null;
  return el ? el.textContent : null;
}

function base64ToBytes(b64) {
  const bin = atob(b64.trim());
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

// Compiles the wasm and instantiates it for this thread.
export async function loadWasm() {
  const b64 = inlined('pcpp-wasm');
  let module;
  if (b64 !== null) {
    module = await WebAssembly.compile(base64ToBytes(b64));
  } else {
    const url = new URL('../pkg/pcpp_bg.wasm', import.meta.url);
    const res = await fetch(url);
    if (!res.ok) throw new Error(`could not load ${url.pathname}: HTTP ${res.status}`);
    module = await WebAssembly.compileStreaming(res);
  }
  initSync({ module });
  initPanicHook();
  return module;
}

// A planning worker that has instantiated `module`.
export function startWorker(module) {
  const src = inlined('pcpp-worker');
  let worker;
  if (src !== null) {
    // Classic, not module: Chromium refuses module workers from the Blob
    // URLs of a file:// page (scripts/single-file.mjs bundles it that way).
    const url = URL.createObjectURL(new Blob([src], { type: 'text/javascript' }));
    worker = new Worker(url);
  } else {
    worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });
  }
  worker.postMessage({ type: 'init', module });
  return worker;
}
