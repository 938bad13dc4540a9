// The packets of a pcapng file (Enhanced Packet Blocks), for the tests: data and timestamp.
// Little-endian sections only (what hwfoc writes); a test reads files it made itself.

/** `[{iface, tsUnits, data}]` in file order; `tsUnits` is the raw 64-bit timestamp as a BigInt. */
export function packets(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const out = [];
  for (let at = 0; at + 12 <= bytes.length;) {
    const type = view.getUint32(at, true);
    const len = view.getUint32(at + 4, true);
    if (len < 12 || at + len > bytes.length) throw new Error(`pcapng: bad block at ${at}`);
    if (type === 6) {
      const iface = view.getUint32(at + 8, true);
      const ts = (BigInt(view.getUint32(at + 12, true)) << 32n) | BigInt(view.getUint32(at + 16, true));
      const captured = view.getUint32(at + 20, true);
      out.push({ iface, tsUnits: ts, data: bytes.slice(at + 28, at + 28 + captured) });
    }
    at += len;
  }
  return out;
}

/** Every packet's data of interface `iface`, joined. */
export function joined(bytes, iface = 0) {
  const parts = packets(bytes).filter((p) => p.iface === iface).map((p) => p.data);
  const out = new Uint8Array(parts.reduce((n, p) => n + p.length, 0));
  let at = 0;
  for (const p of parts) { out.set(p, at); at += p.length; }
  return out;
}
