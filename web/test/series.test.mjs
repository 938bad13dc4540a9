import { test } from 'node:test';
import assert from 'node:assert/strict';
import { envelope, blocks, lowerBound, nearest, range, splitByEsc, timed, gather, hasValue } from '../src/files/series.js';
import { toCsv, float32Text, csvColumns } from '../src/files/csv.js';

test('envelope keeps each pixel column first, min, max and last', () => {
  const xs = [0, 0.1, 0.2, 0.3, 1.0, 1.5];
  const ys = [5, 1, 9, 4, 7, NaN];
  const env = envelope(xs, ys, 0, 2, 2);
  assert.deepEqual(Array.from(env.slice(0, 4)), [5, 1, 9, 4]);
  assert.deepEqual(Array.from(env.slice(4, 8)), [7, 7, 7, 7]);
});

test('envelope of an empty window is all NaN', () => {
  const env = envelope([0, 1], [1, 2], 5, 6, 3);
  assert.ok(env.every(Number.isNaN));
  assert.deepEqual(range(env).map(Number.isNaN), [true, true]);
});

test('envelope of a million samples keeps the extremes', () => {
  const n = 1_000_000;
  const xs = new Float64Array(n).map((_, i) => i);
  const ys = new Float32Array(n).map((_, i) => Math.sin(i / 1000));
  ys[123_456] = 50;
  ys[654_321] = -50;
  assert.deepEqual(range(envelope(xs, ys, 0, n, 800)), [-50, 50]);
});

test('the envelope from blocks keeps the extremes and the columns of the samples', () => {
  const n = 1_000_000;
  const xs = new Float64Array(n).map((_, i) => i);
  const ys = new Float32Array(n).map((_, i) => (i % 1000) / 10);
  ys[123_457] = 500;
  ys[654_321] = NaN;
  ys[654_322] = -500;
  const exact = envelope(xs, ys, 0, n, 100);
  const fast = envelope(xs, ys, 0, n, 100, blocks(ys));
  assert.deepEqual(range(fast), [-500, 500]);
  assert.deepEqual(Array.from(fast), Array.from(exact));
  // Zoomed in, too few samples per column for blocks: sample by sample.
  assert.deepEqual(
    Array.from(envelope(xs, ys, 1000, 2000, 100, blocks(ys))),
    Array.from(envelope(xs, ys, 1000, 2000, 100)),
  );
});

test('lowerBound and nearest', () => {
  const xs = [1, 2, 2, 4];
  assert.equal(lowerBound(xs, 2), 1);
  assert.equal(lowerBound(xs, 5), 4);
  assert.equal(nearest(xs, 3.1), 3);
  assert.equal(nearest(xs, 0), 0);
  assert.equal(nearest([], 1), -1);
});

test('splitByEsc and timed', () => {
  const records = { count: 5, columns: { esc: Uint8Array.of(0, 3, 0, 3, 0) } };
  const escs = splitByEsc(records);
  assert.deepEqual(escs.map((e) => [e.esc, Array.from(e.index)]), [[0, [0, 2, 4]], [3, [1, 3]]]);
  assert.equal(timed(Float64Array.of(1, 1, 2, 2, 3), escs), true);
  assert.equal(timed(Float64Array.of(1, 1, 0.5, 2, 3), escs), false);
  assert.equal(timed(Float64Array.of(NaN, NaN, NaN, NaN, NaN), escs), false);
  assert.deepEqual(Array.from(gather(Float32Array.of(9, 8, 7, 6, 5), escs[1].index)), [8, 6]);
});

test('toCsv writes nulls as empty cells, protocols by name, faults from the status', () => {
  const records = {
    protocols: ['hw-foc', 'datalink'],
    columns: {
      t_s: Float64Array.of(0.5, NaN),
      protocol: Uint8Array.of(0, 1),
      voltage_v: Float32Array.of(24.7, NaN),
      mos_temp_c: Float32Array.of(28, NaN),
      status: Float64Array.of(5, NaN),
    },
  };
  const names = csvColumns(records);
  assert.deepEqual(names, ['t_s', 'protocol', 'voltage_v', 'mos_temp_c', 'status', 'faults']);
  const faultNames = (p, s) => (p === 'hw-foc' && s === 5 ? ['a', 'c'] : ['?']);
  assert.equal(
    toCsv(records, names, [0, 1], faultNames),
    't_s,protocol,voltage_v,mos_temp_c,status,faults\n0.5,hw-foc,24.7,28.0,5,a|c\n,datalink,,,,\n',
  );
});

test('float32Text gives the shortest decimal of a float32', () => {
  assert.equal(float32Text(Math.fround(24.7)), '24.7');
  assert.equal(float32Text(Math.fround(-0.015625)), '-0.015625');
  assert.equal(float32Text(Math.fround(11428.5712890625)), '11428.571');
  // 61.9140625 exactly: a tie between 61.914062 and 61.914063, the even digit taken (as ryu).
  assert.equal(float32Text(Math.fround(61.9140625)), '61.914062');
  assert.equal(float32Text(0), '0');
});

import { View } from '../src/files/view.js';
import { formatTick, niceTicks } from '../src/files/chart.js';

test('View zooms about a point and stays inside the recording', () => {
  const v = new View(0, 100);
  v.zoom(50, 0.5);
  assert.deepEqual([v.x0, v.x1], [25, 75]);
  v.pan(-40);
  assert.deepEqual([v.x0, v.x1], [0, 50]);
  v.zoom(0, 10);
  assert.deepEqual([v.x0, v.x1], [0, 100]);
});

test('formatTick', () => {
  assert.equal(formatTick(12.34567), '12.35');
  assert.equal(formatTick(NaN), '');
  assert.equal(formatTick(2e7), '2.00e+7');
});

test('niceTicks', () => {
  assert.deepEqual(niceTicks(0, 10, 5), [0, 2, 4, 6, 8, 10]);
  assert.deepEqual(niceTicks(23.4, 24.9, 3), [23.5, 24, 24.5]);
  assert.deepEqual(niceTicks(1, 1, 3), []);
});

test('a column has a value unless every entry is NaN', () => {
  assert.equal(hasValue(new Float32Array([NaN, NaN, NaN])), false);
  assert.equal(hasValue(new Float64Array(0)), false);
  assert.equal(hasValue(new Float32Array([NaN, NaN, 0])), true);
  assert.equal(hasValue(new Uint8Array([0])), true);
});
