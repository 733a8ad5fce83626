// Makes dist/pcpp.html: the page as ONE file that works opened from file://
// with no server. Usage: node scripts/single-file.mjs dist/index.html OUT.
//
// - CSS inlined in a <style>.
// - The ES modules of the page (web/main.js and what it imports, including
//   the wasm-bindgen glue) joined into one inline module script. No bundler
//   dependency: the modules are ours and use only the import/export forms
//   handled below; anything else fails the build loudly.
// - The worker's modules joined the same way into a non-executed
//   <script type="text/plain" id="pcpp-worker">; web/engine.js starts it
//   from a Blob URL, as a classic worker.
// - The wasm as base64 in <script type="application/octet-stream"
//   id="pcpp-wasm">; engine.js compiles it and posts the module to the
//   worker, so it is inlined once.
// - A CSP of its own: no remote origin, the inline script allowed by its
//   sha256 hash, the inline style by 'unsafe-inline' (styles cannot run code).
import { createHash } from 'node:crypto';
import { readFileSync, writeFileSync } from 'node:fs';
import { dirname, relative, resolve } from 'node:path';

const [input, output] = process.argv.slice(2);
if (!input || !output) {
  console.error('usage: node scripts/single-file.mjs dist/index.html OUT.html');
  process.exit(2);
}
const base = dirname(resolve(input));

// Joins a module graph into one module body. Each module becomes a function
// scope returning its exports; imports become destructuring of those.
function bundle(entry) {
  const order = [];
  const seen = new Map();
  const ident = (file) => `__m_${relative(base, file).replace(/[^A-Za-z0-9]/g, '_')}`;
  const importRe = /^import\s+([\w$*{][^;]*?)\s+from\s+['"]([^'"]+)['"];?[ \t]*$/gm;
  function visit(file) {
    if (seen.has(file)) return;
    seen.set(file, null);
    const src = readFileSync(file, 'utf8');
    const deps = [];
    const body = src.replace(importRe, (_, clause, spec) => {
      if (!spec.startsWith('.')) throw new Error(`${file}: only relative imports can be inlined (${spec})`);
      const dep = resolve(dirname(file), spec);
      deps.push(dep);
      return `const ${bindings(clause, file)} = ${ident(dep)};`;
    });
    for (const d of deps) visit(d);
    const exports = [];
    let out = body.replace(/^export\s+(async\s+function|function|class|const|let)\s+([A-Za-z_$][\w$]*)/gm,
      (_, kind, name) => { exports.push([name, name]); return `${kind} ${name}`; });
    out = out.replace(/^export\s*\{([^}]*)\};?\s*$/gm, (_, list) => {
      for (const part of list.split(',').map((s) => s.trim()).filter(Boolean)) {
        const m = part.match(/^([\w$]+)(?:\s+as\s+([\w$]+))?$/);
        if (!m) throw new Error(`${file}: cannot inline export { ${part} }`);
        exports.push([m[2] || m[1], m[1]]);
      }
      return '';
    });
    if (/^\s*(import|export)\b/m.test(out)) {
      throw new Error(`${file}: an import/export form the single-file build does not handle`);
    }
    const ret = exports.map(([as, name]) => `${JSON.stringify(as)}: ${name}`).join(', ');
    seen.set(file, `const ${ident(file)} = (() => {\n${out}\nreturn { ${ret} };\n})();\n`);
    order.push(file);
  }
  visit(resolve(entry));
  return order.map((f) => seen.get(f)).join('\n');
}

function bindings(clause, file) {
  // `D`, `{ a, b as c }`, `D, { a }` or `* as ns`
  const ns = clause.match(/^\*\s+as\s+([\w$]+)$/);
  if (ns) return ns[1];
  const m = clause.trim().match(/^(?:([\w$]+)\s*,?\s*)?(?:\{([^}]*)\})?$/);
  if (!m) throw new Error(`${file}: cannot inline import ${clause}`);
  const parts = [];
  if (m[1]) parts.push(`default: ${m[1]}`);
  for (const p of (m[2] || '').split(',').map((s) => s.trim()).filter(Boolean)) {
    const q = p.match(/^([\w$]+)(?:\s+as\s+([\w$]+))?$/);
    if (!q) throw new Error(`${file}: cannot inline import { ${p} }`);
    parts.push(q[2] ? `${q[1]}: ${q[2]}` : q[1]);
  }
  return `{ ${parts.join(', ')} }`;
}

// Text inside a <script> element must not close it early.
function scriptSafe(text, what) {
  if (/<\/script/i.test(text) || /<!--/.test(text)) throw new Error(`${what} contains </script or <!--`);
  return text;
}

let html = readFileSync(input, 'utf8');
const css = readFileSync(resolve(base, 'web/style.css'), 'utf8');
const mainJs = scriptSafe(bundle(resolve(base, 'web/main.js')), 'the page bundle');
// The worker runs as a classic script: Chromium will not start a module
// worker from a Blob URL made by a file:// page (its origin is opaque). The
// bundle has no import/export left; only the glue's default wasm URL, never
// used here (the module is posted to the worker), names import.meta.
const workerJs = scriptSafe(bundle(resolve(base, 'web/worker.js')), 'the worker bundle')
  .replaceAll('import.meta.url', 'self.location.href');
const wasm = readFileSync(resolve(base, 'pkg/pcpp_bg.wasm')).toString('base64');
const hash = createHash('sha256').update(mainJs, 'utf8').digest('base64');
const csp = [
  "default-src 'none'",
  `script-src 'sha256-${hash}' 'wasm-unsafe-eval'`,
  'worker-src blob:',
  "style-src 'unsafe-inline'",
  'img-src data: blob:',
  "base-uri 'none'",
  "form-action 'none'",
].join('; ');

function section(name, replacement) {
  const re = new RegExp(`<!-- pcpp:${name} -->[\\s\\S]*?<!-- /pcpp:${name} -->`);
  if (!re.test(html)) throw new Error(`index.html has no pcpp:${name} section`);
  html = html.replace(re, () => replacement);
}
section('csp', `<meta http-equiv="Content-Security-Policy" content="${csp}">`);
section('style', `<style>\n${css}</style>`);
section('script', [
  `<script type="application/octet-stream" id="pcpp-wasm">${wasm}</script>`,
  `<script type="text/plain" id="pcpp-worker">${workerJs}</script>`,
  `<script type="module">${mainJs}</script>`,
].join('\n'));
writeFileSync(output, html);
console.error(`wrote ${output} (${(html.length / 1e6).toFixed(1)} MB)`);
