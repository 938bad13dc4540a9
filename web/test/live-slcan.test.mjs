// SLCAN: the open sequence the command sends, and an adapter's lines turned into the SocketCAN
// records the simulator writes to pcapng for the same bus.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { SlcanLines, bitrateCode, openSequence, recordOf } from '../src/live/slcan.js';
import { packets } from '../e2e/live/pcapng.js';
import { hwfocBin } from '../e2e/live/hwfoc-bin.js';
import { tempDir } from '../e2e/live/temp-dir.js';

test('the open sequence is the command\'s: \\rC\\r, S6\\r, O\\r at 500 kbit/s', () => {
  assert.equal(bitrateCode(500000), 6);
  assert.equal(bitrateCode(1000000), 8);
  assert.equal(bitrateCode(333000), null);
  assert.deepEqual(openSequence(6).map((b) => new TextDecoder().decode(b)), ['\rC\r', 'S6\r', 'O\r']);
});

test('lines that are not frames give no record; a split line is read whole', () => {
  const p = new SlcanLines();
  const enc = (s) => new TextEncoder().encode(s);
  assert.equal(p.push(enc('\r\x07z\rV1013\rt12')).length, 0);
  const r = p.push(enc('32AABB\r'));
  assert.deepEqual([...r], [0, 0, 0x01, 0x23, 2, 0, 0, 0, 0xaa, 0xbb, 0, 0, 0, 0, 0, 0]);
  assert.equal(recordOf('t1239'), null, 'length over 8');
  assert.equal(recordOf('T2000000010'), null, 'id over 29 bits');
  assert.equal(recordOf('t800'), null, 'id over 11 bits');
  assert.equal(p.push(enc(`T${'1'.repeat(60)}\r`)).length, 0, 'an overlong line');
  assert.equal(recordOf('t12320102EA60')[9], 0x02, 'a timestamp after the data is read past');
});

test('a simulated bus as an adapter sends it gives the pcapng records of the same bus',
  { skip: hwfocBin() ? false : 'needs hwfoc (cargo build, or HWFOC)' }, () => {
    const dir = tempDir('slcan-');
    const args = ['simulate', '--protocol', 'hw-can', '--escs', '2', '--duration', '3', '--no-config'];
    execFileSync(hwfocBin(), [...args, '-o', `${dir}/bus.log`], { stdio: 'ignore' });
    execFileSync(hwfocBin(), [...args, '-o', `${dir}/bus.pcapng`], { stdio: 'ignore' });
    // candump's `ID#DATA` as an SLCAN adapter reports it: T, 8 id digits, length, data.
    const lines = readFileSync(`${dir}/bus.log`, 'utf8').trim().split('\n').map((l) => {
      const [id, data] = l.split(' ')[2].split('#');
      return `T${id}${data.length / 2}${data}\r`;
    });
    const p = new SlcanLines();
    const text = new TextEncoder().encode(lines.join(''));
    const got = [];
    for (let i = 0; i < text.length; i += 7) got.push(...p.push(text.slice(i, i + 7)));
    const want = packets(readFileSync(`${dir}/bus.pcapng`)).flatMap((pk) => [...pk.data]);
    assert.ok(lines.length > 600, String(lines.length));
    assert.equal(got.length, want.length);
    assert.deepEqual(got, want);
  });

// The page as web/build.sh builds it (its src/hwfoc.js beside the WebAssembly glue in pkg/).
const wasmPath = fileURLToPath(new URL('../dist/pkg/hwfoc_web_bg.wasm', import.meta.url));

test('an SLCAN adapter\'s lines of a simulated bus decode to the records hwfoc decode gives',
  { skip: !hwfocBin() ? 'needs hwfoc (cargo build, or HWFOC)' : !existsSync(wasmPath) ? 'needs web/build.sh' : false }, async () => {
    const api = await import('../dist/src/hwfoc.js');
    await api.init(readFileSync(wasmPath));
    const dir = tempDir('slcan-');
    execFileSync(hwfocBin(), ['simulate', '--protocol', 'hw-can', '--escs', '2', '--duration', '3', '--no-config', '-o', `${dir}/bus.log`], { stdio: 'ignore' });
    const want = execFileSync(hwfocBin(), ['decode', '--no-config', `${dir}/bus.log`], { encoding: 'utf8' }).trim().split('\n').map((l) => JSON.parse(l));
    const lines = readFileSync(`${dir}/bus.log`, 'utf8').trim().split('\n');
    const session = new api.Session({ name: 'slcan:bus' });
    const p = new SlcanLines();
    for (const l of lines) {
      const [time, , frame] = l.split(' ');
      const [id, data] = frame.split('#');
      const records = p.push(new TextEncoder().encode(`T${id}${data.length / 2}${data}\r`));
      session.feed(records, Math.round(Number(time.slice(1, -1)) * 1e6));
    }
    const got = session.takeRecords();
    assert.equal(got.count, want.length);
    assert.ok(Math.abs(got.columns.voltage_v.at(-1) - want.at(-1).voltage_v) < 1e-4);
  });

test('an SLCAN adapter\'s lines read ten at a time give the link figures hwfoc summary gives',
  { skip: !hwfocBin() ? 'needs hwfoc (cargo build, or HWFOC)' : !existsSync(wasmPath) ? 'needs web/build.sh' : false }, async () => {
    const api = await import('../dist/src/hwfoc.js');
    await api.init(readFileSync(wasmPath));
    const dir = tempDir('slcan-');
    execFileSync(hwfocBin(), ['simulate', '--protocol', 'hw-can', '--escs', '2', '--duration', '4', '--no-config', '-o', `${dir}/bus.log`], { stdio: 'ignore' });
    const want = JSON.parse(execFileSync(hwfocBin(), ['summary', '--json', '--no-config', `${dir}/bus.log`], { encoding: 'utf8' }));
    const lines = readFileSync(`${dir}/bus.log`, 'utf8').trim().split('\n');
    const session = new api.Session({ name: 'slcan:bus' });
    const p = new SlcanLines();
    // A browser's reads hand on several lines at once: ten, at the time of the last.
    for (let i = 0; i < lines.length; i += 10) {
      const group = lines.slice(i, i + 10).map((l) => l.split(' '));
      const text = group.map(([, , frame]) => {
        const [id, data] = frame.split('#');
        return `T${id}${data.length / 2}${data}\r`;
      }).join('');
      const t = Number(group.at(-1)[0].slice(1, -1));
      session.feed(p.push(new TextEncoder().encode(text)), Math.round(t * 1e6));
    }
    session.finish();
    const got = session.summary().escs;
    assert.equal(got.length, want.escs.length);
    for (const [k, e] of want.escs.entries()) {
      assert.equal(got[k].frames, e.frames, `esc ${e.esc}'s frames`);
      assert.equal(got[k].link.lost_packets, e.link.lost_packets, `esc ${e.esc}'s lost packets`);
    }
  });
