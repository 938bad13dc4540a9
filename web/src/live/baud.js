// The port search of `hwfoc monitor` (crates/hwfoc-io/src/serial.rs `Search`): a port opened
// without a rate is read at 19200 baud, then 115200, in turn, until the bytes read at one rate
// give frames. A rate is left after 1.5 s of bytes without a frame or 3 s without any byte, and
// kept once two frames of any format were decoded from its bytes. Each rate starts with a new
// decoder; bytes read at a rate that gave no frame are never handed on. Times are the caller's.

import { SEARCH_BYTES_FOR_MS, SEARCH_LOCK_FRAMES, SEARCH_RATES, SEARCH_SILENT_FOR_MS } from './limits.js';

/**
 * The search of one port. `newDecoder()` gives an object whose `feed(bytes)` returns how many
 * frames those bytes completed (a WebAssembly `Session`, see `sessionJudge`).
 */
export class BaudSearch {
  constructor(newDecoder, now) {
    this.newDecoder = newDecoder;
    this.index = 0;
    this.#start(now);
  }

  #start(now) {
    this.since = now;
    this.firstByte = null;
    this.bytesRead = 0;
    this.frames = 0;
    this.held = [];
    this.decoder = this.newDecoder();
  }

  /** The rate being tried. */
  get baud() {
    return SEARCH_RATES[this.index];
  }

  /** Whether the rate gave enough frames to be the port's. */
  get locked() {
    return this.frames >= SEARCH_LOCK_FRAMES;
  }

  /** Takes bytes read at the rate being tried at `now` (ms), held with `tMicros`; true once locked. */
  bytes(bytes, now, tMicros) {
    if (bytes.length === 0) return this.locked;
    this.firstByte ??= now;
    this.bytesRead += bytes.length;
    this.held.push({ bytes, tMicros });
    this.frames += this.decoder.feed(bytes);
    return this.locked;
  }

  /** Whether, at `now`, the next rate is to be tried. */
  due(now) {
    if (this.locked) return false;
    if (this.firstByte !== null) return now - this.firstByte >= SEARCH_BYTES_FOR_MS;
    return now - this.since >= SEARCH_SILENT_FOR_MS;
  }

  /** Starts the next rate at `now`: returns it and the bytes the rate left gave. */
  next(now) {
    const discarded = this.bytesRead;
    this.index = (this.index + 1) % SEARCH_RATES.length;
    this.#start(now);
    return { baud: this.baud, discarded };
  }

  /** Starts the rate being tried again (the port was reopened). */
  restart(now) {
    this.#start(now);
  }

  /** The chunks read at the locked rate, to be handed on, in order (then forgotten). */
  takeHeld() {
    const held = this.held;
    this.held = [];
    return held;
  }
}

/**
 * A decoder for the search over the WebAssembly API: a fresh Session, whose frames (data and
 * device information, as the command's search counts every frame the detector gives) are read
 * from its summary.
 */
export function sessionJudge(api) {
  return () => {
    const session = new api.Session({});
    let seen = 0;
    return {
      feed(bytes) {
        session.feed(bytes, undefined);
        session.takeRecords();
        const now = (session.summary()?.escs ?? []).reduce((n, e) => n + (e.frames ?? 0) + (e.info_frames ?? 0), 0);
        const found = now - seen;
        seen = now;
        return found;
      },
    };
  };
}
