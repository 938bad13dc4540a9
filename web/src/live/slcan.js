// SLCAN adapters (the Lawicel ASCII protocol), as crates/hwfoc-io/src/can/slcan.rs and
// can/bus.rs `open_slcan` drive them: the open sequence, and the adapter's received-frame lines
// turned into the 16-byte SocketCAN records a CAN session decodes
// (`CanFrame::to_socketcan_record`: big-endian id with the EFF/RTR flags, length, 3 pad bytes,
// 8 data bytes).

import { SLCAN_BITRATES } from './limits.js';

/** The `S` code of `bitrate` (bit/s), or null when SLCAN has none. */
export function bitrateCode(bitrate) {
  const i = SLCAN_BITRATES.indexOf(bitrate);
  return i < 0 ? null : i;
}

/**
 * The commands that set an adapter up, in the order the command sends them, each awaited:
 * an empty command and close (from whatever state), the bitrate, open.
 */
export function openSequence(code) {
  return ['\rC\r', `S${code}\r`, 'O\r'].map((s) => new TextEncoder().encode(s));
}

/** The command that closes the channel. */
export const CLOSE = new TextEncoder().encode('C\r');
/** The longest line an adapter sends (`T`, 8 id digits, length, 16 data digits, 4 timestamp). */
export const MAX_LINE = 30;
const CAN_EFF_FLAG = 0x80000000;
const CAN_RTR_FLAG = 0x40000000;
const BEL = 0x07;
const CR = 0x0d;

/** Reads an adapter's output in any pieces; gives SocketCAN records of the frames it received. */
export class SlcanLines {
  line = [];
  overlong = false;
  counts = { frames: 0, acks: 0, refused: 0, notUnderstood: 0 };

  /** The records (16 bytes each, concatenated) of the frames completed by `bytes`. */
  push(bytes) {
    const out = [];
    for (const b of bytes) {
      if (b === BEL) {
        this.counts.refused += 1;
        this.line = [];
      } else if (b === CR) {
        this.#end(out);
      } else if (this.line.length < MAX_LINE) {
        this.line.push(b);
      } else {
        this.overlong = true;
      }
    }
    const records = new Uint8Array(out.length * 16);
    out.forEach((r, i) => records.set(r, i * 16));
    return records;
  }

  #end(out) {
    const text = String.fromCharCode(...this.line);
    const overlong = this.overlong;
    this.line = [];
    this.overlong = false;
    if (text === '' || text === 'z' || text === 'Z') {
      this.counts.acks += 1;
      return;
    }
    const record = overlong ? null : recordOf(text);
    if (record) {
      this.counts.frames += 1;
      out.push(record);
    } else {
      this.counts.notUnderstood += 1;
    }
  }
}

/** The SocketCAN record of one SLCAN frame line (without its `\r`), or null. */
export function recordOf(text) {
  const kind = text[0];
  const extended = kind === 'T' || kind === 'R';
  const remote = kind === 'r' || kind === 'R';
  if (!'tTrR'.includes(kind) || text.length < 2) return null;
  const idDigits = extended ? 8 : 3;
  const hex = /^[0-9A-Fa-f]*$/;
  const idText = text.slice(1, 1 + idDigits);
  const lenText = text[1 + idDigits];
  if (idText.length !== idDigits || !hex.test(idText) || !/^[0-8]$/.test(lenText ?? '')) return null;
  const id = parseInt(idText, 16);
  if (id >= (extended ? 2 ** 29 : 2 ** 11)) return null;
  const len = Number(lenText);
  const rest = text.slice(2 + idDigits);
  const dataDigits = remote ? 0 : len * 2;
  // What follows the data: nothing, or a 4-digit millisecond timestamp.
  if (!hex.test(rest) || (rest.length !== dataDigits && rest.length !== dataDigits + 4)) return null;
  const record = new Uint8Array(16);
  const canId = (id | (extended ? CAN_EFF_FLAG : 0) | (remote ? CAN_RTR_FLAG : 0)) >>> 0;
  new DataView(record.buffer).setUint32(0, canId, false);
  record[4] = len;
  for (let i = 0; i < dataDigits / 2; i++) record[8 + i] = parseInt(rest.slice(2 * i, 2 * i + 2), 16);
  return record;
}
