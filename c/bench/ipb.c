/* SPDX-License-Identifier: MIT OR Apache-2.0 */
/* Instructions per byte of the HW-FOC decoder (c/bench/ipb.sh runs it under cachegrind):
 *   ipb write DIR        writes DIR/clean.bin and DIR/noisy.bin (2 MiB each, made by the
 *                        header's encoders: data frames, an info frame after every 20; noisy:
 *                        ~30 % garbage runs of 1..64 random bytes, ~2 % flipped, ~2 % cut)
 *   ipb feed|push FILE   decodes FILE in 64 KiB feeds or a byte at a time
 *   ipb none FILE        reads FILE only (the baseline subtracted from the others' count) */
#define HWFOC_IMPLEMENTATION
#include "hwfoc.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LEN (2u << 20)
static uint8_t buf[LEN + 512];
static uint64_t rng = 0x9E3779B97F4A7C15ull;
static uint32_t next(void) {
    rng ^= rng >> 12; rng ^= rng << 25; rng ^= rng >> 27;
    return (uint32_t)((rng * 0x2545F4914F6CDD1Dull) >> 32);
}

static size_t make(int noisy) {
    size_t n = 0, k, m;
    uint16_t packet = 0;
    uint8_t frame[HWFOC_FOC_INFO_LEN], text[HWFOC_FOC_INFO_TEXT_LEN];
    hwfoc_foc_data d;
    memset(text, 'A', sizeof text);
    while (n < LEN) {
        if (noisy && next() % 100 < 30)
            for (k = 1 + next() % 64; k > 0 && n < LEN; k--) buf[n++] = (uint8_t)next();
        if (packet % 21 == 20) {
            hwfoc_foc_encode_info(text, frame);
            m = HWFOC_FOC_INFO_LEN;
        } else {
            memset(&d, 0, sizeof d);
            d.packet = packet; d.throttle_in_raw = (uint16_t)(next() % 1024); d.erpm_raw = (uint16_t)next();
            d.voltage_raw = (uint16_t)(next() % 600); d.mos_adc = (uint8_t)next();
            hwfoc_foc_encode_data(&d, frame);
            m = HWFOC_FOC_DATA_LEN;
        }
        packet++;
        if (noisy && next() % 100 < 2) frame[next() % m] ^= (uint8_t)(1u << (next() % 8));
        if (noisy && next() % 100 < 2) m = next() % m;
        if (n + m > LEN) break;
        memcpy(buf + n, frame, m);
        n += m;
    }
    return n;
}

static unsigned long frames;
static void on_frame(void *ctx, const hwfoc_foc_frame *f) { (void)ctx; (void)f; frames++; }

__attribute__((noinline)) void decode(const uint8_t *p, size_t n, int push) {
    static hwfoc_foc_decoder d;
    size_t i, c;
    hwfoc_foc_init(&d);
    if (push) for (i = 0; i < n; i++) hwfoc_foc_push(&d, p[i], on_frame, NULL);
    else for (i = 0; i < n; i += c) {
        c = n - i < 65536 ? n - i : 65536;
        hwfoc_foc_feed(&d, p + i, c, on_frame, NULL);
    }
    hwfoc_foc_flush(&d, on_frame, NULL);
}

int main(int argc, char **argv) {
    FILE *f;
    size_t n;
    char path[4096];
    int noisy;
    if (argc == 3 && !strcmp(argv[1], "write")) {
        for (noisy = 0; noisy < 2; noisy++) {
            snprintf(path, sizeof path, "%s/%s.bin", argv[2], noisy ? "noisy" : "clean");
            n = make(noisy);
            if (!(f = fopen(path, "wb")) || fwrite(buf, 1, n, f) != n || fclose(f)) { fprintf(stderr, "ipb: %s: cannot write\n", path); return 1; }
        }
        return 0;
    }
    if (argc != 3 || (strcmp(argv[1], "feed") && strcmp(argv[1], "push") && strcmp(argv[1], "none"))) { fprintf(stderr, "usage: ipb write DIR | ipb feed|push|none FILE\n"); return 2; }
    if (!(f = fopen(argv[2], "rb"))) { fprintf(stderr, "ipb: %s: cannot open\n", argv[2]); return 1; }
    n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    if (strcmp(argv[1], "none")) decode(buf, n, !strcmp(argv[1], "push"));
    printf("%zu bytes, %lu frames\n", n, frames);
    return 0;
}
