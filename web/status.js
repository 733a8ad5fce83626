// The page's error panel, status line and progress of a plan: what every
// other module reports through.
import { $, pageText, state } from './page.js';

// What the error on screen is about (its topic), so that a later success
// clears only the error it supersedes: 'check' (a G-code file that could
// not be checked), 'file' (a file of a kind the page does not read), or
// null (the others: planning, the scan, the drawing).
let shownTopic = null;

// `file`: the file the title names; the core's message starting with its
// name does not say it a second time. `topic`: what the error is about
// (above). `notice`: not a failure of the user's (the demo drawing refused
// on a new scan), shown in the panel's calm colours.
export function showError(title, message, file, topic = null, notice = false) {
  const m = String(message);
  $('error-title').textContent = title;
  $('error-message').textContent = pageText(file && m.startsWith(`${file}: `) ? m.slice(file.length + 2) : m);
  $('error-panel').classList.toggle('notice', notice);
  $('error-panel').hidden = false;
  shownTopic = topic;
}

// Hides the error panel; with `topics` (one or a list), only if the error
// on screen is about one of them: a G-code file checked clears the error
// of the check before it, not a scan that failed to load.
export function clearError(topics) {
  if (topics !== undefined && ![topics].flat().includes(shownTopic)) return;
  $('error-panel').hidden = true;
  shownTopic = null;
}

// The status line keeps a fixed height (index.html): a text too long for
// it scrolls there, and shows whole on hover.
export function setStatus(text, stale) {
  const el = $('plan-status');
  el.textContent = text;
  el.title = text;
  el.classList.toggle('stale', !!stale);
}

const STAGES = ['read', 'import', 'register', 'index', 'plan'];

export function showProgress(stage, label, fraction) {
  $('progress').hidden = false;
  const at = STAGES.indexOf(stage);
  for (const li of $('stages').children) {
    const i = STAGES.indexOf(li.dataset.stage);
    li.classList.toggle('active', i === at);
    li.classList.toggle('done', at >= 0 && i < at);
  }
  $('progress-label').textContent = label || '';
  const bar = $('progress-bar');
  bar.hidden = stage !== 'read' || !(fraction >= 0);
  if (!bar.hidden) bar.value = fraction;
}

// A plan's progress and Cancel appear only once it has taken a moment:
// during a drag, plans of a few milliseconds would make the toolbar flicker.
const PROGRESS_DELAY_MS = 250;

export function laterProgress(label) {
  state.progressLabel = label;
  if (state.progressTimer || !$('progress').hidden) return;
  state.progressTimer = setTimeout(() => {
    state.progressTimer = 0;
    if (!state.busy) return;
    $('cancel-btn').hidden = false;
    showProgress('plan', state.progressLabel);
  }, PROGRESS_DELAY_MS);
}

export function endProgress() {
  clearTimeout(state.progressTimer);
  state.progressTimer = 0;
  $('progress').hidden = true;
  $('cancel-btn').hidden = true;
}
