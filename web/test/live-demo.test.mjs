// The demo replays records at their pace, their times moved to now, and starts over at the end.
import { test, mock } from 'node:test';
import assert from 'node:assert/strict';
import { replay } from '../src/live/demo.js';

test('records come when their time has come, shifted to now, over and over', () => {
  mock.timers.enable({ apis: ['setInterval'] });
  let clock = 1000;
  const got = [];
  const records = { count: 3, columns: { t_s: Float64Array.from([50, 50.1, 50.5]), rpm: Float32Array.from([1, 2, 3]) }, protocols: ['hw-foc'] };
  const stop = replay(records, (set) => got.push([...set.columns.rpm].join() + '@' + [...set.columns.t_s].map((t) => t.toFixed(1)).join()), { now: () => clock, every: 50 });
  const step = (s) => { clock += s; mock.timers.tick(50); };
  step(0);
  step(0.05);
  step(0.1);
  step(0.4);
  step(0.1);
  step(0.05);
  stop();
  mock.timers.reset();
  assert.deepEqual(got, ['1@1000.0', '2@1000.1', '3@1000.5', '1@1000.6']);
});
