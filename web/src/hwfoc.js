// The page's one API over the WebAssembly build of the workspace's crates (crates/hwfoc-web).
// Both modes use it: the files mode (src/files/) and the live mode (src/live/). Nothing is
// decoded in JavaScript: the bytes go to the same code as the command's.

import wasmInit, * as wasm from '../pkg/hwfoc_web.js';

let ready = null;

/**
 * Loads the WebAssembly module; every other call needs it done. `wasmSource` is for Node
 * (the .wasm's bytes); the page leaves it out and the module is fetched beside the glue.
 * @param {BufferSource | URL | string} [wasmSource]
 */
export async function init(wasmSource) {
  ready ??= wasmInit(wasmSource === undefined ? undefined : { module_or_path: wasmSource });
  await ready;
}

/**
 * The bytes of one stream (a serial port, or a file's contents), decoded as they come.
 */
export class Session {
  /**
   * @param {{protocol?: string, baud?: number, name?: string}} [options] `protocol` as
   *   `--protocol` names it (every format when left out), the port's `baud`, the stream's
   *   `name` (the port's or the file's, as notices name it).
   */
  constructor({ protocol, baud, name } = {}) {
    this.name = name ?? 'stream';
    this.baud = baud;
    this.inner = new wasm.WasmSession(protocol ?? undefined, this.name, baud ?? undefined);
  }

  /**
   * Decodes a chunk.
   * @param {Uint8Array} bytes
   * @param {number} [tMicros] receive time of the chunk's last byte (Unix microseconds);
   *   undefined for a file's bytes.
   */
  feed(bytes, tMicros) {
    this.inner.feed(bytes, tMicros ?? undefined);
  }

  /** Ends the stream: the frames held at its end are handed on. */
  finish() {
    this.inner.finish();
  }

  /**
   * The records decoded since the last call: `{count, columns, protocols}`, one typed array per
   * column of docs/RECORD-SCHEMA.md (a null as NaN); `protocol` holds places in `protocols`.
   */
  takeRecords() {
    return this.inner.takeRecords();
  }

  /** The summary of the bytes so far, as `hwfoc summary --json` prints it. */
  summary() {
    return this.inner.summary();
  }

  /** The notices so far, as the command's stderr lines. */
  notices() {
    return Array.from(this.inner.notices());
  }

  /** Frees the WebAssembly memory the session holds. */
  free() {
    this.inner.free();
  }
}

/**
 * A recording's records, summary and notices, its format told from its content as the command
 * tells it.
 * @param {string} name the file's name (notices name it)
 * @param {Uint8Array} bytes its content
 * @returns {{records: object, summary: object, notices: string[]}}
 */
export function openFile(name, bytes) {
  const opened = wasm.openFile(name, bytes);
  return { records: opened.records, summary: opened.summary, notices: Array.from(opened.notices) };
}

/**
 * The names of a status word's set fault bits, in bit order, as a record's `faults` gives them.
 * @param {string} protocol as `--protocol` names it (a record's `protocols[protocol]`)
 * @param {number} status the record's `status`
 * @returns {string[]}
 */
export function faultNames(protocol, status) {
  return Array.from(wasm.faultNames(protocol, status));
}

/**
 * A recording of a port's bytes with their receive times, as `hwfoc record` writes it.
 */
export class Recorder {
  /** @param {{port?: string, baud?: number}} [options] */
  constructor({ port, baud } = {}) {
    this.inner = new wasm.WasmRecorder(port ?? 'port', baud ?? 0);
  }

  /**
   * @param {Uint8Array} bytes a chunk as the port gave it
   * @param {number} tMicros its last byte's receive time (Unix microseconds)
   */
  add(bytes, tMicros) {
    this.inner.add(bytes, tMicros);
  }

  /** @returns {Uint8Array} the pcapng file */
  finish() {
    return this.inner.finish();
  }
}
