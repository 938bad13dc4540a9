// Recording: every chunk of every port goes to that port's recorder as it came, with its time.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startRecording } from '../src/live/recording.js';

/** A stand-in for the WebAssembly Recorder that keeps what it is given. */
class FakeRecorder {
  static made = [];
  constructor(options) {
    this.options = options;
    this.chunks = [];
    FakeRecorder.made.push(this);
  }
  add(bytes, tMicros) { this.chunks.push([[...bytes], tMicros]); }
  finish() { return Uint8Array.from(this.chunks.flatMap(([b]) => b)); }
}

test('one pcapng per port, each with its port\'s chunks in order and their times', () => {
  const recording = startRecording({ Recorder: FakeRecorder }, new Date('2026-11-28T17:00:00.123Z'));
  recording.add(0, 'port 1', 19200, new Uint8Array([1, 2]), 10);
  recording.add(2, 'port 3', 115200, new Uint8Array([9]), 11);
  recording.add(0, 'port 1', 19200, new Uint8Array([3]), 12);
  const files = recording.finish();
  assert.deepEqual(files.map((f) => f.name), ['hwfoc-2026-11-28T17-00-00Z-port1.pcapng', 'hwfoc-2026-11-28T17-00-00Z-port3.pcapng']);
  assert.deepEqual([...files[0].bytes], [1, 2, 3]);
  const port1 = FakeRecorder.made.find((r) => r.options.port === 'port 1');
  assert.deepEqual(port1.options, { port: 'port 1', baud: 19200 });
  assert.deepEqual(port1.chunks.map(([, t]) => t), [10, 12]);
});

test('a build without a recorder fails at the start, before any bytes', () => {
  const api = { Recorder: class { constructor() { throw new Error('no recorder in this build'); } } };
  assert.throws(() => startRecording(api), /no recorder/);
});
