// The monitor's defaults, in one place: alarm levels (as `hwfoc monitor --help` documents them,
// crates/hwfoc-cli/src/commands/monitor/config.rs), the level of each fault bit (the severity
// of the codec's fault descriptions, crates/hwfoc/src/status.rs and hw5/frame.rs), the cell detection (monitor/fleet.rs) and the port search
// (crates/hwfoc-io/src/serial.rs). tests/unit/live-limits.test.js compares them with the command.

/** Alarm levels, by the name of their `hwfoc monitor` flag (`--mos-warning-c` is `mos_warning_c`). */
export const ALARM_DEFAULTS = Object.freeze({
  mos_warning_c: 90,
  mos_critical_c: 105,
  cap_warning_c: 85,
  cap_critical_c: 100,
  temp_hysteresis_c: 5,
  cell_warning_v: 3.5,
  cell_critical_v: 3.3,
  cell_hysteresis_v: 0.1,
  stale_after_s: 1,
  fault_hold_s: 0.5,
});

/** Highest plausible voltage of one LiPo cell: the cells are the first voltage / this, rounded up. */
export const FULL_CELL_V = 4.35;

/** Fault bits that are warnings (voltage limits, throttle signal, unassigned bits); every other is critical. */
export const WARNING_FAULTS = Object.freeze({
  'hw-foc': ['input_voltage_high', 'input_voltage_low', 'reserved_3', 'throttle_signal_lost',
    'throttle_not_zeroed', 'reserved_15'],
  hw5: ['throttle_not_zero_at_start', 'throttle_signal_lost', 'low_voltage', 'input_voltage_error'],
});

/** The level of a fault named `name` in a frame of `protocol` (DataLink carries HW-FOC's word). */
export function faultLevel(protocol, name) {
  const table = protocol === 'hw5' ? WARNING_FAULTS.hw5 : WARNING_FAULTS['hw-foc'];
  if (name.startsWith('unknown') || table.includes(name)) return 'warning';
  return 'critical';
}

/** The rates a port's baud search tries in turn: the ESCs' own wires, then DataLink hubs and HW5. */
export const SEARCH_RATES = Object.freeze([19200, 115200]);
/** Milliseconds of bytes at one rate without a frame before the next rate is tried. */
export const SEARCH_BYTES_FOR_MS = 1500;
/** Milliseconds without any byte before the next rate is tried. */
export const SEARCH_SILENT_FOR_MS = 3000;
/** Frames that lock a rate. */
export const SEARCH_LOCK_FRAMES = 2;
/** Milliseconds between attempts to reopen a lost port. */
export const RETRY_EVERY_MS = 500;

/** SLCAN's `S` codes: bitrates in bit/s by code (S0 = 10 kbit/s ... S8 = 1 Mbit/s). */
export const SLCAN_BITRATES = Object.freeze([10000, 20000, 50000, 100000, 125000, 250000, 500000,
  800000, 1000000]);
/** The bitrate of a Hobbywing DroneCAN bus as it leaves the factory. */
export const DEFAULT_CAN_BITRATE = 500000;
/** The rate an SLCAN adapter's serial side is opened at (USB adapters ignore it). */
export const SLCAN_SERIAL_BAUD = 115200;

/** The most ports the live page opens at once. */
export const MAX_PORTS = 16;
/** Seconds of history charted. */
export const CHART_SECONDS = 60;
