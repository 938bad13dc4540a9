// Alarms latch as the monitor's do (monitor/alarms.rs tests): raised at the level, cleared
// only past the hysteresis, escalated once, bits held off for the hold time.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { Latch, Threshold, describeChange } from '../src/live/alarms.js';
import { Fleet, limitsFrom } from '../src/live/fleet.js';

test('a temperature warning is raised at 90 and cleared at 85, not before', () => {
  const th = new Threshold(90, 105, 5);
  const l = new Latch();
  assert.equal(l.update(th, 89.9, 0), null);
  assert.deepEqual(l.update(th, 90, 1), { kind: 'raised', level: 'warning' });
  assert.equal(l.update(th, 85.1, 2), null);
  assert.equal(l.level, 'warning');
  assert.deepEqual(l.update(th, 106, 3), { kind: 'escalated', level: 'critical' });
  assert.equal(l.update(th, 101, 4), null, 'easing back to warning is not news');
  const cleared = l.update(th, 84, 5.5);
  assert.equal(cleared.kind, 'cleared');
  assert.equal(cleared.level, 'critical');
  assert.equal(cleared.worst, 106);
  assert.equal(describeChange('mos_temp', cleared), 'mos_temp critical cleared after 4.5 s');
});

test('low voltage is bad when low', () => {
  const th = new Threshold(3.5 * 6, 3.3 * 6, 0.1 * 6, true);
  const l = new Latch();
  assert.equal(l.update(th, 22, 0), null);
  assert.equal(l.update(th, 20.9, 1).level, 'warning');
  assert.equal(l.update(th, 21.5, 2), null);
  assert.equal(l.update(th, 21.7, 3).kind, 'cleared');
});

test('a status bit clears only after it stayed off for the hold time', () => {
  const l = new Latch();
  assert.equal(l.set(true, 'critical', 0.5, 10).kind, 'raised');
  assert.equal(l.set(false, 'critical', 0.5, 10.2), null);
  assert.equal(l.set(true, 'critical', 0.5, 10.3), null);
  assert.equal(l.set(false, 'critical', 0.5, 10.7), null);
  assert.equal(l.set(false, 'critical', 0.5, 10.8).kind, 'cleared');
});

function records(rows) {
  const names = Object.keys(rows[0]);
  const columns = {};
  for (const n of names) columns[n] = n === 'faults' || n === 'protocol' ? rows.map((r) => r[n]) : Float64Array.from(rows, (r) => r[n] ?? NaN);
  return { count: rows.length, columns };
}

test('the fleet raises a fault, a temperature, a low voltage, stale and disconnected, once each', () => {
  const fleet = new Fleet(limitsFrom());
  const row = (t, extra = {}) => ({ esc: 0, t_s: t, protocol: 'hw-foc', voltage_v: 25.2, current_a: 10, mos_temp_c: 40, cap_temp_c: 30, faults: null, ...extra });
  fleet.addRecords(0, records([row(0), row(0.05, { faults: ['mos_overheat'] }), row(0.1, { faults: ['mos_overheat'], mos_temp_c: 95 })]), 0.1);
  const [e] = fleet.list();
  assert.equal(e.cells, 6, 'six cells from 25.2 V');
  assert.deepEqual(e.alarms().sort((x, y) => x.name.localeCompare(y.name)), [{ name: 'mos_overheat', level: 'critical' }, { name: 'mos_temp', level: 'warning' }]);
  fleet.addRecords(0, records([row(0.2, { voltage_v: 20.5 })]), 0.2);
  assert.equal(e.alarms().find((a) => a.name === 'low_voltage').level, 'warning');
  fleet.addRecords(0, records([row(1.0)]), 1.0);
  assert.ok(!e.alarms().some((a) => a.name === 'mos_overheat'), 'cleared after 0.5 s off');
  fleet.tick(2.5);
  assert.ok(e.alarms().some((a) => a.name === 'stale'));
  fleet.portLost(0, 3);
  assert.deepEqual(e.alarms().filter((a) => ['stale', 'disconnected'].includes(a.name)), [{ name: 'disconnected', level: 'critical' }]);
  fleet.portBack(0, 4);
  assert.ok(!e.alarms().some((a) => a.name === 'disconnected'));
  const texts = fleet.log.map((l) => l.text).reverse();
  assert.equal(texts.filter((t) => t === 'esc 0 mos_overheat critical raised').length, 1);
  assert.ok(texts.includes('esc 0 mos_overheat critical cleared after 0.9 s'), texts.join('\n'));
});

test('peaks, power and the summary energy since the last reset', () => {
  const fleet = new Fleet(limitsFrom());
  fleet.addRecords(0, records([{ esc: 0, t_s: 1, voltage_v: 24, current_a: 10, rpm: 5000 }, { esc: 0, t_s: 1.05, voltage_v: 23, current_a: 20, rpm: 4000 }]), 1.05);
  fleet.addRecords(1, records([{ esc: 0, t_s: 1, voltage_v: 24, current_a: -1, rpm: 100 }]), 1.05);
  const [a, b] = fleet.list();
  assert.equal([a.number, b.number].join(), '0,1');
  assert.equal(a.peaks.rpm, 5000);
  assert.equal(a.peaks.voltage_v, 23, 'voltage peak is its minimum');
  fleet.setSummary(0, { escs: [{ esc: 0, energy: { charge_mah: 3, energy_wh: 0.07 }, link: { lost_packets: 2 } }] });
  const t = fleet.totals();
  assert.equal(t.powerW, 460, 'regeneration counts as no power');
  assert.equal(t.mah, 3);
  fleet.resetPeaks();
  fleet.setSummary(0, { escs: [{ esc: 0, energy: { charge_mah: 5, energy_wh: 0.1 } }] });
  assert.equal(fleet.totals().mah, 2);
  assert.deepEqual(a.peaks, {});
});
