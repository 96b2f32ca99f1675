// What your controller runs (issue 23, item 1): the view, fetched when a shaper is first
// realised (web/realise.js loads it). For each compared shaper realised by a firmware or a
// generic controller, `realizeShaper` of the recording module (instantiated here, on the page's
// thread) gives the shaper the controller runs and what that costs; `drawRealisation` draws
// V(f) designed (solid) and as run (dashed) on one chart; the table gives V at each mode and
// I(Vtol) before and after, and the library's one-line summary says what was changed.
//
// A solved family (si, direct, bounded sampled) is realised from the impulses the page drew
// (a custom spec): this module has no solver. A realisation that fails names its field
// (`shapers[k].realise.…`) and the view keeps that shaper's last good realisation.
import initRecording, { realizeShaper, drawRealisation } from '../pkg/page/recording.js';
import { isRealised } from './realise.js';

const $ = (id) => document.getElementById(id);
/** The compared shapers' colours (web/dom.js's COLORS; this bundle has its own copy). */
const COLORS = ['#0072b2', '#d55e00', '#009e73', '#cc79a7'];
/** Points of each V(f) curve. */
const POINTS = 201;

let started = null;
/** Instantiates the recording module (once). */
export function ready() {
  started ??= initRecording();
  return started;
}

/** The last good realisation of each shaper: `{ key, r, label }`, `key` what it was computed
 * from (an edit that changes none of it, the mismatch say, reuses it). */
const lastGood = new Map();
/** What the chart last drew (its data and size, as JSON): unchanged, it is not drawn again. */
let drawnKey = '';

// The chart's CSS size, kept by a ResizeObserver (as main.js does for the other charts): reading
// clientWidth in update() would lay the whole page out again, the tables' texts having changed.
let chartSize = null;
let observer = null;
function sizeOf(canvas, schedule) {
  if (!chartSize) {
    chartSize = [canvas.clientWidth, canvas.clientHeight];
    observer = typeof ResizeObserver === 'function' ? new ResizeObserver(() => {
      const next = [canvas.clientWidth, canvas.clientHeight];
      if (next[0] !== chartSize[0] || next[1] !== chartSize[1]) {
        chartSize = next;
        schedule();
      }
    }) : null;
    observer?.observe(canvas);
  }
  return chartSize;
}

const fmt = (x, digits = 4) => (Number.isFinite(x) ? String(Number(x.toPrecision(digits))) : '—');
const pct = (v) => (Number.isFinite(v) ? (Math.abs(v) < 1e-11 ? '≈ 0' : fmt(v * 100, 3)) : '—');

/** The realizeShaper spec of shaper k: its own spec, or (solved families) the impulses drawn. */
function specOf(st, k, drawn, solved) {
  const { realise, ...shaper } = st.shapers[k];
  if (solved && drawn) return { modes: st.modes, family: 'custom', impulses: drawn.shaper.impulses };
  return { ...shaper, modes: st.modes };
}

/** The controller's options of `realise`: only the numbers given (blank ones default). */
function optionsOf(realise, st, curve) {
  const o = { firmware: realise.firmware, vtol: st.view.vtol, curve };
  for (const k of ['periodS', 'amplitudeSteps', 'maxImpulses']) {
    if (realise[k] !== undefined && realise[k] !== null) o[k] = realise[k];
  }
  return o;
}

/** An error of realizeShaper renamed to the page's field of shaper k. */
function renamed(e, k) {
  const field = typeof e?.field === 'string' ? e.field : '';
  const message = String(e?.message ?? e);
  const to = field.startsWith('options.') ? `shapers[${k}].realise.${field.slice(8)}`
    : field === 'options' ? `shapers[${k}].realise.firmware` : `shapers[${k}]${field ? `.${field}` : ''}`;
  return { kind: e?.kind, field: to, message: message.startsWith(field) && field ? `${to}${message.slice(field.length)}` : message };
}

/** Writes `text` into `node` only when it changed (writing makes the browser lay out again). */
function setText(node, text) {
  if (node.textContent !== text) node.textContent = text;
}

/**
 * Updates the view for the frame just drawn (see web/realise.js, updateRealisation): every
 * realised shaper that was drawn is realised again (the designs change with every edit), its
 * errors shown at its fields, the last good realisation kept for a shaper whose realisation
 * fails.
 */
export function update(st, result, kept, hooks) {
  const section = $('realisation');
  const shown = [];
  const topHz = Math.max(...st.modes.map((m) => m.frequencyHz).filter(Number.isFinite), 1);
  const curve = { fromHz: 0, toHz: 2.5 * topHz, points: POINTS };
  kept.forEach((k, j) => {
    const spec = st.shapers[k];
    if (!isRealised(spec)) return;
    const solved = hooks.solvedFamilies.has(spec.family);
    const args = [specOf(st, k, result.results[j], solved), optionsOf(spec.realise, st, curve)];
    const key = JSON.stringify(args);
    // Another shaper now at k (one before it was removed): its last good is not this one's.
    if (lastGood.get(k) && lastGood.get(k).family !== spec.family) lastGood.delete(k);
    if (lastGood.get(k)?.key !== key || lastGood.get(k)?.failed) {
      try {
        lastGood.set(k, { key, family: spec.family, r: realizeShaper(...args), label: result.results[j].label });
      } catch (e) {
        hooks.showError(renamed(e, k));
        const last = lastGood.get(k);
        if (last) last.failed = true;
      }
    }
    const good = lastGood.get(k);
    if (good) shown.push({ k, ...good });
  });
  for (const k of [...lastGood.keys()]) if (!(k < st.shapers.length) || !isRealised(st.shapers[k])) lastGood.delete(k);
  if (section.hidden !== !shown.length) section.hidden = !shown.length;
  if (!shown.length) return;
  drawChart(st, shown, hooks.schedule);
  showSummaries(shown);
  showTable(st, shown);
}

function drawChart(st, shown, schedule) {
  const canvas = $('realisation-chart');
  const ratio = window.devicePixelRatio || 1;
  const [cw, ch] = sizeOf(canvas, schedule);
  const w = Math.max(1, Math.round(cw * ratio));
  const h = Math.max(1, Math.round(ch * ratio));
  const key = JSON.stringify([w, h, st.view.vtol, st.modes, shown.map(({ k, key: of, label }) => [k, of, label])]);
  if (key === drawnKey) return;
  drawnKey = key;
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
  drawRealisation(canvas, {
    shapers: shown.map(({ k, r, label }) => ({
      label: `${k + 1}: ${label}`, color: COLORS[k % COLORS.length], ideal: r.sensitivityIdeal, realised: r.sensitivityRealised,
    })),
    vtol: st.view.vtol,
    modesHz: st.modes.map((m) => m.frequencyHz),
  }, { pixelRatio: ratio });
}

/** One line per realised shaper: who runs it, and the library's summary. */
function showSummaries(shown) {
  const list = $('realisation-summary');
  while (list.children.length > shown.length) list.lastChild.remove();
  shown.forEach(({ k, r, label }, i) => {
    let li = list.children[i];
    if (!li) {
      li = list.appendChild(document.createElement('li'));
      li.append(document.createElement('span'), document.createElement('strong'), document.createTextNode(''), document.createElement('span'));
      li.children[0].className = 'swatch';
      li.lastChild.className = 'realisation-text';
    }
    li.dataset.shaper = String(k);
    li.children[0].style.background = COLORS[k % COLORS.length];
    setText(li.children[1], `Shaper ${k + 1} (${label}) on ${title(r.firmware)}`);
    setText(li.childNodes[2], r.runs === 'custom' ? ', as a custom shaper: ' : `, as its ${r.runs.toUpperCase()}: `);
    setText(li.lastChild, r.summary);
  });
}

const title = (firmware) => ({
  klipper: 'Klipper', kalico: 'Kalico', rrf: 'RepRapFirmware', marlin: 'Marlin (classic)',
  marlinFtMotion: 'Marlin FT_MOTION', prusa: 'Prusa', generic: 'the generic controller',
}[firmware] ?? firmware);

/** The table: a column per realised shaper; V at each mode and I(Vtol), designed → as run. */
function showTable(st, shown) {
  const table = $('realisation-table');
  const head = shown.map(({ k }) => `Shaper ${k + 1}`);
  const key = JSON.stringify(head);
  if (table.tHead.dataset.key !== key) {
    const tr = document.createElement('tr');
    tr.append(document.createElement('th'), ...head.map((t) => Object.assign(document.createElement('th'), { scope: 'col', textContent: t })));
    table.tHead.replaceChildren(tr);
    table.tHead.dataset.key = key;
  }
  const vtolPct = fmt(st.view.vtol * 100, 4);
  const rows = [['Impulses, designed → run', (r) => `${r.ideal.impulses.length} → ${r.realised.impulses.length}`],
    ['Duration (ms), designed → run', (r) => `${fmt(r.ideal.duration * 1e3, 5)} → ${fmt(r.realised.duration * 1e3, 5)}`]];
  st.modes.forEach((m, i) => {
    rows.push([`V at mode ${i + 1} (${fmt(m.frequencyHz, 4)} Hz), designed → run (%)`,
      (r) => `${pct(r.modes[i]?.vibrationIdeal)} → ${pct(r.modes[i]?.vibrationRealised)}`]);
  });
  rows.push([`I(${vtolPct} %) at mode 1, designed → run`, (r) => `${fmt(r.insensitivityIdeal.width, 4)} → ${fmt(r.insensitivityRealised.width, 4)}`]);
  rows.push(['Acts as a shaper for (Hz)', (r) => (r.actsAsHz == null ? '—' : fmt(r.actsAsHz, 5))]);
  const body = table.tBodies[0];
  while (body.rows.length > rows.length) body.deleteRow(-1);
  rows.forEach(([name, f], i) => {
    const tr = body.rows[i] ?? body.insertRow();
    const cells = [name, ...shown.map(({ r }) => f(r))];
    while (tr.cells.length > cells.length) tr.deleteCell(-1);
    cells.forEach((text, c) => {
      let cell = tr.cells[c];
      if (!cell) {
        cell = document.createElement(c === 0 ? 'th' : 'td');
        if (c === 0) cell.scope = 'row';
        tr.appendChild(cell);
      }
      setText(cell, text);
    });
  });
}
