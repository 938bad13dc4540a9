// CSV of the records in view: the record schema's columns by name (docs/RECORD-SCHEMA.md), as
// `hwfoc decode --format csv` writes them: a null is an empty cell.

/**
 * The shortest decimal that reads back as the float32 `v` (as the command writes a float32
 * column: 24.7, not 24.700000762939453).
 * @param {number} v
 */
export function float32Text(v) {
  for (let p = 1; p < 9; p++) {
    const text = v.toPrecision(p);
    if (Math.fround(Number(text)) === v) return String(Number(text));
  }
  return String(v);
}

/**
 * One cell: a null (NaN) empty; a float32 column's value by `float32Text`.
 * @param {number} v
 * @param {boolean} f32
 */
function cell(v, f32) {
  if (Number.isNaN(v)) return '';
  return f32 ? float32Text(v) : String(v);
}

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
  const f32 = columns.map((c) => c instanceof Float32Array);
  for (let k = 0; k < rows.length; k++) {
    const i = rows[k];
    const cells = names.map((n, c) =>
      n === 'protocol'
        ? records.protocols[columns[c][i]]
        : n === 'faults'
          ? faults(i)
          : cell(columns[c][i], f32[c]),
    );
    lines.push(cells.join(','));
  }
  return lines.join('\n') + '\n';
}
