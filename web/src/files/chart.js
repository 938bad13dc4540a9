// One quantity's chart: every chosen ESC's line on a canvas, drawn from per-pixel envelopes,
// with the fault episodes shaded. The view (x0..x1) is shared by the charts of a recording and
// changed by the caller (wheel to zoom, drag to pan: see view.js).

import { envelope, range } from './series.js';

/** The ESCs' line colours, by place in the recording's ESC list. */
export const COLOURS = ['#1f77b4', '#d62728', '#2ca02c', '#ff7f0e', '#9467bd', '#8c564b', '#e377c2', '#17becf'];

const MARGIN_LEFT = 56;
const MARGIN_BOTTOM = 18;

/**
 * A chart on `canvas`.
 */
export class Chart {
  /**
   * @param {HTMLCanvasElement} canvas
   * @param {string} title the quantity's column name and unit
   */
  constructor(canvas, title) {
    this.canvas = canvas;
    this.title = title;
  }

  /** The plot area's left edge and width in CSS pixels. */
  plotArea() {
    const width = this.canvas.clientWidth;
    return { left: MARGIN_LEFT, width: Math.max(1, width - MARGIN_LEFT - 4) };
  }

  /**
   * Draws the lines.
   * @param {{x0: number, x1: number}} view
   * @param {{xs: ArrayLike<number>, ys: ArrayLike<number>, blocked?: object, colour: string}[]} lines
   * @param {{from: number, to: number}[]} shaded fault episodes, in x
   * @param {number | null} cursor the cursor's x, or null
   */
  draw(view, lines, shaded, cursor) {
    const canvas = this.canvas;
    const dpr = globalThis.devicePixelRatio || 1;
    const cssW = canvas.clientWidth;
    const cssH = canvas.clientHeight;
    if (canvas.width !== Math.round(cssW * dpr) || canvas.height !== Math.round(cssH * dpr)) {
      canvas.width = Math.round(cssW * dpr);
      canvas.height = Math.round(cssH * dpr);
    }
    const ctx = canvas.getContext('2d');
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, cssW, cssH);
    const { left, width } = this.plotArea();
    const top = 14;
    const height = Math.max(1, cssH - top - MARGIN_BOTTOM);
    const px = Math.max(1, Math.floor(width));
    const envs = lines.map((l) => envelope(l.xs, l.ys, view.x0, view.x1, px, l.blocked));
    let lo = Infinity;
    let hi = -Infinity;
    for (const env of envs) {
      const [a, b] = range(env);
      if (a < lo) lo = a;
      if (b > hi) hi = b;
    }
    if (!(lo <= hi)) {
      lo = 0;
      hi = 1;
    } else if (lo === hi) {
      lo -= 1;
      hi += 1;
    }
    const yOf = (v) => top + height - ((v - lo) / (hi - lo)) * height;
    const xScale = width / (view.x1 - view.x0);

    ctx.fillStyle = 'rgba(214, 39, 40, 0.15)';
    for (const s of shaded) {
      const a = Math.max(0, (s.from - view.x0) * xScale);
      const b = Math.min(width, (s.to - view.x0) * xScale);
      if (b >= a) ctx.fillRect(left + a, top, Math.max(1, b - a), height);
    }

    ctx.lineWidth = 1;
    ctx.font = '11px system-ui, sans-serif';
    ctx.fillStyle = '#444';
    ctx.strokeStyle = '#eee';
    ctx.textAlign = 'right';
    for (const v of niceTicks(lo, hi, Math.max(2, Math.floor(height / 35)))) {
      const y = Math.round(yOf(v)) + 0.5;
      ctx.beginPath();
      ctx.moveTo(left, y);
      ctx.lineTo(left + width, y);
      ctx.stroke();
      ctx.fillText(formatTick(v), left - 4, y + 4);
    }
    ctx.textAlign = 'center';
    for (const v of niceTicks(view.x0, view.x1, Math.max(2, Math.floor(width / 90)))) {
      const x = Math.round(left + (v - view.x0) * xScale) + 0.5;
      ctx.beginPath();
      ctx.moveTo(x, top);
      ctx.lineTo(x, top + height);
      ctx.stroke();
      ctx.fillText(formatTick(v), x, top + height + 13);
    }
    ctx.strokeStyle = '#bbb';
    ctx.strokeRect(left + 0.5, top + 0.5, width - 1, height - 1);
    ctx.textAlign = 'left';
    ctx.fillText(this.title, left + 4, top - 3);

    envs.forEach((env, k) => {
      ctx.strokeStyle = lines[k].colour;
      ctx.beginPath();
      let pen = false;
      for (let c = 0; c < px; c++) {
        const o = c * 4;
        if (Number.isNaN(env[o])) continue;
        const x = left + c + 0.5;
        if (pen) ctx.lineTo(x, yOf(env[o]));
        else ctx.moveTo(x, yOf(env[o]));
        ctx.lineTo(x, yOf(env[o + 1]));
        ctx.lineTo(x, yOf(env[o + 2]));
        ctx.lineTo(x, yOf(env[o + 3]));
        pen = true;
      }
      ctx.stroke();
    });

    if (cursor !== null && cursor >= view.x0 && cursor <= view.x1) {
      const x = left + (cursor - view.x0) * xScale;
      ctx.strokeStyle = '#000';
      ctx.beginPath();
      ctx.moveTo(x + 0.5, top);
      ctx.lineTo(x + 0.5, top + height);
      ctx.stroke();
    }
  }
}

/**
 * Round values between `lo` and `hi` for about `count` ticks (steps of 1, 2 or 5 times a power
 * of ten).
 * @param {number} lo
 * @param {number} hi
 * @param {number} count
 */
export function niceTicks(lo, hi, count) {
  if (!(hi > lo) || count < 1) return [];
  const raw = (hi - lo) / count;
  const power = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 5, 10].map((m) => m * power).find((s) => s >= raw) ?? 10 * power;
  const ticks = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) {
    ticks.push(Number(v.toPrecision(12)));
  }
  return ticks;
}

/**
 * A tick's label: at most 4 significant digits.
 * @param {number} v
 */
export function formatTick(v) {
  if (!Number.isFinite(v)) return '';
  if (v !== 0 && (Math.abs(v) >= 1e6 || Math.abs(v) < 1e-3)) return v.toExponential(2);
  return String(Number(v.toPrecision(4)));
}
