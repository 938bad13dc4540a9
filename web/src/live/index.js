// The live mode: serial ports (or SLCAN adapters) through Web Serial, each decoded by its own
// WebAssembly session, shown on the monitor's dashboard; recording to pcapng; the demo.

import { Dashboard } from './dashboard.js';
import { el } from './dom.js';
import { DEMO_URL, replay } from './demo.js';
import { explain, hasWebSerial, noSerialNote } from './errors.js';
import { Fleet, limitsFrom } from './fleet.js';
import { DEFAULT_CAN_BITRATE, MAX_PORTS, SEARCH_RATES, SLCAN_BITRATES } from './limits.js';
import { LivePort } from './ports.js';
import { sessionJudge } from './baud.js';
import { downloadAll, startRecording } from './recording.js';

/** How often the dashboard is redrawn, ms. */
const RENDER_EVERY_MS = 250;
/** How often each session's summary (link counters, energy) is read, ms. */
const SUMMARY_EVERY_MS = 1000;


/** Mounts the live mode in `element`; `api` is web/src/hwfoc.js. Returns `unmount()`. */
export function mountLive(element, api, { serial = globalThis.navigator?.serial } = {}) {
  if (!document.querySelector('link[data-live-css]')) {
    document.head.append(el('link', { rel: 'stylesheet', href: new URL('./live.css', import.meta.url).href, 'data-live-css': '' }));
  }
  const fleet = new Fleet(limitsFrom(), { faultNames: api.faultNames });
  const ports = [];
  const sessions = new Map();
  let recording = null;
  let stopDemo = null;

  const message = el('p', { class: 'live-message', 'data-testid': 'live-message', role: 'status' });
  const say = (text) => { message.textContent = text; };
  const portList = el('ul', { class: 'live-ports', 'data-testid': 'port-status' });
  const baud = el('select', { 'aria-label': 'Baud rate' },
    el('option', { value: '' }, 'Baud: search'), ...SEARCH_RATES.map((b) => el('option', { value: String(b) }, `${b} baud`)));
  const bitrate = el('select', { 'aria-label': 'CAN bitrate' },
    ...SLCAN_BITRATES.map((b) => el('option', { value: String(b), selected: b === DEFAULT_CAN_BITRATE }, `${b / 1000} kbit/s`)));
  const addPort = el('button', { type: 'button', 'data-testid': 'add-port' }, 'Add port');
  const addCan = el('button', { type: 'button', 'data-testid': 'add-slcan' }, 'Add SLCAN adapter');
  const demo = el('button', { type: 'button', 'data-testid': 'demo' }, 'Demo');
  const record = el('button', { type: 'button', 'data-testid': 'record' }, 'Record');
  // The dashboard shows once there is an ESC to show.
  const board = el('div', { class: 'live-board', hidden: true });
  const dashboard = new Dashboard(board, { onResetPeaks: () => fleet.resetPeaks() });
  const bar = el('div', { class: 'live-bar' });
  element.replaceChildren(bar, message, portList, board);

  if (hasWebSerial()) {
    bar.append(addPort, baud, addCan, bitrate, record, demo);
  } else {
    bar.append(demo);
    say(noSerialNote());
  }

  // An SLCAN adapter's bus is read as `hwfoc decode slcan:PORT` reads it: every CAN protocol.
  function sessionOf(index, slcanBitrate, rate) {
    const name = slcanBitrate ? `slcan:${ports[index].name}` : ports[index].name;
    if (!sessions.has(index)) sessions.set(index, new api.Session({ baud: rate, name }));
    return sessions.get(index);
  }

  function showPorts() {
    portList.replaceChildren(...ports.map((p) => el('li', { class: p.state, 'data-state': p.state }, p.statusText ?? p.name)));
  }

  async function open(port, slcanBitrate) {
    if (ports.length >= MAX_PORTS) {
      say(`At most ${MAX_PORTS} ports: close one first.`);
      return;
    }
    const index = ports.length;
    const fixed = baud.value ? Number(baud.value) : null;
    const live = new LivePort(port, index, {
      baud: fixed,
      slcan: slcanBitrate ?? null,
      newDecoder: sessionJudge(api),
      onData: (bytes, tMicros, rate) => {
        const fresh = !sessions.has(index);
        sessionOf(index, slcanBitrate, rate).feed(bytes, tMicros);
        // A port's first frames are shown at once, not at the next redraw.
        if (fresh) setTimeout(refresh, 0);
        // An SLCAN adapter's frames are not serial bytes: a CAN bus is recorded by `hwfoc record slcan:PORT`.
        if (!slcanBitrate) recording?.add(index, live.name, rate, bytes, tMicros);
      },
      onStatus: (text, state) => {
        live.statusText = text;
        if (state === 'lost' || state === 'error') say(text);
        if (state === 'open' && message.textContent.includes(live.name)) say(`${live.name} is back.`);
        showPorts();
      },
      onLost: () => fleet.portLost(index, Date.now() / 1000),
      onBack: () => fleet.portBack(index, Date.now() / 1000),
    });
    ports.push(live);
    showPorts();
    if (!(await live.start())) {
      ports.pop();
      showPorts();
    }
  }

  addPort.addEventListener('click', () => choose(null));
  addCan.addEventListener('click', () => choose(Number(bitrate.value)));
  async function choose(slcanBitrate) {
    let port;
    try {
      port = await serial.requestPort();
    } catch (e) {
      say(explain(e, 'choose'));
      return;
    }
    if (ports.some((p) => p.port === port && p.state !== 'closed')) {
      say(`${ports.find((p) => p.port === port).name} is already open in this page.`);
      return;
    }
    say('');
    await open(port, slcanBitrate);
  }

  // A device plugged back in resumes the lost port that is the same object, else the first lost
  // one with its USB ids (Web Serial gives no serial number to tell two alike adapters apart).
  const onConnect = (event) => {
    const port = event.target ?? event.port;
    const lost = ports.find((p) => p.awaits(port) && p.port === port) ?? ports.find((p) => p.awaits(port));
    lost?.connected(port);
  };
  const onDisconnect = (event) => ports.forEach((p) => p.disconnected(event.target ?? event.port));
  serial?.addEventListener?.('connect', onConnect);
  serial?.addEventListener?.('disconnect', onDisconnect);

  record.addEventListener('click', () => {
    if (recording) {
      const files = recording.finish();
      recording = null;
      record.textContent = 'Record';
      downloadAll(files);
      say(`Recording saved: ${files.map((f) => f.name).join(', ')}.`);
    } else {
      try {
        recording = startRecording(api);
      } catch (e) {
        say(`Recording is not available: ${e?.message ?? e}.`);
        return;
      }
      record.textContent = '● Stop and download';
      say('Recording what the ports send.');
    }
  });

  demo.addEventListener('click', async () => {
    if (stopDemo) return;
    try {
      await api.init?.();
      const bytes = new Uint8Array(await (await fetch(DEMO_URL)).arrayBuffer());
      const { records, notices } = api.openFile('demo.pcapng', bytes);
      if (!records.count) throw new Error(`the bundled recording gave no frame (${notices.join('; ')})`);
      // The demo is a virtual port after the real ones.
      const index = MAX_PORTS;
      stopDemo = replay(records, (set, now) => fleet.addRecords(index, set, now));
      demo.disabled = true;
      say('Demo: a recording of two simulated ESCs, replayed in real time.');
    } catch (e) {
      say(`The demo could not start: ${e?.message ?? e}.`);
    }
  });

  function refresh() {
    const now = Date.now() / 1000;
    for (const [index, s] of sessions) fleet.addRecords(index, s.takeRecords(), now);
    fleet.tick(now);
    for (const e of fleet.escs.values()) e.state = ports[e.port]?.state;
    board.hidden = fleet.escs.size === 0;
    if (!board.hidden) dashboard.render(fleet, now);
  }

  const timers = [
    setInterval(refresh, RENDER_EVERY_MS),
    setInterval(() => {
      for (const [index, s] of sessions) fleet.setSummary(index, s.summary());
    }, SUMMARY_EVERY_MS),
  ];

  return async function unmount() {
    timers.forEach(clearInterval);
    stopDemo?.();
    serial?.removeEventListener?.('connect', onConnect);
    serial?.removeEventListener?.('disconnect', onDisconnect);
    await Promise.all(ports.map((p) => p.stop()));
  };
}

