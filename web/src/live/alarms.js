// Alarms as the monitor raises them (crates/hwfoc-cli/src/commands/monitor/alarms.rs): a latch
// per alarm that fires once per episode, escalates once, and clears with hysteresis (levels) or
// after a hold time (status bits, a stale ESC, a lost port), so nothing flickers.

const RANK = { warning: 1, critical: 2 };

/** Two levels on one quantity, bad when high (temperatures) or low (voltage). */
export class Threshold {
  constructor(warning, critical, hysteresis, lowIsBad = false) {
    Object.assign(this, { warning, critical, hysteresis, lowIsBad });
  }

  #badness(value) {
    return this.lowIsBad ? [-value, -this.warning, -this.critical] : [value, this.warning, this.critical];
  }

  /** The level `value` is at on its own: 'critical', 'warning' or null. */
  levelOf(value) {
    const [v, w, c] = this.#badness(value);
    if (v >= c) return 'critical';
    if (v >= w) return 'warning';
    return null;
  }

  /** The level after `value`, coming from `level`: left only `hysteresis` back past it. */
  next(level, value) {
    const [v, w, c] = this.#badness(value);
    const h = this.hysteresis;
    let held = null;
    if (level === 'critical' && v > c - h) held = 'critical';
    else if (level && v > w - h) held = 'warning';
    return worse(held, this.levelOf(value));
  }
}

function worse(a, b) {
  return (RANK[a] ?? 0) >= (RANK[b] ?? 0) ? a : b;
}

/** One alarm's episode: its level, when it started, its worst value. */
export class Latch {
  level = null;
  reported = null;
  since = 0;
  worstValue = null;
  lastOn = -Infinity;

  /** Feeds a reading at `t` seconds; returns a change or null. */
  update(threshold, value, t) {
    const next = threshold.next(this.level, value);
    if (next) {
      const isWorse = threshold.lowIsBad ? value < this.worstValue : value > this.worstValue;
      if (this.worstValue === null || isWorse) this.worstValue = value;
    }
    return this.#moveTo(next, t);
  }

  /** Feeds an on/off condition: on raises at once, off clears after `holdS` seconds off. */
  set(on, level, holdS, t) {
    if (on) {
      this.lastOn = t;
      return this.#moveTo(worse(level, this.level), t);
    }
    if (this.level && t - this.lastOn >= holdS - 1e-9) return this.#moveTo(null, t);
    return null;
  }

  /** Ends the episode now. */
  clear(t) {
    return this.#moveTo(null, t);
  }

  #moveTo(next, t) {
    let change = null;
    if (!this.reported && next) {
      this.since = t;
      this.reported = next;
      change = { kind: 'raised', level: next };
    } else if (this.reported === 'warning' && next === 'critical') {
      this.reported = 'critical';
      change = { kind: 'escalated', level: 'critical' };
    } else if (this.reported && !next) {
      change = { kind: 'cleared', level: this.reported, durationS: Math.max(0, t - this.since), worst: this.worstValue };
      this.reported = null;
      this.worstValue = null;
    }
    this.level = next;
    return change;
  }
}

/** The words of a change as the monitor logs it: `mos_overheat critical raised`. */
export function describeChange(name, change) {
  if (change.kind === 'cleared') return `${name} ${change.level} cleared after ${change.durationS.toFixed(1)} s`;
  return `${name} ${change.level} ${change.kind}`;
}
