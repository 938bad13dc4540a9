// The dashboard's DOM: the monitor's table (values with peaks, rate, link counters, faults and
// alarms), the totals (power, peak, mAh, Wh), the alarm log and the last minute charted.

import { CHART_SECONDS } from './limits.js';
import { el } from './dom.js';
import { SHOWN, powerOf } from './fleet.js';

const DIGITS = { rpm: 0, throttle_in_pct: 1, throttle_out_pct: 1 };
const COLOURS = ['#2a7ab0', '#d0452f', '#3a9a3a', '#9b59b6', '#e08e0b', '#16a2a2', '#7f6a00', '#c2185b',
  '#455a64', '#8d6e63', '#00897b', '#5c6bc0', '#f4511e', '#6d4c41', '#43a047', '#1e88e5'];


/** `value` with `digits` decimals, without the sign of a value that rounds to zero ("-0.0"). */
export function fixed(value, digits) {
  const text = value.toFixed(digits);
  return Number(text) === 0 ? text.replace('-', '') : text;
}

/** A value as the table shows it. */
export function format(column, value) {
  if (value === null || value === undefined || Number.isNaN(value)) return '–';
  return fixed(value, DIGITS[column] ?? 1);
}

/** The dashboard inside `root`; `render(fleet, now)` redraws it. */
export class Dashboard {
  constructor(root, { onResetPeaks } = {}) {
    this.root = root;
    this.chartColumn = 'rpm';
    const head = el('tr', {}, el('th', {}, 'ESC'), ...SHOWN.map((q) => el('th', {}, `${q.title} ${q.unit}`)),
      el('th', {}, 'Power W'), el('th', {}, 'Rate Hz'), el('th', {}, 'Lost/dup/CRC'), el('th', {}, 'mAh'),
      el('th', {}, 'Wh'), el('th', {}, 'Age s'), el('th', {}, 'Faults and alarms'));
    this.body = el('tbody');
    this.table = el('table', { class: 'live-table' }, el('thead', {}, head), this.body);
    this.totals = el('p', { class: 'live-totals', 'data-testid': 'totals' });
    this.select = el('select', { 'aria-label': 'Quantity charted' },
      ...SHOWN.map((q) => el('option', { value: q.column, selected: q.column === this.chartColumn }, q.title)));
    this.select.addEventListener('change', () => { this.chartColumn = this.select.value; });
    const reset = el('button', { type: 'button' }, 'Reset peaks');
    reset.addEventListener('click', () => onResetPeaks?.());
    this.canvas = el('canvas', { class: 'live-chart', height: 200 });
    this.logList = el('ol', { class: 'live-log', 'data-testid': 'alarm-log' });
    root.append(
      el('div', { class: 'live-scroll' }, this.table),
      this.totals,
      el('div', { class: 'live-chart-bar' }, el('label', {}, 'Last minute: ', this.select), reset),
      this.canvas,
      el('h3', {}, 'Alarms'),
      this.logList,
    );
  }

  render(fleet, now) {
    const escs = fleet.list();
    while (this.body.rows.length > escs.length) this.body.deleteRow(-1);
    escs.forEach((e, i) => this.#row(this.body.rows[i] ?? this.body.insertRow(), e, now));
    const t = fleet.totals();
    const shown = (v, digits) => (v === null ? '–' : fixed(v, digits));
    this.totals.textContent = `All ESCs: ${shown(t.powerW, 0)} W now, peak ${shown(t.peakPowerW, 0)} W, ` +
      `${shown(t.mah, 0)} mAh, ${shown(t.wh, 2)} Wh`;
    this.#log(fleet.log);
    this.#chart(escs, now);
  }

  #row(row, e, now) {
    const alarms = e.alarms();
    const levelOf = (name) => alarms.find((a) => a.name === name)?.level;
    const cells = [el('td', { 'data-col': 'esc' }, `esc ${e.number}`)];
    for (const q of SHOWN) {
      const v = e.values[q.column];
      const alarm = q.column === 'mos_temp_c' ? levelOf('mos_temp') : q.column === 'cap_temp_c' ? levelOf('cap_temp')
        : q.column === 'voltage_v' ? levelOf('low_voltage') : null;
      const td = el('td', { 'data-col': q.column, 'data-value': v ?? '', class: alarm ?? '' }, format(q.column, v));
      const peak = e.peaks[q.column];
      if (peak !== undefined) td.append(el('span', { class: 'peak' }, ` ${q.peak === 'max' ? '↑' : '↓'}${format(q.column, peak)}`));
      cells.push(td);
    }
    const power = powerOf(e.values);
    const link = e.link;
    const used = e.used();
    const lost = e.state === 'lost';
    cells.push(
      el('td', { 'data-col': 'power_w' }, power === null ? '–' : fixed(power, 0)),
      el('td', { 'data-col': 'rate' }, e.rate(now).toFixed(1)),
      el('td', { 'data-col': 'link' }, link ? `${link.lost_packets ?? 0}/${link.duplicate_packets ?? 0}/${link.checksum_failures ?? 0}` : '–'),
      el('td', { 'data-col': 'mah' }, used ? used.mah.toFixed(0) : '–'),
      el('td', { 'data-col': 'wh' }, used ? used.wh.toFixed(2) : '–'),
      el('td', { 'data-col': 'age' }, e.lastT === null ? '–' : Math.max(0, now - e.lastT).toFixed(1)),
      el('td', { 'data-col': 'alarms' }, ...alarms.map((a) => el('span', { class: `alarm ${a.level}` },
        // A port that is gone reads as the monitor's does: `disconnected 12 s`.
        a.name === 'disconnected' ? `disconnected ${Math.max(0, now - e.latch('disconnected').since).toFixed(0)} s` : a.name, ' ')),
        ...e.faults.filter((f) => !alarms.some((a) => a.name === f)).map((f) => el('span', { class: 'fault' }, f, ' '))),
    );
    row.className = lost ? 'lost' : '';
    row.dataset.esc = String(e.number);
    row.dataset.frames = String(e.frames);
    row.replaceChildren(...cells);
  }

  #log(log) {
    const shown = log.slice(0, 50);
    if (this.logList.dataset.n === String(log.length) && this.logList.childElementCount === shown.length) return;
    this.logList.dataset.n = String(log.length);
    this.logList.replaceChildren(...shown.map((entry) =>
      el('li', { class: entry.level ?? '' }, `${new Date(entry.t * 1000).toLocaleTimeString()} ${entry.text}`)));
  }

  #chart(escs, now) {
    const c = this.canvas;
    const width = Math.max(200, c.clientWidth || c.parentElement?.clientWidth || 600);
    if (c.width !== width) c.width = width;
    const g = c.getContext('2d');
    if (!g) return;
    g.clearRect(0, 0, c.width, c.height);
    const col = this.chartColumn;
    let lo = Infinity;
    let hi = -Infinity;
    for (const e of escs) for (const s of e.history) if (s[col] !== null && s[col] !== undefined) { lo = Math.min(lo, s[col]); hi = Math.max(hi, s[col]); }
    if (!Number.isFinite(lo)) return;
    if (hi === lo) { hi += 1; lo -= 1; }
    const pad = 30;
    const x = (t) => pad + ((t - (now - CHART_SECONDS)) / CHART_SECONDS) * (c.width - pad - 4);
    const y = (v) => c.height - 16 - ((v - lo) / (hi - lo)) * (c.height - 24);
    g.fillStyle = '#666';
    g.font = '11px sans-serif';
    g.fillText(format(col, hi), 2, 12);
    g.fillText(format(col, lo), 2, c.height - 16);
    g.fillText(`-${CHART_SECONDS} s`, pad, c.height - 2);
    escs.forEach((e, i) => {
      g.strokeStyle = COLOURS[i % COLOURS.length];
      g.beginPath();
      let pen = false;
      let last = null;
      for (const s of e.history) {
        const v = s[col];
        // A gap of more than a second is not bridged.
        if (v === null || v === undefined || (last !== null && s.t - last > 1)) { pen = false; }
        if (v !== null && v !== undefined) {
          if (pen) g.lineTo(x(s.t), y(v)); else g.moveTo(x(s.t), y(v));
          pen = true;
        }
        last = s.t;
      }
      g.stroke();
    });
  }
}
