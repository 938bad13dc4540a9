// The live mode's defaults equal the command's: the alarm levels `hwfoc monitor --help`
// documents, and the port search and SLCAN constants of the Rust sources.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import * as limits from '../src/live/limits.js';
import { hwfocBin } from '../e2e/live/hwfoc-bin.js';

const repo = fileURLToPath(new URL('../../', import.meta.url));

test('alarm defaults equal hwfoc monitor --help', { skip: hwfocBin() ? false : 'needs hwfoc (cargo build, or HWFOC)' }, () => {
  const help = execFileSync(hwfocBin(), ['monitor', '--help'], { encoding: 'utf8' });
  const documented = {};
  for (const m of help.matchAll(/--([a-z-]+) <[A-Z]+>\s*\n\s+[^[]*?\[default: ([0-9.]+)\]/g)) {
    documented[m[1].replaceAll('-', '_')] = Number(m[2]);
  }
  for (const [key, value] of Object.entries(limits.ALARM_DEFAULTS)) {
    assert.equal(documented[key], value, `--${key.replaceAll('_', '-')}`);
  }
  assert.equal(Object.keys(limits.ALARM_DEFAULTS).length, 10);
});

function rust(path) {
  return readFileSync(`${repo}${path}`, 'utf8');
}

/** The text of those of `paths` that exist, joined (the I/O crates' modules move between crates). */
function sources(...paths) {
  return paths.filter((p) => existsSync(`${repo}${p}`)).map(rust).join('\n');
}

const SERIAL = ['crates/hwfoc-io/src/serial.rs', 'crates/hwfoc-records/src/serial.rs', 'crates/hwfoc-ports/src/serial.rs'];
const CAN = ['crates/hwfoc-io/src/can/bus.rs', 'crates/hwfoc-io/src/can/slcan.rs', 'crates/hwfoc-records/src/can/mod.rs',
  'crates/hwfoc-ports/src/can/bus.rs', 'crates/hwfoc-ports/src/can/slcan.rs', 'crates/hwfoc-ports/src/slcan.rs'];

test('port search constants equal the command\'s (serial.rs)', () => {
  const src = sources(...SERIAL);
  const rates = src.match(/pub const SEARCH_RATES: \[u32; \d+\] = \[([^\]]+)\]/)[1].split(',').map((s) => Number(s.trim().replaceAll('_', '')));
  assert.deepEqual([...limits.SEARCH_RATES], rates);
  const ms = (name) => Number(src.match(new RegExp(`pub const ${name}: Duration = Duration::from_millis\\((\\d+)\\)`))[1]);
  assert.equal(limits.SEARCH_BYTES_FOR_MS, ms('SEARCH_BYTES_FOR'));
  assert.equal(limits.SEARCH_SILENT_FOR_MS, ms('SEARCH_SILENT_FOR'));
  assert.equal(limits.RETRY_EVERY_MS, ms('RETRY_EVERY'));
  assert.equal(limits.SEARCH_LOCK_FRAMES, Number(src.match(/pub const SEARCH_LOCK_FRAMES: u32 = (\d+);/)[1]));
});

test('SLCAN constants equal the command\'s (can/)', () => {
  const slcan = sources(...CAN);
  const rates = slcan.match(/pub const BITRATES: \[u32; 9\] = \[([^\]]+)\]/)[1].split(',').filter((s) => s.trim()).map((s) => Number(s.trim().replaceAll('_', '')));
  assert.deepEqual([...limits.SLCAN_BITRATES], rates);
  const bus = slcan;
  assert.equal(limits.SLCAN_SERIAL_BAUD, Number(bus.match(/pub const SLCAN_BAUD: u32 = ([\d_]+);/)[1].replaceAll('_', '')));
  assert.equal(limits.DEFAULT_CAN_BITRATE, Number(bus.match(/pub const DEFAULT_BITRATE: u32 = ([\d_]+);/)[1].replaceAll('_', '')));
});

test('cell detection and fault levels equal the monitor', () => {
  const fleet = rust('crates/hwfoc-cli/src/commands/monitor/fleet.rs');
  assert.equal(limits.FULL_CELL_V, Number(fleet.match(/const FULL_CELL_V: f64 = ([\d.]+);/)[1]));
  // The monitor's fault levels are the codec's fault descriptions' severities (format.rs).
  const warnings = (path) => [...rust(path).matchAll(/FaultDescription::new\(\s*"([a-z0-9_]+)",\s*"[^"]*",\s*(Warning|Critical),?\s*\)/g)]
    .filter((m) => m[2] === 'Warning').map((m) => m[1]);
  assert.deepEqual(limits.WARNING_FAULTS['hw-foc'], warnings('crates/hwfoc/src/status.rs'));
  assert.deepEqual(limits.WARNING_FAULTS.hw5, warnings('crates/hwfoc/src/hw5/frame.rs'));
  assert.match(rust('crates/hwfoc/src/format.rs'), /pub const UNKNOWN: Severity = Severity::Warning;/);
  assert.equal(limits.faultLevel('hw-foc', 'mos_overheat'), 'critical');
  assert.equal(limits.faultLevel('datalink', 'throttle_signal_lost'), 'warning');
  assert.equal(limits.faultLevel('hw5', 'motor_locked'), 'critical');
});
