#!/usr/bin/env python3
"""Stand-ins for what a bridge writes to, for scripts/bench-bridge.sh: N pseudo-terminals (their
names printed one per line) and a UDP socket on 127.0.0.1:PORT, all read and discarded until
SIGTERM; then prints the bytes each received."""

import os
import pty
import select
import signal
import socket
import sys
import tty


def main():
    n, port = int(sys.argv[1]), int(sys.argv[2])
    masters, names = [], []
    for _ in range(n):
        m, s = pty.openpty()
        tty.setraw(s)
        masters.append((m, s))
        names.append(os.ttyname(s))
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", port))
    for name in names:
        print(name, flush=True)
    received = {name: 0 for name in names}
    received["udp"] = 0
    running = [True]
    signal.signal(signal.SIGTERM, lambda *_: running.__setitem__(0, False))
    fds = {m: name for (m, _), name in zip(masters, names)}
    while running[0]:
        try:
            ready = select.select(list(fds) + [sock], [], [], 0.2)[0]
        except InterruptedError:
            continue
        for fd in ready:
            if fd is sock:
                received["udp"] += len(sock.recv(65536))
            else:
                try:
                    received[fds[fd]] += len(os.read(fd, 65536))
                except OSError:
                    pass
    print(" ".join(f"{k}={v}" for k, v in received.items()), file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()
