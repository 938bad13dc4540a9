// What the dashboard shows of every ESC, fed with the records the WebAssembly session decodes:
// latest values, peaks, frame rate, the link counters and energy of the session's summary,
// alarms (as the monitor raises them) and the last minute of history.

import { ALARM_DEFAULTS, CHART_SECONDS, FULL_CELL_V, faultLevel } from './limits.js';
import { Latch, Threshold, describeChange } from './alarms.js';

/** The quantities of the table and charts: record column, heading, unit, which peak. */
export const SHOWN = Object.freeze([
  { column: 'throttle_in_pct', title: 'Thr in', unit: '%', peak: 'max' },
  { column: 'throttle_out_pct', title: 'Thr out', unit: '%', peak: 'max' },
  { column: 'rpm', title: 'RPM', unit: 'rpm', peak: 'max' },
  { column: 'voltage_v', title: 'Voltage', unit: 'V', peak: 'min' },
  { column: 'current_a', title: 'Current', unit: 'A', peak: 'max' },
  { column: 'phase_current_a', title: 'Phase', unit: 'A', peak: 'max' },
  { column: 'mos_temp_c', title: 'MOSFET', unit: '°C', peak: 'max' },
  { column: 'cap_temp_c', title: 'Cap', unit: '°C', peak: 'max' },
]);

/** Samples of history kept per ESC (a minute at 20 frames/s is 1200). */
const HISTORY_MAX = 2048;
/** Alarm log entries kept. */
const LOG_MAX = 1000;
/** The window of the frame rate, s. */
const RATE_WINDOW_S = 2;

/** The alarm levels of the defaults, overridden by `overrides` (same keys). */
export function limitsFrom(overrides = {}) {
  const d = { ...ALARM_DEFAULTS, ...overrides };
  return {
    mos: new Threshold(d.mos_warning_c, d.mos_critical_c, d.temp_hysteresis_c),
    cap: new Threshold(d.cap_warning_c, d.cap_critical_c, d.temp_hysteresis_c),
    cell: d,
    cells: d.battery_cells ?? null,
    staleAfterS: d.stale_after_s,
    faultHoldS: d.fault_hold_s,
  };
}

function voltageThreshold(limits, cells) {
  const c = limits.cell;
  return new Threshold(c.cell_warning_v * cells, c.cell_critical_v * cells, c.cell_hysteresis_v * cells, true);
}

/** One ESC: `port` (index of its port), `esc` (its number in that port's session). */
class Esc {
  constructor(port, esc, label) {
    this.port = port;
    this.esc = esc;
    this.label = label;
    this.protocol = null;
    this.values = {};
    this.peaks = {};
    this.faults = [];
    this.lastT = null;
    this.times = [];
    this.history = [];
    this.cells = null;
    this.latches = new Map();
    this.link = null;
    this.energy = null;
    this.energyBase = null;
    this.frames = 0;
  }

  latch(name) {
    if (!this.latches.has(name)) this.latches.set(name, new Latch());
    return this.latches.get(name);
  }

  /** Alarms on now: [{name, level}]. */
  alarms() {
    return [...this.latches].filter(([, l]) => l.level).map(([name, l]) => ({ name, level: l.level }));
  }

  /** The frame rate over the last two seconds, Hz. */
  rate(now) {
    const recent = this.times.filter((t) => t > now - RATE_WINDOW_S);
    return recent.length / RATE_WINDOW_S;
  }

  /** Charge (mAh) and energy (Wh) since the last reset, from the session's summary; null without one. */
  used() {
    if (!this.energy) return null;
    const b = this.energyBase ?? { charge_mah: 0, energy_wh: 0 };
    return { mah: this.energy.charge_mah - b.charge_mah, wh: this.energy.energy_wh - b.energy_wh };
  }
}

/** Every ESC of every port, and the alarm log. */
export class Fleet {
  /**
   * `faultNames(protocol, status)`: the names of a status word's bits (the WebAssembly API's),
   * for records that carry `status` but no `faults` column.
   */
  constructor(limits = limitsFrom(), { onLog, faultNames } = {}) {
    this.limits = limits;
    this.faultNames = faultNames;
    this.escs = new Map();
    this.log = [];
    this.onLog = onLog;
    this.portAlarms = new Map();
  }

  #esc(port, esc) {
    const key = `${port}/${esc}`;
    if (!this.escs.has(key)) {
      this.escs.set(key, new Esc(port, esc, key));
      // Numbered as the monitor numbers inputs: by port, then by the port's own ESC numbers.
      const sorted = [...this.escs.values()].sort((a, b) => a.port - b.port || a.esc - b.esc);
      sorted.forEach((e, i) => { e.number = i; });
    }
    return this.escs.get(key);
  }

  /** ESCs in their order. */
  list() {
    return [...this.escs.values()].sort((a, b) => a.number - b.number);
  }

  #logChange(who, name, change, t) {
    if (!change) return;
    const entry = { t, who, text: `${who} ${describeChange(name, change)}`, level: change.level, change };
    this.log.unshift(entry);
    if (this.log.length > LOG_MAX) this.log.pop();
    this.onLog?.(entry);
  }

  /**
   * Takes the records a port's session decoded (`{count, columns}`), received at `now` (Unix
   * seconds: the time of records without `t_s`).
   */
  addRecords(port, { count, columns, protocols }, now) {
    const col = (name, i) => {
      const c = columns[name];
      if (!c) return null;
      const v = c[i];
      return v === undefined || v === null || Number.isNaN(v) ? null : Number(v);
    };
    for (let i = 0; i < count; i++) {
      const e = this.#esc(port, col('esc', i) ?? 0);
      const t = col('t_s', i) ?? now;
      const protocol = columns.protocol?.[i];
      e.protocol = (protocols && protocol !== undefined ? protocols[protocol] : protocol) ?? e.protocol;
      e.frames += 1;
      e.lastT = t;
      e.times.push(t);
      if (e.times.length > 4096) e.times.splice(0, 2048);
      const sample = { t };
      for (const q of SHOWN) {
        const v = col(q.column, i);
        e.values[q.column] = v;
        sample[q.column] = v;
        if (v === null) continue;
        const p = e.peaks[q.column];
        if (p === undefined || (q.peak === 'max' ? v > p : v < p)) e.peaks[q.column] = v;
      }
      e.history.push(sample);
      while (e.history.length > HISTORY_MAX || (e.history.length && e.history[0].t < t - CHART_SECONDS)) e.history.shift();
      const status = col('status', i);
      if (columns.faults) e.faults = faultsOf(columns.faults[i]);
      else e.faults = status && this.faultNames ? this.faultNames(e.protocol, status) : [];
      this.#judge(e, t);
    }
  }

  #judge(e, t) {
    const who = `esc ${e.number}`;
    const v = e.values;
    if (v.mos_temp_c !== null && v.mos_temp_c !== undefined) this.#logChange(who, 'mos_temp', e.latch('mos_temp').update(this.limits.mos, v.mos_temp_c, t), t);
    if (v.cap_temp_c !== null && v.cap_temp_c !== undefined) this.#logChange(who, 'cap_temp', e.latch('cap_temp').update(this.limits.cap, v.cap_temp_c, t), t);
    if (v.voltage_v !== null && v.voltage_v !== undefined) {
      if (e.cells === null) e.cells = this.limits.cells ?? (v.voltage_v > 2 ? Math.min(255, Math.max(1, Math.ceil(v.voltage_v / FULL_CELL_V))) : null);
      if (e.cells) this.#logChange(who, 'low_voltage', e.latch('low_voltage').update(voltageThreshold(this.limits, e.cells), v.voltage_v, t), t);
    }
    const on = new Set(e.faults);
    for (const name of on) this.#logChange(who, name, e.latch(name).set(true, faultLevel(e.protocol, name), this.limits.faultHoldS, t), t);
    for (const [name, latch] of e.latches) {
      if (['mos_temp', 'cap_temp', 'low_voltage', 'stale', 'disconnected'].includes(name) || on.has(name)) continue;
      this.#logChange(who, name, latch.set(false, latch.level ?? 'warning', this.limits.faultHoldS, t), t);
    }
    this.#logChange(who, 'stale', e.latch('stale').set(false, 'warning', 0, t), t);
  }

  /** Takes a port session's summary (`hwfoc summary --json`'s object): link counters, energy. */
  setSummary(port, summary) {
    for (const s of summary?.escs ?? []) {
      const e = this.#esc(port, s.esc ?? 0);
      e.link = s.link ?? null;
      e.energy = s.energy ?? null;
      if (e.energy && !e.energyBase) e.energyBase = { charge_mah: 0, energy_wh: 0 };
    }
  }

  /** At `now`: raises the stale alarm of an ESC silent for the stale time while its port is open. */
  tick(now) {
    for (const e of this.escs.values()) {
      if (e.lastT === null || this.portAlarms.get(e.port)) continue;
      const silent = now - e.lastT >= this.limits.staleAfterS;
      if (silent) this.#logChange(`esc ${e.number}`, 'stale', e.latch('stale').set(true, 'warning', 0, now), now);
    }
  }

  /** Port `port` is gone at `now`: its ESCs' disconnected alarm is raised. */
  portLost(port, now) {
    this.portAlarms.set(port, true);
    for (const e of this.escs.values()) {
      if (e.port !== port) continue;
      e.latch('stale').clear(now);
      this.#logChange(`esc ${e.number}`, 'disconnected', e.latch('disconnected').set(true, 'critical', 0, now), now);
    }
  }

  /** Port `port` is back. */
  portBack(port, now) {
    this.portAlarms.set(port, false);
    for (const e of this.escs.values()) {
      if (e.port === port) this.#logChange(`esc ${e.number}`, 'disconnected', e.latch('disconnected').set(false, 'critical', 0, now), now);
    }
  }

  /** Resets the peaks, and the charge and energy counted from now (the monitor's `c`). */
  resetPeaks() {
    this.peakPowerW = 0;
    for (const e of this.escs.values()) {
      e.peaks = {};
      e.peakPowerW = 0;
      if (e.energy) e.energyBase = { ...e.energy };
    }
  }

  /** All ESCs together: power now (W, the sum of their latest frames), its peak, mAh, Wh (null where no summary gives them). */
  totals() {
    let power = 0;
    let mah = null;
    let wh = null;
    for (const e of this.escs.values()) {
      const p = powerOf(e.values);
      if (p !== null) power += p;
      e.peakPowerW = Math.max(e.peakPowerW ?? 0, p ?? 0);
      const used = e.used();
      if (used) {
        mah = (mah ?? 0) + used.mah;
        wh = (wh ?? 0) + used.wh;
      }
    }
    this.peakPowerW = Math.max(this.peakPowerW ?? 0, power);
    return { powerW: power, peakPowerW: this.peakPowerW, mah, wh };
  }
}

/** Power drawn, W: voltage x input current, a negative power counted as none (energy.rs `drawn_w`). */
export function powerOf(values) {
  if (values.voltage_v == null || values.current_a == null) return null;
  return Math.max(0, values.voltage_v * values.current_a);
}

function faultsOf(cell) {
  if (!cell) return [];
  if (Array.isArray(cell)) return cell;
  return String(cell).split('|').filter(Boolean);
}
