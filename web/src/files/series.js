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
 * Whether `column` holds a value (not all NaN): a plain loop, since a column of a quantity the
 * protocol does not send is read to its end (a closure per element cost 0.4 s on 1.15 million
 * records of 14 columns).
 * @param {ArrayLike<number>} column
 */
export function hasValue(column) {
  for (let i = 0; i < column.length; i++) {
    if (column[i] === column[i]) return true;
  }
  return false;
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

/** Samples per block of `blocks`. */
export const BLOCK = 16;

/**
 * The lowest and highest value of each block of `BLOCK` samples (NaN for a block of nulls):
 * a view with many samples per pixel is drawn from these, a sixteenth of the work.
 * @param {ArrayLike<number>} ys
 * @returns {{min: Float32Array, max: Float32Array}}
 */
export function blocks(ys) {
  const n = Math.ceil(ys.length / BLOCK);
  const min = new Float32Array(n).fill(NaN);
  const max = new Float32Array(n).fill(NaN);
  for (let b = 0; b < n; b++) {
    let lo = Infinity;
    let hi = -Infinity;
    const end = Math.min(ys.length, (b + 1) * BLOCK);
    for (let i = b * BLOCK; i < end; i++) {
      const y = ys[i];
      if (y < lo) lo = y;
      if (y > hi) hi = y;
    }
    if (lo <= hi) {
      min[b] = lo;
      max[b] = hi;
    }
  }
  return { min, max };
}

/**
 * The envelope of `ys` over x from `x0` to `x1` on `width` pixel columns: for each column the
 * first, lowest, highest and last value of the samples in it (NaN in a column without one;
 * NaN samples, nulls, are passed over). 4 numbers per column.
 *
 * With `blocked` (`blocks(ys)`) and at least 4 blocks' samples per column, whole blocks are
 * taken at once, each in the column of its first sample (so a block across a column's edge
 * counts in the first: at most a quarter of a column off); first and last are then the block's
 * bounds' samples where they are numbers.
 * @param {ArrayLike<number>} xs sorted
 * @param {ArrayLike<number>} ys
 * @param {number} x0
 * @param {number} x1
 * @param {number} width
 * @param {{min: Float32Array, max: Float32Array}} [blocked]
 */
export function envelope(xs, ys, x0, x1, width, blocked) {
  const out = new Float64Array(width * 4).fill(NaN);
  if (!(x1 > x0) || width <= 0) return out;
  const scale = width / (x1 - x0);
  const start = lowerBound(xs, x0);
  const end = Math.min(xs.length, lowerBound(xs, x1) + 1);
  const add = (px, first, lo, hi, last) => {
    if (px < 0) return;
    const o = Math.min(width - 1, px) * 4;
    if (Number.isNaN(out[o])) {
      out[o] = first;
      out[o + 1] = lo;
      out[o + 2] = hi;
    } else {
      if (lo < out[o + 1]) out[o + 1] = lo;
      if (hi > out[o + 2]) out[o + 2] = hi;
    }
    out[o + 3] = last;
  };
  const coarse = blocked !== undefined && end - start >= width * BLOCK * 4;
  let i = start;
  while (i < end) {
    if (coarse && i % BLOCK === 0 && i + BLOCK <= end) {
      const b = i / BLOCK;
      const lo = blocked.min[b];
      if (!Number.isNaN(lo)) {
        const hi = blocked.max[b];
        const first = Number.isNaN(ys[i]) ? lo : ys[i];
        const last = Number.isNaN(ys[i + BLOCK - 1]) ? hi : ys[i + BLOCK - 1];
        add(Math.floor((xs[i] - x0) * scale), first, lo, hi, last);
      }
      i += BLOCK;
      continue;
    }
    const y = ys[i];
    if (!Number.isNaN(y) && xs[i] <= x1) add(Math.floor((xs[i] - x0) * scale), y, y, y, y);
    i++;
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
