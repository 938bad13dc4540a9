// Recording to pcapng: one WebAssembly Recorder per port (the pcapng `hwfoc record` writes),
// given every chunk exactly as the port sent it with its receive time, saved as downloads.

/** A recording of every port from now: `add(...)` each chunk, `finish()` the files. */
export function startRecording(api, stamp = new Date()) {
  const recorders = new Map();
  // A build without the recorder fails here, before any port's bytes are taken.
  new api.Recorder({ port: 'check', baud: 0 }).finish();
  const name = stamp.toISOString().replace(/[:.]/g, '-').replace(/-\d+Z$/, 'Z');
  return {
    add(index, port, baud, bytes, tMicros) {
      if (!recorders.has(index)) recorders.set(index, { port, recorder: new api.Recorder({ port, baud }) });
      recorders.get(index).recorder.add(bytes, tMicros);
    },
    /** The files: `{name, bytes}` per port that sent anything. */
    finish() {
      return [...recorders].map(([index, r]) => ({ name: `hwfoc-${name}-port${index + 1}.pcapng`, bytes: r.recorder.finish() }));
    },
  };
}

/** Offers each file as a download. */
export function downloadAll(files) {
  for (const f of files) {
    const url = URL.createObjectURL(new Blob([f.bytes], { type: 'application/vnd.tcpdump.pcap' }));
    const a = document.createElement('a');
    a.href = url;
    a.download = f.name;
    document.body.append(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(url), 10000);
  }
}
