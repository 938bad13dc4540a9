// One serial port (or SLCAN adapter) read through Web Serial: opened at its rate or searching
// for it (baud.js), every chunk handed on with its receive time, and reopened by itself when
// the adapter is plugged back in after being unplugged.

import { BaudSearch } from './baud.js';
import { explain, unpluggedNote } from './errors.js';
import { DEFAULT_CAN_BITRATE, RETRY_EVERY_MS, SLCAN_SERIAL_BAUD } from './limits.js';
import { CLOSE, SlcanLines, bitrateCode, openSequence } from './slcan.js';

/** How often a searching port checks whether to try the next rate, ms. */
const SEARCH_POLL_MS = 100;
/** How long an SLCAN adapter is given to answer each open command, ms. */
const SLCAN_ANSWER_MS = 200;

/** The receive time of now, Unix microseconds. */
export function nowMicros() {
  return Math.round((performance.timeOrigin + performance.now()) * 1000);
}

/** A readable name of a Web Serial port: its USB ids where the browser gives them. */
export function portName(port, index) {
  const info = port.getInfo?.() ?? {};
  const hex = (n) => n.toString(16).padStart(4, '0');
  if (info.usbVendorId !== undefined) return `port ${index + 1} (USB ${hex(info.usbVendorId)}:${hex(info.usbProductId ?? 0)})`;
  return `port ${index + 1}`;
}

/** Whether two Web Serial ports are the same device (the one that was unplugged, back). */
export function samePort(a, b) {
  if (a === b) return true;
  const x = a.getInfo?.() ?? {};
  const y = b.getInfo?.() ?? {};
  return x.usbVendorId !== undefined && x.usbVendorId === y.usbVendorId && x.usbProductId === y.usbProductId;
}

/**
 * A port being read. `options`: `baud` (a number, or null to search), `slcan` (a CAN bitrate:
 * the port is an SLCAN adapter), `newDecoder` (for the search), and the callbacks `onData(bytes,
 * tMicros, baud)` (bytes as the wire gave them at the port's rate; for SLCAN the 16-byte records
 * of the frames), `onStatus(text, state)` (state: 'searching', 'open', 'lost', 'error',
 * 'closed').
 */
export class LivePort {
  constructor(port, index, options) {
    this.port = port;
    this.index = index;
    this.name = portName(port, index);
    this.options = options;
    this.baud = options.slcan ? SLCAN_SERIAL_BAUD : options.baud;
    this.search = null;
    this.stopped = false;
    this.reader = null;
    this.state = 'closed';
    this.lostAt = null;
  }

  #status(text, state) {
    this.state = state;
    this.options.onStatus?.(text, state);
  }

  /** Opens the port and reads it until `stop()`; resolves false if it could not be opened at all. */
  async start() {
    const searching = !this.options.slcan && !this.options.baud;
    if (searching) this.search = new BaudSearch(this.options.newDecoder, performance.now());
    const rate = () => (this.search ? this.search.baud : this.baud);
    try {
      await this.port.open({ baudRate: rate(), bufferSize: 65536 });
    } catch (e) {
      this.#status(explain(e, 'open', this.name), 'error');
      return false;
    }
    this.loop = this.#run(rate);
    return true;
  }

  async #run(rate) {
    while (!this.stopped) {
      if (this.options.slcan) await this.#slcanOpen();
      this.#status(this.search ? `${this.name}: searching at ${rate()} baud` : `${this.name}: ${rate()} baud`,
        this.search ? 'searching' : 'open');
      const outcome = await this.#read();
      if (this.stopped) break;
      try { await this.port.close(); } catch { /* already closed by the unplug */ }
      if (outcome === 'next') {
        const { baud } = this.search.next(performance.now());
        this.options.onSearch?.(baud);
      } else {
        this.lostAt = Date.now();
        this.#status(unpluggedNote(this.name), 'lost');
        this.options.onLost?.();
        await this.#waitForReplug();
        if (this.stopped) break;
        this.search?.restart(performance.now());
        this.options.onBack?.();
      }
      if (!(await this.#reopen(rate()))) break;
    }
  }

  /** Reads until the port fails ('lost'), the search wants the next rate ('next') or stop. */
  async #read() {
    let timer = null;
    let outcome = 'lost';
    if (this.search) {
      timer = setInterval(() => {
        if (this.search && this.search.due(performance.now())) {
          outcome = 'next';
          this.reader?.cancel().catch(() => {});
        }
      }, SEARCH_POLL_MS);
    }
    const slcan = this.options.slcan ? new SlcanLines() : null;
    try {
      this.unplugged = false;
      while (this.port.readable && !this.stopped && !this.unplugged && outcome !== 'next') {
        this.reader = this.port.readable.getReader();
        try {
          for (;;) {
            const { value, done } = await this.reader.read();
            if (done) break;
            if (value?.length) this.#received(value, slcan);
          }
        } catch (e) {
          // A framing, parity, break or overrun error leaves the port readable: go on reading.
          if (!this.port.readable || e?.name === 'NetworkError') break;
        } finally {
          this.reader.releaseLock();
          this.reader = null;
        }
      }
    } finally {
      clearInterval(timer);
    }
    return this.stopped ? 'stopped' : outcome;
  }

  #received(bytes, slcan) {
    const t = nowMicros();
    if (slcan) {
      const records = slcan.push(bytes);
      if (records.length) this.options.onData(records, t, this.baud);
      return;
    }
    if (this.search) {
      if (!this.search.bytes(bytes, performance.now(), t)) return;
      const baud = this.search.baud;
      const held = this.search.takeHeld();
      this.search = null;
      this.baud = baud;
      this.#status(`${this.name}: found at ${baud} baud`, 'open');
      this.options.onFound?.(baud);
      for (const chunk of held) this.options.onData(chunk.bytes, chunk.tMicros, baud);
      return;
    }
    this.options.onData(bytes, t, this.baud);
  }

  async #slcanOpen() {
    const code = bitrateCode(this.options.slcan ?? DEFAULT_CAN_BITRATE);
    const writer = this.port.writable?.getWriter();
    if (!writer) return;
    try {
      for (const command of openSequence(code)) {
        await writer.write(command);
        await new Promise((r) => setTimeout(r, SLCAN_ANSWER_MS));
      }
    } catch { /* a lost port shows up on the read */ } finally {
      writer.releaseLock();
    }
  }

  #waitForReplug() {
    return new Promise((resolve) => {
      this.replugged = resolve;
    });
  }

  /** Whether this port is lost and waiting for `port` (itself, or a device with its USB ids). */
  awaits(port) {
    return this.state === 'lost' && samePort(this.port, port);
  }

  /** The browser says `port`, this port's device, was plugged in: reading resumes. */
  connected(port) {
    if (this.state !== 'lost') return;
    this.port = port;
    const resolve = this.replugged;
    this.replugged = null;
    resolve?.();
  }

  /** The browser says `port` was unplugged: if it is this very port, the read ends as lost. */
  disconnected(port) {
    if (this.port !== port) return;
    this.unplugged = true;
    this.reader?.cancel().catch(() => {});
  }

  async #reopen(baudRate) {
    for (let attempt = 0; !this.stopped; attempt++) {
      try {
        await this.port.open({ baudRate, bufferSize: 65536 });
        return true;
      } catch (e) {
        if (e?.name === 'InvalidStateError') return true;
        if (attempt > 20) {
          this.#status(explain(e, 'open', this.name), 'error');
          return false;
        }
        await new Promise((r) => setTimeout(r, RETRY_EVERY_MS));
      }
    }
    return false;
  }

  /** Stops reading and closes the port (an SLCAN adapter's channel closed first). */
  async stop() {
    this.stopped = true;
    this.replugged?.();
    await this.reader?.cancel().catch(() => {});
    if (this.options.slcan && this.port.writable) {
      const w = this.port.writable.getWriter();
      await w.write(CLOSE).catch(() => {});
      w.releaseLock();
    }
    await this.loop?.catch(() => {});
    await this.port.close().catch(() => {});
    this.#status(`${this.name}: closed`, 'closed');
  }
}
