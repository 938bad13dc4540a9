// A fake `navigator.serial` for the browser tests, injected with `page.addInitScript`: each
// port feeds its chunks (`{at: ms from the first, b64}`) at their real pace once opened (as
// random bytes when opened at another rate than its `baud`), and keeps what it fed in `window.__fake.fed[i]` (base64 per chunk) so a test
// compares it with a recording, and what the page wrote to it in `__fake.written[i]`. `__fake.unplug(i)` / `plug(i)` act as pulling the adapter out
// and putting it back (the feed goes on from where it was); `__fake.refuseNext` makes the next
// requestPort fail as a user who chose nothing; `__fake.busy[i]` makes open fail as a port
// another program holds.

/** The function injected into the page (it runs there, so it names nothing of this module). */
export function installFakeSerial(ports) {
  const decode = (b64) => Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
  const serial = new EventTarget();
  const fake = { fed: ports.map(() => []), written: ports.map(() => ''), busy: ports.map(() => false), refuseNext: false, opened: [] };
  const fire = (type, port) => {
    const event = new Event(type);
    Object.defineProperty(event, 'target', { value: port });
    serial.dispatchEvent(event);
  };

  class FakePort extends EventTarget {
    constructor(index, spec) {
      super();
      this.index = index;
      this.spec = spec;
      this.chunks = spec.chunks.map((c) => ({ at: c.at, bytes: decode(c.b64) }));
      this.next = 0;
      this.readable = null;
      this.writable = null;
      this.present = true;
      this.clock = null;
    }

    getInfo() {
      return { usbVendorId: 0x1a86, usbProductId: 0x7520 + this.index };
    }

    async open({ baudRate }) {
      if (this.readable) throw new DOMException('The port is already open.', 'InvalidStateError');
      if (!this.present || fake.busy[this.index]) throw new DOMException('Failed to open serial port.', 'NetworkError');
      fake.opened.push({ port: this.index, baudRate, at: performance.now() });
      this.granted = true;
      const right = baudRate === this.spec.baud;
      // The feed's clock: chunk times from where the feed stands, at the real pace.
      const base = performance.now() - (this.next < this.chunks.length ? this.chunks[this.next].at : 0);
      let timer = null;
      this.readable = new ReadableStream({
        start: (controller) => {
          this.controller = controller;
          timer = setInterval(() => {
            const now = performance.now() - base;
            while (this.next < this.chunks.length && this.chunks[this.next].at <= now) {
              const bytes = this.chunks[this.next++].bytes;
              if (right) {
                fake.fed[this.index].push(btoa(String.fromCharCode(...bytes)));
                controller.enqueue(bytes.slice());
              } else {
                // Read at another rate, a UART makes line noise of the wire's edges.
                controller.enqueue(bytes.map(() => Math.floor(Math.random() * 256)));
              }
            }
          }, 5);
        },
        cancel: () => clearInterval(timer),
      });
      this.stopFeed = () => clearInterval(timer);
      this.writable = new WritableStream({
        write: (chunk) => { fake.written[this.index] += new TextDecoder().decode(chunk); },
      });
    }

    async close() {
      this.stopFeed?.();
      this.readable = null;
      this.writable = null;
    }

    unplug() {
      this.present = false;
      this.stopFeed?.();
      this.controller?.error(new DOMException('The device has been lost.', 'NetworkError'));
      this.readable = null;
      this.writable = null;
      fire('disconnect', this);
    }

    plug() {
      this.present = true;
      fire('connect', this);
    }
  }

  const all = ports.map((spec, i) => new FakePort(i, spec));
  // The chooser offers the first port not yet opened (one that failed to open is offered again).
  serial.requestPort = async () => {
    const port = all.find((p) => !p.granted);
    if (fake.refuseNext || !port) {
      fake.refuseNext = false;
      throw new DOMException('No port selected by the user.', 'NotFoundError');
    }
    return port;
  };
  serial.getPorts = async () => all.filter((p) => p.granted);
  fake.unplug = (i) => all[i].unplug();
  fake.plug = (i) => all[i].plug();
  fake.done = () => all.every((p) => p.next >= p.chunks.length);
  Object.defineProperty(navigator, 'serial', { value: serial, configurable: true });
  window.__fake = fake;
}
