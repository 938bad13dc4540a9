// The packets of a pcapng file (Enhanced Packet Blocks), for the tests: interface, time and
// data. Little-endian sections only (what hwfoc writes); a test reads files it made itself.

/** `[{iface, t, data}]` in file order; `t` in seconds (the interface's `if_tsresol`). */
export function packets(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const out = [];
  const resolutions = [];
  for (let at = 0; at + 12 <= bytes.length;) {
    const type = view.getUint32(at, true);
    const len = view.getUint32(at + 4, true);
    if (len < 12 || at + len > bytes.length) throw new Error(`pcapng: bad block at ${at}`);
    if (type === 0x0a0d0d0a) resolutions.length = 0;
    if (type === 1) {
      let units = 1e6;
      for (let o = at + 16; o + 4 <= at + len - 4;) {
        const code = view.getUint16(o, true);
        const olen = view.getUint16(o + 2, true);
        if (code === 0) break;
        if (code === 9) {
          const v = view.getUint8(o + 4);
          units = v & 0x80 ? 2 ** (v & 0x7f) : 10 ** v;
        }
        o += 4 + Math.ceil(olen / 4) * 4;
      }
      resolutions.push(units);
    }
    if (type === 6) {
      const iface = view.getUint32(at + 8, true);
      const ts = (BigInt(view.getUint32(at + 12, true)) << 32n) | BigInt(view.getUint32(at + 16, true));
      const units = BigInt(resolutions[iface] ?? 1e6);
      const t = Number(ts / units) + Number(ts % units) / Number(units);
      const captured = view.getUint32(at + 20, true);
      out.push({ iface, t, data: bytes.slice(at + 28, at + 28 + captured) });
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
