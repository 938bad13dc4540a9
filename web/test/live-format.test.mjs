// The live table's numbers: a small negative reading is 0, never "-0.0" (issue 34's screenshots).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { fixed, format } from '../src/live/dashboard.js';

test('a reading that rounds to zero shows 0, a negative one keeps its sign', () => {
  assert.equal(format('current_a', -0.01), '0.0');
  assert.equal(format('current_a', -1.5), '-1.5');
  assert.equal(format('current_a', null), '–');
  assert.equal(format('rpm', -0.4), '0');
  // Power and the totals too.
  assert.equal(fixed(-0.3, 0), '0');
  assert.equal(fixed(12.5, 1), '12.5');
});
