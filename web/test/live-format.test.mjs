// The dashboard's numbers: a value that rounds to zero is shown without a sign.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { fixed, format } from '../src/live/dashboard.js';

test('a value that rounds to zero has no sign; others keep theirs', () => {
  assert.equal(format('current_a', -0.0), '0.0');
  assert.equal(format('current_a', -0.04), '0.0');
  assert.equal(format('current_a', -0.06), '-0.1');
  assert.equal(format('rpm', -0.4), '0');
  assert.equal(fixed(-0.3, 0), '0');
  assert.equal(fixed(12.345, 2), '12.35');
  assert.equal(format('voltage_v', null), '–');
});
