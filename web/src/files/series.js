// A recording's records split by ESC, and what the charts draw from them: the x of each
// record (its time, or its frame number where the recording has no times) and per-pixel
// envelopes, so that a million frames draw as fast as a thousand.

/**
 * The records of each ESC: `{esc, index: Uint32Array}` (places in the record columns), in ESC
 * order.
 * @param {{count: number, columns: {esc: Uint8Array}}} records
 */
export function splitByEsc(records) {
  const esc = records.columns.esc;
  const counts = new Uint32Array(256);
  for (let i = 0; i < records.count; i++) counts[esc[i]]++;
  const out = [];
  const fill = new Map();
  for (let e = 0; e < 256; e++) {
    if (counts[e] === 0) continue;
    const entry = { esc: e, index: new Uint32Array(counts[e]) };
    out.push(entry);
    fill.set(e, { entry, at: 0 });
  }
  const byEsc = new Array(256);
  for (const [e, f] of fill) byEsc[e] = f;
  for (let i = 0; i < records.count; i++) {
    const f = byEsc[esc[i]];
    f.entry.index[f.at++] = i;
  }
  return out;
}

/**
 * Whether the records have times to chart against: every `t_s` a number, never going back
 * within an ESC. Otherwise the charts use each ESC's frame number.
 * @param {Float64Array} t
 * @param {{index: Uint32Array}[]} escs
 */
export function timed(t, escs) {
  for (const { index } of escs) {
    let last = -Infinity;
    for (let k = 0; k < index.length; k++) {
      const v = t[index[k]];
      if (!(v >= last)) return false;
      last = v;
    }
  }
  return escs.length > 0;
}

/**
 * One column's values at the places `index`, in an array of the column's type.
 * @param {Float32Array | Float64Array | Uint8Array} column
 * @param {Uint32Array} index
 */
export function gather(column, index) {
  const out = new column.constructor(index.length);
  for (let k = 0; k < index.length; k++) out[k] = column[index[k]];
  return out;
}

/**
 * The first place in the sorted `xs` whose value is not below `x`.
 * @param {ArrayLike<number>} xs
 * @param {number} x
 */
export function lowerBound(xs, x) {
  let lo = 0;
  let hi = xs.length;
  while (lo < hi) {
    const mid = (lo + hi) >>> 1;
    if (xs[mid] < x) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/**
 * The place in the sorted `xs` nearest to `x` (-1 for an empty array).
 * @param {ArrayLike<number>} xs
 * @param {number} x
 */
export function nearest(xs, x) {
  if (xs.length === 0) return -1;
  const i = lowerBound(xs, x);
  if (i === 0) return 0;
  if (i === xs.length) return xs.length - 1;
  return x - xs[i - 1] <= xs[i] - x ? i - 1 : i;
}

/**
 * The envelope of `ys` over x from `x0` to `x1` on `width` pixel columns: for each column the
 * first, lowest, highest and last value of the samples in it (NaN in a column without one;
 * NaN samples, nulls, are passed over). 4 numbers per column.
 * @param {ArrayLike<number>} xs sorted
 * @param {ArrayLike<number>} ys
 * @param {number} x0
 * @param {number} x1
 * @param {number} width
 */
export function envelope(xs, ys, x0, x1, width) {
  const out = new Float64Array(width * 4).fill(NaN);
  if (!(x1 > x0) || width <= 0) return out;
  const scale = width / (x1 - x0);
  const end = lowerBound(xs, x1);
  for (let i = lowerBound(xs, x0); i <= end && i < xs.length; i++) {
    const y = ys[i];
    if (Number.isNaN(y)) continue;
    const px = Math.min(width - 1, Math.floor((xs[i] - x0) * scale));
    if (px < 0) continue;
    const o = px * 4;
    if (Number.isNaN(out[o])) {
      out[o] = y;
      out[o + 1] = y;
      out[o + 2] = y;
    } else {
      if (y < out[o + 1]) out[o + 1] = y;
      if (y > out[o + 2]) out[o + 2] = y;
    }
    out[o + 3] = y;
  }
  return out;
}

/**
 * The lowest and highest of an envelope's values ([NaN, NaN] when it has none).
 * @param {Float64Array} env
 */
export function range(env) {
  let lo = Infinity;
  let hi = -Infinity;
  for (let o = 0; o < env.length; o += 4) {
    if (env[o + 1] < lo) lo = env[o + 1];
    if (env[o + 2] > hi) hi = env[o + 2];
  }
  return lo <= hi ? [lo, hi] : [NaN, NaN];
}
