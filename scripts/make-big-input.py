#!/usr/bin/env python3
"""Write a large raw HW-FOC telemetry stream for benchmarks: `make-big-input.py OUT SIZE_MB`.

The stream is what a USB-UART adapter on an ESC's telemetry wire would record over a long run,
made with the standard library only:

- data frames (9B 16 01 02, big-endian fields, checksum = 16-bit sum of bytes 0..21 sent low byte
  first) whose values follow a throttle profile: idle, spin-ups, a long cruise, regenerative braking,
  temperatures rising and falling through the ADC table, a fault episode now and then;
- a device-information frame after every idle data frame, as a real ESC sends them;
- line noise: a few garbage bytes, a corrupted frame and a dropped frame per block.

One block holds exactly 65536 data frames (packet numbers 0..65535), so repeating it keeps the
packet numbers consecutive across the wrap: the decoder sees one long, continuous run. The block is
built once and written as many times as needed to reach SIZE_MB (MiB, rounded up to whole blocks).
"""

import math
import os
import struct
import sys

DATA = struct.Struct(">4sHHHHHhhBBH")
HEADER = bytes([0x9B, 0x16, 0x01, 0x02])


def data_frame(packet, thr_in, thr_out, erpm, volt, cur, phase, mos, cap, status):
    body = DATA.pack(HEADER, packet, thr_in, thr_out, erpm, volt, cur, phase, mos, cap, status)
    return body + struct.pack("<H", sum(body) & 0xFFFF)


def info_frame():
    text = b"XR_FOC_ESC HW577_KZ1_V1.1 XR-01.0.00 01040443".ljust(72, b" ")
    body = bytes([0x9B, 0x4C, 0x01, 0x01]) + text
    # The info frame's check byte: the low byte of the sum of bytes 0..75.
    return body + bytes([sum(body) & 0xFF])


def block():
    out = bytearray()
    info = info_frame()
    temp = 30.0
    for packet in range(65536):
        phase_of_run = (packet % 8192) / 8192.0
        idle = phase_of_run < 0.1
        if idle:
            throttle = 0.0
        elif phase_of_run < 0.3:
            throttle = (phase_of_run - 0.1) / 0.2 * 0.8
        elif phase_of_run < 0.8:
            throttle = 0.8 + 0.15 * math.sin(packet / 40.0)
        else:
            throttle = max(0.0, 0.8 - (phase_of_run - 0.8) / 0.2)
        thr = min(1024, int(throttle * 1024))
        erpm = int(throttle * 9000)
        cur = int(throttle * throttle * 60 * 64)
        if 0.8 <= phase_of_run < 0.85:
            cur = -int(5 * 64)  # regenerative braking
        volt = int(252 - throttle * 20 - (packet % 200) / 100)
        temp += (throttle * 0.02) - (temp - 30.0) * 0.0005
        # ADC code: about 206 at 28 degC, falling ~1.9 codes per degree (see the ADC table).
        mos = max(33, min(241, int(210 - (temp - 26) * 1.9)))
        cap = max(33, min(241, int(212 - (temp - 26) * 1.2)))
        status = 0x0040 if 4000 <= packet % 16384 < 4100 else 0
        frame = data_frame(packet, thr, thr, erpm, volt, cur, cur * 3 // 2, mos, cap, status)
        if packet % 20000 == 777:
            continue  # a dropped frame
        if packet % 20000 == 1234:
            bad = bytearray(frame)
            bad[9] ^= 0x10  # a bit error: checksum failure
            frame = bytes(bad)
        out += frame
        if idle and packet % 7 == 0:
            out += info
        if packet % 5000 == 99:
            out += bytes([0x00, 0x9B, 0x55, 0xFF, 0x9B, 0x16])  # garbage on the line
    return bytes(out)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.split("\n")[0])
    path, size_mb = sys.argv[1], float(sys.argv[2])
    chunk = block()
    target = int(size_mb * 1024 * 1024)
    with open(path, "wb") as f:
        written = 0
        while written < target:
            f.write(chunk)
            written += len(chunk)
    print(f"{path}: {written} bytes, {written // len(chunk)} blocks of {len(chunk)} bytes", file=sys.stderr)


if __name__ == "__main__":
    main()
