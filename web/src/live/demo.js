// The demo: a recording bundled with the page (testdata/recordings/chunked-2esc.pcapng, two
// simulated ESCs, one with a MOSFET-overheat episode), decoded by the WebAssembly reader and
// replayed in real time, over and over, as a virtual port.

/** Where the bundled recording is, next to this module. */
export const DEMO_URL = new URL('./demo.pcapng', import.meta.url);

/** The records of `records` (`{count, columns}`) from row `from` to `to`, as a new set. */
export function slice(records, from, to) {
  const columns = {};
  for (const [name, c] of Object.entries(records.columns)) columns[name] = c.slice(from, to);
  return { count: to - from, columns, protocols: records.protocols };
}

/**
 * A virtual port replaying `records` at their pace: `onRecords(set, nowS)` gets each frame when
 * its time has come, its `t_s` moved to now. Returns `stop()`.
 */
export function replay(records, onRecords, { now = () => Date.now() / 1000, every = 50 } = {}) {
  const t = records.columns.t_s;
  if (!records.count || !t) return () => {};
  const first = t[0];
  const span = t[records.count - 1] - first + 0.1;
  let start = now();
  let next = 0;
  const timer = setInterval(() => {
    const elapsed = now() - start;
    let end = next;
    while (end < records.count && t[end] - first <= elapsed) end++;
    if (end > next) {
      const set = slice(records, next, end);
      const shift = start - first;
      set.columns.t_s = Float64Array.from(set.columns.t_s, (v) => v + shift);
      onRecords(set, now());
      next = end;
    }
    if (next >= records.count && elapsed >= span) {
      start += span;
      next = 0;
    }
  }, every);
  return () => clearInterval(timer);
}
