// The files mode: recordings dropped or picked are decoded by the WebAssembly build
// (api.openFile), summarised per ESC, and charted with zoom, pan and a cursor readout.

import { Chart, COLOURS } from './chart.js';
import { csvColumns, toCsv } from './csv.js';
import { blocks, gather, hasValue, nearest, splitByEsc, timed } from './series.js';
import { escSummary } from './summary.js';
import { View } from './view.js';

/** The record columns that are quantities to chart, by their presence in the records. */
const NOT_CHARTED = new Set(['t_s', 'esc', 'protocol', 'packet', 'status', 'node', 'msg2_age_ms', 'msg3_age_ms']);

/**
 * Mounts the files mode in `root`.
 * @param {HTMLElement} root
 * @param {typeof import('../hwfoc.js')} api
 */
export function mountFiles(root, api) {
  const doc = root.ownerDocument;
  root.innerHTML = `
    <div class="drop" tabindex="0">
      <p>Drop recordings here (raw bytes, logic-analyser CSV, pcapng of serial or CAN, candump
      logs) or <label class="pick">choose files<input type="file" multiple hidden></label>.
      Nothing leaves this computer.</p>
    </div>
    <nav class="recordings" aria-label="recordings"></nav>
    <div class="notices" role="status"></div>
    <div class="summaries"></div>
    <div class="plot" hidden>
      <div class="controls">
        <fieldset class="escs"><legend>ESCs</legend></fieldset>
        <fieldset class="quantities"><legend>quantities</legend></fieldset>
        <div class="actions">
          <button type="button" class="reset">whole recording</button>
          <button type="button" class="export">CSV of the view</button>
        </div>
      </div>
      <p class="hint">Wheel: zoom. Drag: pan. Double-click: whole recording.</p>
      <div class="readout" aria-live="polite"></div>
      <div class="charts"></div>
    </div>`;
  const input = root.querySelector('input[type=file]');
  const drop = root.querySelector('.drop');
  const state = { recordings: [], current: null };
  const opener = makeOpener(api);

  const open = async (files) => {
    for (const file of files) {
      const bytes = new Uint8Array(await file.arrayBuffer());
      const started = performance.now();
      drop.setAttribute('aria-busy', 'true');
      const opened = await opener(file.name, bytes);
      drop.removeAttribute('aria-busy');
      const recording = prepare(file.name, opened, performance.now() - started);
      state.recordings.push(recording);
      show(recording);
    }
    listRecordings();
  };

  input.addEventListener('change', () => open(Array.from(input.files)));
  drop.addEventListener('dragover', (e) => {
    e.preventDefault();
    drop.classList.add('over');
  });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('over');
    open(Array.from(e.dataTransfer.files));
  });

  function listRecordings() {
    const nav = root.querySelector('.recordings');
    nav.replaceChildren(
      ...state.recordings.map((r) => {
        const b = doc.createElement('button');
        b.type = 'button';
        b.textContent = r.name;
        b.setAttribute('aria-pressed', String(r === state.current));
        b.addEventListener('click', () => {
          show(r);
          listRecordings();
        });
        return b;
      }),
    );
  }

  function show(recording) {
    state.current = recording;
    const notices = root.querySelector('.notices');
    const lines = recording.error ? [recording.error] : recording.notices;
    notices.replaceChildren(
      ...lines.map((line) => {
        const p = doc.createElement('p');
        p.textContent = line;
        return p;
      }),
    );
    const summaries = root.querySelector('.summaries');
    summaries.dataset.recording = recording.name;
    summaries.dataset.openMs = String(Math.round(recording.openMs));
    const escs = recording.error ? [] : recording.summary.escs;
    summaries.replaceChildren(...escs.map((esc, k) => escSummary(doc, esc, COLOURS[k % COLOURS.length])));
    const plot = root.querySelector('.plot');
    plot.hidden = recording.error !== undefined || recording.records.count === 0;
    if (!plot.hidden) mountPlot(plot, recording, api);
  }
}

/**
 * Opens a recording: in a worker where the browser has module workers (the page stays
 * responsive while a large file is decoded), else on the page's thread.
 * @param {typeof import('../hwfoc.js')} api
 * @returns {(name: string, bytes: Uint8Array) => Promise<object>} openFile's answer, or {error}
 */
function makeOpener(api) {
  const direct = async (name, bytes) => {
    try {
      return api.openFile(name, bytes);
    } catch (e) {
      return { error: `${name}: ${e?.message ?? e}` };
    }
  };
  let worker;
  try {
    worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });
  } catch {
    return direct;
  }
  const waiting = new Map();
  let next = 0;
  worker.onmessage = ({ data }) => {
    waiting.get(data.id)?.(data.error ? { error: data.error } : data.opened);
    waiting.delete(data.id);
  };
  worker.onerror = (e) => {
    // A worker that cannot start (no module workers): every open goes on the page's thread.
    e.preventDefault?.();
    worker = null;
    for (const [id, done] of waiting) done(null);
    waiting.clear();
  };
  return async (name, bytes) => {
    if (!worker) return direct(name, bytes);
    const id = next++;
    const answer = await new Promise((done) => {
      waiting.set(id, done);
      // Copied, not transferred: the page keeps the bytes should the worker fail.
      worker.postMessage({ id, name, bytes });
    });
    return answer ?? direct(name, bytes);
  };
}

/**
 * A recording as the page holds it: what openFile gave, split by ESC, with each ESC's x.
 * @param {string} name
 * @param {{records?: object, summary?: object, notices?: string[], error?: string}} opened
 * @param {number} openMs
 */
function prepare(name, opened, openMs) {
  if (opened.error) return { name, error: opened.error, openMs };
  const { records, summary, notices } = opened;
  const escs = splitByEsc(records);
  const isTimed = timed(records.columns.t_s, escs);
  for (const e of escs) {
    e.xs = isTimed ? gather(records.columns.t_s, e.index) : Float64Array.from(e.index, (_, k) => k);
    e.ys = new Map();
    e.chosen = true;
  }
  const quantities = Object.keys(records.columns).filter(
    (name) => !NOT_CHARTED.has(name) && hasValue(records.columns[name]),
  );
  let min = Infinity;
  let max = -Infinity;
  for (const e of escs) {
    if (e.xs.length === 0) continue;
    min = Math.min(min, e.xs[0]);
    max = Math.max(max, e.xs[e.xs.length - 1]);
  }
  return {
    name,
    records,
    summary,
    notices,
    openMs,
    escs,
    timed: isTimed,
    quantities,
    chosen: new Set(quantities),
    view: new View(Number.isFinite(min) ? min : 0, Number.isFinite(max) ? max : 1),
  };
}

/**
 * An ESC's values of one column and their blocks' extremes, made once.
 * @param {object} recording
 * @param {object} esc
 * @param {string} name
 * @returns {{ys: ArrayLike<number>, blocked: {min: Float32Array, max: Float32Array}}}
 */
function series(recording, esc, name) {
  if (!esc.ys.has(name)) {
    const ys = gather(recording.records.columns[name], esc.index);
    esc.ys.set(name, { ys, blocked: blocks(ys) });
  }
  return esc.ys.get(name);
}

/**
 * The fault episodes of an ESC in x (time or frame number).
 * @param {object} recording
 * @param {number} escNumber
 */
function episodes(recording, escNumber) {
  const esc = recording.summary.escs.find((e) => e.esc === escNumber);
  return (esc?.fault_episodes ?? []).map((e) =>
    recording.timed ? { from: e.start_t_s, to: e.end_t_s } : { from: e.start_frame, to: e.end_frame },
  );
}

/**
 * Builds the controls and charts of `recording` in `plot`.
 * @param {HTMLElement} plot
 * @param {object} recording
 * @param {typeof import('../hwfoc.js')} api
 */
/** The listeners of the recording each plot element shows, dropped when another is mounted. */
const mounts = new WeakMap();

function mountPlot(plot, recording, api) {
  // The plot element is shared by the recordings' tabs: the one shown before must stop drawing
  // into it (its window resize listener wrote its own time range into the readout).
  mounts.get(plot)?.abort();
  const mounted = new AbortController();
  mounts.set(plot, mounted);
  const doc = plot.ownerDocument;
  const unit = recording.timed ? 's' : 'frame';
  const escBox = plot.querySelector('.escs');
  escBox.replaceChildren(escBox.querySelector('legend'));
  recording.escs.forEach((e, k) => {
    escBox.append(checkbox(doc, `ESC ${e.esc}`, e.chosen, COLOURS[k % COLOURS.length], (on) => {
      e.chosen = on;
      redraw();
    }));
  });
  const qBox = plot.querySelector('.quantities');
  qBox.replaceChildren(qBox.querySelector('legend'));
  for (const q of recording.quantities) {
    qBox.append(checkbox(doc, q, recording.chosen.has(q), null, (on) => {
      if (on) recording.chosen.add(q);
      else recording.chosen.delete(q);
      build();
    }));
  }
  const chartsBox = plot.querySelector('.charts');
  const readout = plot.querySelector('.readout');
  let charts = [];
  let cursor = null;
  let pending = false;

  function build() {
    chartsBox.replaceChildren();
    charts = recording.quantities
      .filter((q) => recording.chosen.has(q))
      .map((q) => {
        const canvas = doc.createElement('canvas');
        canvas.className = 'chart';
        canvas.dataset.quantity = q;
        chartsBox.append(canvas);
        attach(canvas);
        return { q, chart: new Chart(canvas, q) };
      });
    redraw();
  }

  function redraw() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      if (mounted.signal.aborted) return;
      const shaded = recording.escs.filter((e) => e.chosen).flatMap((e) => episodes(recording, e.esc));
      for (const { q, chart } of charts) {
        const lines = recording.escs
          .map((e, k) => ({ e, colour: COLOURS[k % COLOURS.length] }))
          .filter(({ e }) => e.chosen)
          .map(({ e, colour }) => ({ xs: e.xs, ...series(recording, e, q), colour }));
        chart.draw(recording.view, lines, shaded, cursor);
      }
      showReadout();
    });
  }

  function showReadout() {
    if (cursor === null) {
      readout.textContent = `${fmt(recording.view.x0)} .. ${fmt(recording.view.x1)} ${unit}`;
      return;
    }
    const parts = [`${fmt(cursor)} ${unit}`];
    for (const e of recording.escs.filter((x) => x.chosen)) {
      const k = nearest(e.xs, cursor);
      if (k < 0) continue;
      const values = charts.map(({ q }) => `${q} ${fmt(series(recording, e, q).ys[k])}`);
      parts.push(`ESC ${e.esc}: ${values.join(', ')}`);
    }
    readout.textContent = parts.join(' | ');
  }

  function xAt(canvas, clientX) {
    const { left, width } = new Chart(canvas, '').plotArea();
    const r = canvas.getBoundingClientRect();
    const v = recording.view;
    return v.x0 + ((clientX - r.left - left) / width) * (v.x1 - v.x0);
  }

  function attach(canvas) {
    let drag = null;
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      recording.view.zoom(xAt(canvas, e.clientX), e.deltaY < 0 ? 1 / 1.25 : 1.25);
      redraw();
    }, { passive: false });
    canvas.addEventListener('pointerdown', (e) => {
      drag = { x: xAt(canvas, e.clientX) };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      const x = xAt(canvas, e.clientX);
      if (drag) {
        recording.view.pan(drag.x - x);
      } else {
        cursor = x;
      }
      redraw();
    });
    canvas.addEventListener('pointerup', () => {
      drag = null;
    });
    canvas.addEventListener('pointerleave', () => {
      cursor = null;
      redraw();
    });
    canvas.addEventListener('dblclick', () => {
      recording.view.reset();
      redraw();
    });
  }

  plot.querySelector('.reset').onclick = () => {
    recording.view.reset();
    redraw();
  };
  plot.querySelector('.export').onclick = () => {
    const { records } = recording;
    const csv = toCsv(records, csvColumns(records), rowsInView(recording), api.faultNames);
    const a = doc.createElement('a');
    a.href = URL.createObjectURL(new Blob([csv], { type: 'text/csv' }));
    a.download = `${recording.name.replace(/\.[^.]*$/, '')}-view.csv`;
    a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 10_000);
  };
  globalThis.addEventListener?.('resize', redraw, { signal: mounted.signal });
  build();
}

/**
 * The places of the records of the chosen ESCs in view, in record order.
 * @param {object} recording
 */
export function rowsInView(recording) {
  const { x0, x1 } = recording.view;
  const rows = [];
  for (const e of recording.escs) {
    if (!e.chosen) continue;
    for (let k = 0; k < e.xs.length; k++) {
      if (e.xs[k] >= x0 && e.xs[k] <= x1) rows.push(e.index[k]);
    }
  }
  return Uint32Array.from(rows).sort();
}

/**
 * A checkbox with its label.
 * @param {Document} doc
 * @param {string} text
 * @param {boolean} checked
 * @param {string | null} colour
 * @param {(on: boolean) => void} onChange
 */
function checkbox(doc, text, checked, colour, onChange) {
  const label = doc.createElement('label');
  const box = doc.createElement('input');
  box.type = 'checkbox';
  box.checked = checked;
  box.addEventListener('change', () => onChange(box.checked));
  const span = doc.createElement('span');
  span.textContent = text;
  if (colour) span.style.borderBottom = `3px solid ${colour}`;
  label.append(box, span);
  return label;
}

/** A number for the readout (a Unix time to the millisecond). */
function fmt(v) {
  if (!Number.isFinite(v)) return '-';
  return Math.abs(v) >= 1e5 ? v.toFixed(3) : String(Number(v.toPrecision(6)));
}
