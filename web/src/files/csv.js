// CSV of the records in view: the record schema's columns by name (docs/RECORD-SCHEMA.md), as
// `hwfoc decode --format csv` writes them: a null is an empty cell.

/**
 * The shortest decimal that reads back as the float32 `v` (as the command writes a float32
 * column: 24.7, not 24.700000762939453).
 * @param {number} v
 */
export function float32Text(v) {
  for (let p = 1; p < 10; p++) {
    // The p-digit decimals next to v; of those that read back as v, the nearest (on a tie, the
    // one with an even last digit), as the command's float formatting (ryu) chooses.
    const [mantissa, exponent] = v.toExponential(p - 1).split('e');
    const m = Math.round(Number(mantissa.replace('.', '').replace('-', '')));
    const sign = v < 0 ? '-' : '';
    const scale = Number(exponent) - (p - 1);
    let best = null;
    for (const k of [m - 1, m, m + 1]) {
      if (k <= 0 && m > 0) continue;
      const text = `${sign}${k}e${scale}`;
      const value = Number(text);
      if (Math.fround(value) !== v) continue;
      const distance = Math.abs(value - v);
      if (best === null || distance < best.distance || (distance === best.distance && k % 2 === 0)) {
        best = { value, distance };
      }
    }
    if (best !== null) return String(best.value);
  }
  return String(v);
}

/**
 * One cell: a null (NaN) empty; a float column's value as the command writes a float (`28.0`,
 * not `28`), a float32 by `float32Text`; an integer column's as an integer.
 * @param {number} v
 * @param {'f32' | 'f64' | 'int'} kind
 */
function cell(v, kind) {
  if (Number.isNaN(v)) return '';
  if (kind === 'int') return String(v);
  const text = kind === 'f32' ? float32Text(v) : String(v);
  return /[.e]/.test(text) ? text : `${text}.0`;
}

/** The one float64 column of the records; the other Float64Arrays hold integers. */
const FLOAT64 = new Set(['t_s']);

/**
 * The column names of a CSV of `records`: theirs, with `faults` after `status` as the
 * command's CSV has it.
 * @param {{columns: object}} records
 */
export function csvColumns(records) {
  return Object.keys(records.columns).flatMap((n) => (n === 'status' ? ['status', 'faults'] : [n]));
}

/**
 * The CSV text of the records at `rows` (places in the columns, in order). `faults` is made from
 * `status` and `protocol` by `faultNames(protocol, status)`, `|`-joined.
 * @param {{columns: Object<string, ArrayLike<number>>, protocols: string[]}} records
 * @param {string[]} names the columns to write, in order
 * @param {ArrayLike<number>} rows
 * @param {(protocol: string, status: number) => string[]} [faultNames]
 */
export function toCsv(records, names, rows, faultNames = () => []) {
  const lines = [names.join(',')];
  const { status, protocol } = records.columns;
  const faults = (i) =>
    Number.isNaN(status[i]) ? '' : faultNames(records.protocols[protocol[i]], status[i]).join('|');
  const columns = names.map((n) => records.columns[n]);
  const kinds = names.map((n, c) =>
    columns[c] instanceof Float32Array ? 'f32' : FLOAT64.has(n) ? 'f64' : 'int',
  );
  for (let k = 0; k < rows.length; k++) {
    const i = rows[k];
    const cells = names.map((n, c) =>
      n === 'protocol'
        ? records.protocols[columns[c][i]]
        : n === 'faults'
          ? faults(i)
          : cell(columns[c][i], kinds[c]),
    );
    lines.push(cells.join(','));
  }
  return lines.join('\n') + '\n';
}
