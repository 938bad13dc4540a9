// The port search tries 19200 then 115200 as serial.rs `Search` does.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { BaudSearch } from '../src/live/baud.js';

/** A decoder that finds a frame in every chunk starting with 0xAA. */
const fake = () => ({ feed: (bytes) => (bytes[0] === 0xaa ? 1 : 0) });

test('a rate is left after 1.5 s of bytes without frames, or 3 s of silence', () => {
  const s = new BaudSearch(fake, 0);
  assert.equal(s.baud, 19200);
  assert.equal(s.due(2999), false);
  assert.equal(s.due(3000), true, 'silent for 3 s');
  assert.deepEqual(s.next(3000), { baud: 115200, discarded: 0 });
  s.bytes(new Uint8Array([1, 2, 3]), 3100, 1);
  assert.equal(s.due(4599), false);
  assert.equal(s.due(4600), true, 'garbage for 1.5 s');
  assert.deepEqual(s.next(4600), { baud: 19200, discarded: 3 });
});

test('two frames lock the rate, and the bytes held at it are handed on in order', () => {
  const s = new BaudSearch(fake, 0);
  assert.equal(s.bytes(new Uint8Array([0xaa, 1]), 10, 100), false);
  assert.equal(s.bytes(new Uint8Array([7]), 20, 200), false);
  assert.equal(s.bytes(new Uint8Array([0xaa, 2]), 30, 300), true);
  assert.equal(s.due(100000), false, 'a locked rate is kept');
  assert.deepEqual(s.takeHeld().map((c) => c.tMicros), [100, 200, 300]);
});

test('bytes read at a rate left never reach the next rate', () => {
  const s = new BaudSearch(fake, 0);
  s.bytes(new Uint8Array([0xaa]), 10, 1);
  s.next(2000);
  assert.deepEqual(s.takeHeld(), []);
  assert.equal(s.frames, 0);
});
