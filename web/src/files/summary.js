// Per ESC, the figures `hwfoc summary --json` gives, shown as tables. Every figure's cell
// carries its place in the summary (data-key, relative to the ESC's object) and its value as
// JSON (data-value), so that the end-to-end test compares the page with the command.

import { formatTick } from './chart.js';

/** The figures shown above the field table: [label, key]. */
const FIGURES = [
  ['protocol', 'protocol'],
  ['data frames', 'frames'],
  ['info frames', 'info_frames'],
  ['duration, s', 'duration_s'],
  ['frame rate, Hz', 'frame_rate_hz'],
  ['delivery', 'link.delivery_ratio'],
  ['lost packets', 'link.lost_packets'],
  ['duplicate packets', 'link.duplicate_packets'],
  ['checksum failures', 'link.checksum_failures'],
  ['bytes skipped', 'link.bytes_skipped'],
  ['charge, mAh', 'energy.charge_mah'],
  ['energy, Wh', 'energy.energy_wh'],
  ['peak power, W', 'energy.peak_power_w'],
  ['mean power, W', 'energy.mean_power_w'],
  ['fault episodes', 'fault_episode_count'],
];

/**
 * The value at a dotted `key` of `object` (undefined where a part is missing).
 * @param {object} object
 * @param {string} key
 */
export function at(object, key) {
  return key.split('.').reduce((o, part) => (o == null ? undefined : o[part]), object);
}

/**
 * A figure as shown: numbers to 4 significant digits (the ratio as a percentage), null '-'.
 * @param {string} key
 * @param {unknown} value
 */
export function show(key, value) {
  if (value === null || value === undefined) return '-';
  if (typeof value !== 'number') return String(value);
  if (key === 'link.delivery_ratio') return `${(value * 100).toFixed(2)} %`;
  return Number.isInteger(value) ? String(value) : formatTick(value);
}

/**
 * A table cell holding one figure.
 * @param {Document} doc
 * @param {string} key
 * @param {unknown} value
 */
function figureCell(doc, key, value) {
  const td = doc.createElement('td');
  td.dataset.key = key;
  td.dataset.value = JSON.stringify(value ?? null);
  td.textContent = show(key, value);
  return td;
}

/**
 * The summary of one ESC as an element.
 * @param {Document} doc
 * @param {object} esc one entry of the summary's `escs`
 * @param {string} colour its line colour in the charts
 */
export function escSummary(doc, esc, colour) {
  const section = doc.createElement('section');
  section.className = 'esc-summary';
  section.dataset.esc = String(esc.esc);
  const h = doc.createElement('h3');
  h.textContent = `ESC ${esc.esc}`;
  h.style.borderColor = colour;
  section.append(h);

  const device = doc.createElement('p');
  device.className = 'device';
  const infos = esc.info ?? [];
  device.textContent = infos.length ? infos.map((i) => i.text).join('; ') : 'no device information';
  section.append(device);

  const table = doc.createElement('table');
  table.className = 'figures';
  for (const [label, key] of FIGURES) {
    const tr = doc.createElement('tr');
    const th = doc.createElement('th');
    th.textContent = label;
    tr.append(th, figureCell(doc, key, at(esc, key)));
    table.append(tr);
  }
  section.append(table);

  const fields = doc.createElement('table');
  fields.className = 'fields';
  const head = doc.createElement('tr');
  for (const label of ['field', 'min', 'max', 'mean', 'unit']) {
    const th = doc.createElement('th');
    th.textContent = label;
    head.append(th);
  }
  fields.append(head);
  for (const [name, f] of Object.entries(esc.fields ?? {})) {
    if (f.min === null && f.max === null && f.mean === null) continue;
    const tr = doc.createElement('tr');
    const th = doc.createElement('th');
    th.textContent = name;
    tr.append(th);
    for (const stat of ['min', 'max', 'mean']) {
      tr.append(figureCell(doc, `fields.${name}.${stat}`, f[stat]));
    }
    const unit = doc.createElement('td');
    unit.textContent = f.unit;
    tr.append(unit);
    fields.append(tr);
  }
  section.append(fields);

  const episodes = esc.fault_episodes ?? [];
  if (episodes.length) {
    const list = doc.createElement('ul');
    list.className = 'episodes';
    for (const e of episodes) {
      const li = doc.createElement('li');
      const when = e.start_t_s === null ? `frames ${e.start_frame}..${e.end_frame}` : `${show('', e.start_t_s)}..${show('', e.end_t_s)} s`;
      li.textContent = `${when}: ${e.faults.join(', ')} (${e.frames} frames${e.ongoing ? ', ongoing' : ''})`;
      list.append(li);
    }
    section.append(list);
  }
  return section;
}
