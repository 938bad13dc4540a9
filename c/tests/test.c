/* SPDX-License-Identifier: MIT OR Apache-2.0 */
/* The C tests of hwfoc.h, run by c/test.sh under AddressSanitizer and UndefinedBehaviorSanitizer:
 * check values of the CRCs, every format's frames encoded, decoded byte by byte and in chunks,
 * random bytes in random chunkings (same frames and statistics however cut, nothing read out of
 * bounds), the golden vectors of c/tests/vectors.txt and the integer conversions. Exits 1 on the
 * first failure, naming it. (Equality with the Rust codec is crates/hwfoc-c-tests's test.) */
#define HWFOC_IMPLEMENTATION
#define HWFOC_FLOAT
#include "../hwfoc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures;
#define CHECK(cond)                                                                 \
    do {                                                                            \
        if (!(cond)) {                                                              \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
            failures++;                                                             \
        }                                                                           \
    } while (0)

static uint64_t rng_state = 0x2545F4914F6CDD1Dull;
static uint32_t rnd(void) {
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (uint32_t)((rng_state * 0x2545F4914F6CDD1Dull) >> 32);
}

/* ------------------------------------------------------------ what the callbacks keep */
typedef struct seen {
    size_t n;
    uint64_t offsets[4096];
    hwfoc_foc_data foc[4096];
    hwfoc_v3_frame v3[4096];
    hwfoc_v4_frame v4[4096];
    hwfoc_hw5_frame hw5[4096];
    uint16_t dl_counter[4096];
} seen;

static void on_foc(void *ctx, const hwfoc_foc_frame *f) {
    seen *s = (seen *)ctx;
    if (s->n < 4096) { s->offsets[s->n] = f->offset; if (f->kind == HWFOC_FOC_KIND_DATA) s->foc[s->n] = f->data; }
    s->n++;
}
static void on_dl(void *ctx, const hwfoc_dl_frame *f) {
    seen *s = (seen *)ctx;
    if (s->n < 4096) { s->offsets[s->n] = f->offset; s->dl_counter[s->n] = f->counter; }
    s->n++;
}
static void on_v3(void *ctx, const hwfoc_v3_frame *f) {
    seen *s = (seen *)ctx;
    if (s->n < 4096) { s->offsets[s->n] = f->offset; s->v3[s->n] = *f; }
    s->n++;
}
static void on_v4(void *ctx, const hwfoc_v4_frame *f) {
    seen *s = (seen *)ctx;
    if (s->n < 4096) { s->offsets[s->n] = f->offset; s->v4[s->n] = *f; }
    s->n++;
}
static void on_hw5(void *ctx, const hwfoc_hw5_frame *f) {
    seen *s = (seen *)ctx;
    if (s->n < 4096) { s->offsets[s->n] = f->offset; s->hw5[s->n] = *f; }
    s->n++;
}

/* Feeds `data` to a fresh decoder: whole (chunk 0), byte by byte (chunk 1), or in random chunks
 * (chunk 2), then flushes; the frames go to *s, the decoder's final state to *dec. */
#define FEED(PFX, DEC, CB)                                                              \
    static void feed_##PFX(const uint8_t *data, size_t n, int chunk, seen *s, DEC *d) { \
        size_t at = 0;                                                                  \
        memset(s, 0, sizeof *s);                                                        \
        hwfoc_##PFX##_init(d);                                                          \
        while (at < n) {                                                                \
            size_t k = chunk == 0 ? n - at : chunk == 1 ? 1 : 1 + rnd() % 200;          \
            if (k > n - at) k = n - at;                                                 \
            if (k == 1) hwfoc_##PFX##_push(d, data[at], CB, s);                         \
            else hwfoc_##PFX##_feed(d, data + at, k, CB, s);                            \
            at += k;                                                                    \
        }                                                                               \
        hwfoc_##PFX##_flush(d, CB, s);                                                  \
    }
FEED(foc, hwfoc_foc_decoder, on_foc)
FEED(dl, hwfoc_dl_decoder, on_dl)
FEED(v3, hwfoc_v3_decoder, on_v3)
FEED(v4, hwfoc_v4_decoder, on_v4)
FEED(hw5, hwfoc_hw5_decoder, on_hw5)

static seen a, b;

static void test_crcs(void) {
    const uint8_t digits[] = "123456789";
    CHECK(hwfoc_crc16_xmodem(digits, 9) == 0x31C3);
    CHECK(hwfoc_crc16_modbus(digits, 9) == 0x4B37);
    CHECK(hwfoc_crc16_modbus(digits, 0) == 0xFFFF);
    CHECK(hwfoc_sum16(digits, 9) == 0x01DD);
}

static uint8_t stream[65536];

/* Two adjacent frames swapped (5, 7, 6, 8) are one reordering, not two lost and a restart; a
 * gap of one that stays one is a loss; a silence between the gap and the number: no swap (the
 * Rust counters' two_adjacent_frames_swapped_are_a_reordering). */
static void test_sequence(void) {
    static const uint32_t first[] = {4, 5, 7, 6, 8, 9, 11, 12, 13, 65535, 1, 0, 2};
    static const uint32_t wide[] = {0xFFFFFE, 0, 0xFFFFFF, 1};
    hwfoc_sequence s, t, u;
    size_t i;
    memset(&s, 0, sizeof s);
    memset(&t, 0, sizeof t);
    memset(&u, 0, sizeof u);
    for (i = 0; i < 10; i++) hwfoc_sequence_next(&s, first[i], HWFOC_COUNTER16_MAX);
    CHECK(s.count == 10 && s.lost == 1 && s.restarts == 1 && s.duplicates == 0 && s.reordered == 1);
    for (; i < 13; i++) hwfoc_sequence_next(&s, first[i], HWFOC_COUNTER16_MAX); /* across the wrap */
    CHECK(s.lost == 1 && s.restarts == 1 && s.reordered == 2 && s.last == 2);
    for (i = 0; i < 4; i++) hwfoc_sequence_next(&t, wide[i], HWFOC_COUNTER24_MAX);
    CHECK(t.lost == 0 && t.restarts == 0 && t.reordered == 1);
    hwfoc_sequence_next(&u, 5, HWFOC_COUNTER16_MAX);
    hwfoc_sequence_next(&u, 7, HWFOC_COUNTER16_MAX);
    hwfoc_sequence_line_silent(&u, 3, HWFOC_COUNTER16_MAX);
    hwfoc_sequence_next(&u, 6, HWFOC_COUNTER16_MAX);
    CHECK(u.lost == 1 && u.restarts == 1 && u.reordered == 0);
}

static void test_foc(void) {
    hwfoc_foc_decoder d1, d2;
    hwfoc_foc_data f;
    size_t n = 0, i;
    uint8_t text[HWFOC_FOC_INFO_TEXT_LEN];
    memset(text, ' ', sizeof text);
    memcpy(text + 16, "XR_FOC_ESC", 10);
    hwfoc_foc_encode_info(text, stream);
    CHECK(stream[76] == (uint8_t)hwfoc_sum16(stream, 76));
    n = HWFOC_FOC_INFO_LEN;
    for (i = 0; i < 1000; i++) {
        memset(&f, 0, sizeof f);
        f.packet = (uint16_t)(i == 500 ? i + 3 : i); /* 3 lost, then a step back */
        f.erpm_raw = (uint16_t)rnd();
        f.current_raw = (int16_t)(uint16_t)rnd();
        f.status = (uint16_t)rnd();
        if (i == 800) f.throttle_out_raw = HWFOC_FOC_THROTTLE_MAX_RAW + 1u; /* checksum right, no frame */
        if (i == 801) f.throttle_in_raw = HWFOC_FOC_THROTTLE_MAX_RAW;       /* 100 %: a frame */
        hwfoc_foc_encode_data(&f, stream + n);
        n += HWFOC_FOC_DATA_LEN;
        if (i == 700) stream[n++] = HWFOC_SYNC; /* a stray sync byte */
    }
    feed_foc(stream, n, 1, &a, &d1);
    CHECK(a.n == 1000 && d1.stats.checksum_failures == 1);
    CHECK(d1.stats.info_frames == 1 && d1.stats.packets.count == 999);
    CHECK(d1.stats.packets.lost == 4 && d1.stats.packets.restarts == 1 && d1.stats.bytes_skipped == 25);
    CHECK(a.foc[999].packet == 999 && a.foc[801].throttle_in_raw == 1024 && a.offsets[1] == 77);
    feed_foc(stream, n, 2, &b, &d2);
    CHECK(b.n == a.n && memcmp(&d1.stats, &d2.stats, sizeof d1.stats) == 0);
    CHECK(memcmp(a.foc, b.foc, sizeof a.foc) == 0);
}

static void test_dl(void) {
    hwfoc_dl_decoder d1, d2;
    hwfoc_dl_frame f;
    size_t n = 0, i;
    memset(&f, 0, sizeof f);
    for (i = 0; i < 300; i++) {
        f.counter = (uint16_t)i;
        f.present = (uint8_t)rnd();
        f.length_byte = (uint8_t)(i % 2 ? HWFOC_DL_LENGTH_TOTAL : HWFOC_DL_LENGTH_COVERED);
        f.slots[3].packet = (uint16_t)i;
        f.slots[3].erpm_raw = 1;
        f.present |= 1u << 3;
        hwfoc_dl_encode(&f, stream + n);
        n += HWFOC_DL_FRAME_LEN;
    }
    feed_dl(stream, n, 1, &a, &d1);
    CHECK(a.n == 300 && a.dl_counter[299] == 299);
    CHECK(d1.stats.length_bytes[0] == 150 && d1.stats.length_bytes[1] == 150);
    CHECK(d1.stats.channels[3].count == 300 && d1.stats.channels[3].lost == 0);
    feed_dl(stream, n, 2, &b, &d2);
    CHECK(b.n == a.n && memcmp(&d1.stats, &d2.stats, sizeof d1.stats) == 0);
    CHECK(hwfoc_dl_esc_frames_in(0) == 0 && hwfoc_dl_esc_frames_in(1) == 2);
}

static void test_v3(void) {
    hwfoc_v3_decoder d1, d2;
    hwfoc_v3_frame f;
    size_t n = 0, i;
    memset(&f, 0, sizeof f);
    for (i = 0; i < 500; i++) {
        f.counter = (uint32_t)(0xFFFFF0u + i) & HWFOC_COUNTER24_MAX;
        f.throttle_in_raw = (uint16_t)(rnd() % 256);
        f.pwm_out_raw = (uint16_t)(rnd() % 256);
        f.period_us = (uint16_t)rnd();
        if (i == 250) continue; /* a frame cut out whole */
        hwfoc_v3_encode(&f, stream + n);
        n += HWFOC_V3_FRAME_LEN;
    }
    feed_v3(stream, n, 1, &a, &d1);
    CHECK(a.n == 499 && d1.stats.counts.counter.lost == 1 && d1.stats.counts.syncs == 1);
    feed_v3(stream, n, 2, &b, &d2);
    CHECK(b.n == a.n && memcmp(&d1.stats, &d2.stats, sizeof d1.stats) == 0);
    CHECK(hwfoc_v3_erpm(HWFOC_V3_PLACEHOLDER_PERIOD_US) == 0 && hwfoc_v3_erpm(6000) == 10000);
}

static void test_v4(void) {
    hwfoc_v4_decoder d1, d2;
    hwfoc_v4_data f;
    hwfoc_v4_info info = {800, 11, 65, 3, 4, 1, 0, 0};
    size_t n = 0, i;
    memset(&f, 0, sizeof f);
    for (i = 0; i < 400; i++) {
        if (i % 50 == 10) {
            hwfoc_v4_encode_info(&info, stream + n);
            n += HWFOC_V4_INFO_LEN;
        }
        f.counter = (uint32_t)i;
        f.throttle_in_raw = (uint16_t)(rnd() % 800);
        f.voltage_adc = (uint16_t)(rnd() % 4096);
        hwfoc_v4_encode_data(&f, stream + n);
        n += HWFOC_V4_DATA_LEN;
        stream[n++] = HWFOC_V4_TRAILER;
    }
    feed_v4(stream, n, 1, &a, &d1);
    CHECK(a.n == 408 && d1.stats.info_frames == 8 && d1.stats.adoptions == 1 && d1.stats.trailers == 400);
    CHECK(a.v4[407].kind == HWFOC_V4_KIND_DATA && a.v4[407].has_info && a.v4[407].info.full_scale == 800);
    feed_v4(stream, n, 2, &b, &d2);
    CHECK(b.n == a.n && memcmp(&d1.stats, &d2.stats, sizeof d1.stats) == 0);
}

static void test_hw5(void) {
    hwfoc_hw5_decoder d1, d2;
    hwfoc_hw5_frame f;
    size_t n = 0, i;
    memset(&f, 0, sizeof f);
    for (i = 0; i < 300; i++) {
        f.throttle = (uint8_t)(i == 250 ? HWFOC_HW5_THROTTLE_MAX_PCT + 1u : i % 101u);
        f.voltage_raw = (uint16_t)(i == 200 ? HWFOC_HW5_VOLTAGE_MAX_RAW + 1u : HWFOC_HW5_VOLTAGE_MAX_RAW);
        f.erpm_raw = (uint16_t)rnd();
        f.fault = (uint8_t)rnd();
        hwfoc_hw5_encode(&f, stream + n);
        if (i == 100) stream[n + 20] ^= 1; /* a CRC failure */
        n += HWFOC_HW5_TELEMETRY_LEN;
    }
    feed_hw5(stream, n, 1, &a, &d1);
    CHECK(a.n == 297 && d1.stats.crc_failures == 1 && d1.stats.frames[HWFOC_HW5_TELEMETRY] == 297);
    CHECK(d1.stats.out_of_range == 2 && d1.stats.bytes_skipped == 3u * HWFOC_HW5_TELEMETRY_LEN);
    CHECK(a.hw5[296].throttle == 299 % 101 && a.hw5[296].voltage_raw == HWFOC_HW5_VOLTAGE_MAX_RAW);
    feed_hw5(stream, n, 2, &b, &d2);
    CHECK(b.n == a.n && memcmp(&d1.stats, &d2.stats, sizeof d1.stats) == 0);
    CHECK(strcmp(hwfoc_hw5_fault_name(0), "motor_locked") == 0);
}

/* Random bytes biased towards the bytes the scanners look for, whole and in random chunks. */
static void test_noise(void) {
    static const uint8_t special[] = {0x9B, 0x16, 0x4C, 0x01, 0x02, 0x9E, 0xA0, 0xB9, 0x00, 0xFE, 0xFD, 0x03, 0x30, 0x5C, 0x17};
    hwfoc_foc_decoder f1, f2;
    hwfoc_dl_decoder l1, l2;
    hwfoc_v3_decoder t1, t2;
    hwfoc_v4_decoder q1, q2;
    hwfoc_hw5_decoder h1, h2;
    size_t n = sizeof stream, i;
    int round;
    for (round = 0; round < 8; round++) {
        for (i = 0; i < n; i++) stream[i] = rnd() % 2 ? special[rnd() % sizeof special] : (uint8_t)rnd();
        feed_foc(stream, n, 0, &a, &f1); feed_foc(stream, n, 2, &b, &f2);
        CHECK(a.n == b.n && memcmp(&f1.stats, &f2.stats, sizeof f1.stats) == 0 && f1.stats.bytes == n);
        feed_dl(stream, n, 0, &a, &l1); feed_dl(stream, n, 2, &b, &l2);
        CHECK(a.n == b.n && memcmp(&l1.stats, &l2.stats, sizeof l1.stats) == 0);
        feed_v3(stream, n, 0, &a, &t1); feed_v3(stream, n, 2, &b, &t2);
        CHECK(a.n == b.n && memcmp(&t1.stats, &t2.stats, sizeof t1.stats) == 0);
        feed_v4(stream, n, 0, &a, &q1); feed_v4(stream, n, 2, &b, &q2);
        CHECK(a.n == b.n && memcmp(&q1.stats, &q2.stats, sizeof q1.stats) == 0);
        feed_hw5(stream, n, 0, &a, &h1); feed_hw5(stream, n, 2, &b, &h2);
        CHECK(a.n == b.n && memcmp(&h1.stats, &h2.stats, sizeof h1.stats) == 0);
    }
}

/* DroneCAN payloads: a StatusMsg1 little-endian, EscStatus's 18-bit signed rpm across bytes. */
static void test_can(void) {
    int32_t in[HWFOC_CAN_MAX_FIELDS] = {0x1234, 500, 0x4000}, out[HWFOC_CAN_MAX_FIELDS];
    uint8_t p[HWFOC_CAN_MAX_PAYLOAD];
    CHECK(hwfoc_can_pack(HWFOC_CAN_STATUS_MSG1, in, p) == 6);
    CHECK(p[0] == 0x34 && p[1] == 0x12 && p[2] == 0xF4 && p[3] == 0x01 && p[5] == 0x40);
    CHECK(hwfoc_can_unpack(HWFOC_CAN_STATUS_MSG1, p, 6, out) == 0 && out[0] == 0x1234 && out[2] == 0x4000);
    CHECK(hwfoc_can_unpack(HWFOC_CAN_STATUS_MSG1, p, 5, out) == -1);
    in[0] = 7; in[1] = 0x3C00; in[2] = 0; in[3] = 0x5C00; in[4] = -1000; in[5] = 200; in[6] = 3;
    CHECK(hwfoc_can_pack(HWFOC_CAN_ESC_STATUS, in, p) == 14);
    CHECK(hwfoc_can_unpack(HWFOC_CAN_ESC_STATUS, p, 14, out) == 0 && out[4] == -1000 && out[5] == 127 && out[6] == 3);
    CHECK(hwfoc_can_fields(HWFOC_CAN_GET_MAJOR_CONFIG_RESPONSE) == 9 && hwfoc_can_fields(HWFOC_CAN_TYPES) == 0);
}

static void test_conversions(void) {
    int16_t dc = 0;
    CHECK(hwfoc_foc_current_ma(64) == 1000 && hwfoc_foc_current_ma(-1) == -15);
    CHECK(hwfoc_rpm(70000, 7, 1, 1) == 10000 && hwfoc_rpm(70000, 7, 5, 2) == 4000);
    CHECK(hwfoc_throttle_centipct(512, 1024) == 5000);
    CHECK(hwfoc_decivolts_mv(252) == 25200 && hwfoc_erpm_of_raw(700) == 7000);
    CHECK(hwfoc_temp_decidegrees(241, &dc) == 0 && dc == 0);
    CHECK(hwfoc_temp_decidegrees(33, &dc) == 0 && dc == 1290);
    CHECK(hwfoc_temp_decidegrees(242, &dc) == -1 && hwfoc_temp_decidegrees(32, &dc) == 1);
    CHECK(hwfoc_v4_voltage_mv(910, 8, 910) == 8000);
    CHECK(strcmp(hwfoc_foc_fault_name(2), "over_current") == 0);
}

/* ------------------------------------------------------------ golden vectors */
typedef struct vec_frames {
    size_t n, want;
    int found;
    hwfoc_foc_frame foc;
    hwfoc_dl_frame dl;
    hwfoc_v3_frame v3;
    hwfoc_v4_frame v4;
    hwfoc_hw5_frame hw5;
} vec_frames;
#define VEC_CB(PFX, T, FIELD)                                    \
    static void vec_##PFX(void *ctx, const T *f) {               \
        vec_frames *v = (vec_frames *)ctx;                       \
        if (v->n++ == v->want) { v->FIELD = *f; v->found = 1; } \
    }
VEC_CB(foc, hwfoc_foc_frame, foc)
VEC_CB(dl, hwfoc_dl_frame, dl)
VEC_CB(v3, hwfoc_v3_frame, v3)
VEC_CB(v4, hwfoc_v4_frame, v4)
VEC_CB(hw5, hwfoc_hw5_frame, hw5)

/* A field of an info frame's text, trimmed of spaces and NULs, into out. */
static void info_field(const uint8_t *text, size_t start, size_t end, char *out) {
    while (start < end && (text[start] == ' ' || text[start] == 0)) start++;
    while (end > start && (text[end - 1] == ' ' || text[end - 1] == 0)) end--;
    memcpy(out, text + start, end - start);
    out[end - start] = 0;
}

/* An HW-FOC record's key: 1 with its value in *v, 0 for an unknown key. */
static int foc_key(const hwfoc_foc_data *d, const char *key, long long *v) {
    int16_t dc = 0;
    if (!strcmp(key, "packet")) *v = d->packet;
    else if (!strcmp(key, "throttle_in_raw")) *v = d->throttle_in_raw;
    else if (!strcmp(key, "throttle_out_raw")) *v = d->throttle_out_raw;
    else if (!strcmp(key, "erpm_raw")) *v = d->erpm_raw;
    else if (!strcmp(key, "voltage_raw")) *v = d->voltage_raw;
    else if (!strcmp(key, "current_raw")) *v = d->current_raw;
    else if (!strcmp(key, "phase_current_raw")) *v = d->phase_current_raw;
    else if (!strcmp(key, "mos_adc")) *v = d->mos_adc;
    else if (!strcmp(key, "cap_adc")) *v = d->cap_adc;
    else if (!strcmp(key, "status")) *v = d->status;
    else if (!strcmp(key, "erpm")) *v = hwfoc_erpm_of_raw(d->erpm_raw);
    else if (!strcmp(key, "rpm")) *v = hwfoc_rpm(hwfoc_erpm_of_raw(d->erpm_raw), 7, 1, 1);
    else if (!strcmp(key, "mv")) *v = hwfoc_decivolts_mv(d->voltage_raw);
    else if (!strcmp(key, "current_ma")) *v = hwfoc_foc_current_ma(d->current_raw);
    else if (!strcmp(key, "phase_current_ma")) *v = hwfoc_foc_current_ma(d->phase_current_raw);
    else if (!strcmp(key, "throttle_centipct")) *v = hwfoc_throttle_centipct(d->throttle_in_raw, 1024);
    else if (!strcmp(key, "mos_dc")) { if (hwfoc_temp_decidegrees(d->mos_adc, &dc)) return 0; *v = dc; }
    else if (!strcmp(key, "cap_dc")) { if (hwfoc_temp_decidegrees(d->cap_adc, &dc)) return 0; *v = dc; }
    else return 0;
    return 1;
}

static int v4_info_key(const hwfoc_v4_info *i, const char *key, long long *v) {
    if (!strcmp(key, "full_scale")) *v = i->full_scale;
    else if (!strcmp(key, "v1")) *v = i->v1;
    else if (!strcmp(key, "v2")) *v = i->v2;
    else if (!strcmp(key, "i1")) *v = i->i1;
    else if (!strcmp(key, "i2")) *v = i->i2;
    else if (!strcmp(key, "i3")) *v = i->i3;
    else return 0;
    return 1;
}

/* The value of `key` in the frame found: 1 (and *v or text), 0 for a key the format lacks. */
static int vec_key(const char *format, const vec_frames *f, const char *key, long long *v, char *text) {
    if (!strcmp(format, "foc")) {
        const uint8_t *t = f->foc.info_text;
        if (f->foc.kind == HWFOC_FOC_KIND_DATA) return foc_key(&f->foc.data, key, v);
        if (!strcmp(key, "product")) info_field(t, 16, 32, text);
        else if (!strcmp(key, "hardware")) info_field(t, 32, 48, text);
        else if (!strcmp(key, "firmware")) info_field(t, 48, 64, text);
        else if (!strcmp(key, "id")) info_field(t, 64, 72, text);
        else return 0;
        return 2;
    }
    if (!strcmp(format, "datalink")) {
        unsigned ch;
        if (!strcmp(key, "counter")) *v = f->dl.counter;
        else if (!strcmp(key, "slots")) *v = f->dl.present;
        else if (key[0] == 'c' && key[1] == 'h' && key[2] >= '0' && key[2] <= '7' && key[3] == '.') {
            ch = (unsigned)(key[2] - '0');
            return ((unsigned)f->dl.present >> ch & 1u) && foc_key(&f->dl.slots[ch], key + 4, v);
        } else return 0;
        return 1;
    }
    if (!strcmp(format, "v3")) {
        const hwfoc_v3_frame *d = &f->v3;
        if (!strcmp(key, "counter")) *v = d->counter;
        else if (!strcmp(key, "throttle_in_raw")) *v = d->throttle_in_raw;
        else if (!strcmp(key, "pwm_out_raw")) *v = d->pwm_out_raw;
        else if (!strcmp(key, "period_us")) *v = d->period_us;
        else if (!strcmp(key, "erpm")) *v = hwfoc_v3_erpm(d->period_us);
        else if (!strcmp(key, "throttle_centipct")) *v = hwfoc_throttle_centipct(d->throttle_in_raw, HWFOC_V3_FULL_SCALE);
        else return 0;
        return 1;
    }
    if (!strcmp(format, "v4")) {
        const hwfoc_v4_frame *g = &f->v4;
        const hwfoc_v4_data *d = &g->data;
        unsigned full = g->has_info ? g->info.full_scale : HWFOC_V4_DEFAULT_FULL_SCALE;
        if (g->kind == HWFOC_V4_KIND_INFO) return v4_info_key(&g->info, key, v);
        if (!strcmp(key, "counter")) *v = d->counter;
        else if (!strcmp(key, "throttle_in_raw")) *v = d->throttle_in_raw;
        else if (!strcmp(key, "throttle_out_raw")) *v = d->throttle_out_raw;
        else if (!strcmp(key, "erpm")) *v = d->erpm;
        else if (!strcmp(key, "voltage_adc")) *v = d->voltage_adc;
        else if (!strcmp(key, "current_adc")) *v = d->current_adc;
        else if (!strcmp(key, "temp_adc")) *v = d->temp_adc;
        else if (!strcmp(key, "temp2_adc")) *v = d->temp2_adc;
        else if (!strcmp(key, "has_info")) *v = g->has_info;
        else if (!strcmp(key, "full_scale")) *v = full;
        else if (!strcmp(key, "mv"))
            *v = g->has_info ? hwfoc_v4_voltage_mv(d->voltage_adc, g->info.v1, (uint16_t)(g->info.v2 * 10u))
                             : hwfoc_v4_voltage_mv(d->voltage_adc, 8, 910);
        else if (!strcmp(key, "current_ma")) {
            if (!g->has_info || !g->info.i1) return 0;
            *v = hwfoc_v4_current_ma(d->current_adc, &g->info);
        } else if (!strcmp(key, "throttle_centipct")) *v = hwfoc_throttle_centipct(d->throttle_in_raw, full);
        else return 0;
        return 1;
    }
    if (!strcmp(format, "hw5")) {
        const hwfoc_hw5_frame *d = &f->hw5;
        if (!strcmp(key, "throttle")) *v = d->throttle;
        else if (!strcmp(key, "fault")) *v = d->fault;
        else if (!strcmp(key, "erpm_raw")) *v = d->erpm_raw;
        else if (!strcmp(key, "erpm")) *v = hwfoc_erpm_of_raw(d->erpm_raw);
        else if (!strcmp(key, "voltage_raw")) *v = d->voltage_raw;
        else if (!strcmp(key, "mv")) *v = hwfoc_decivolts_mv(d->voltage_raw);
        else if (!strcmp(key, "current_raw")) *v = d->current_raw;
        else if (!strcmp(key, "current_ma")) *v = hwfoc_decivolts_mv(d->current_raw); /* deciamps: x100 mA */
        else if (!strcmp(key, "esc_temp")) *v = d->esc_temp;
        else if (!strcmp(key, "bec_temp")) *v = d->bec_temp;
        else if (!strcmp(key, "motor_temp")) *v = d->motor_temp;
        else if (!strcmp(key, "bec_voltage_raw")) *v = d->bec_voltage_raw;
        else if (!strcmp(key, "bec_mv")) *v = hwfoc_decivolts_mv(d->bec_voltage_raw);
        else if (!strcmp(key, "bec_current_raw")) *v = d->bec_current_raw;
        else if (!strcmp(key, "bec_current_ma")) *v = hwfoc_decivolts_mv(d->bec_current_raw);
        else return 0;
        return 1;
    }
    return 0;
}

static uint8_t vec_bytes[1024];

/* Checks every vector of the file at `path`; returns the number of values checked. */
static int test_vectors(const char *path) {
    static char line[4096];
    int lineno = 0, values = 0;
    FILE *file = fopen(path, "r");
    if (!file) {
        fprintf(stderr, "%s: cannot open\n", path);
        failures++;
        return 0;
    }
    while (fgets(line, sizeof line, file)) {
        char *format, *hex, *word, *eq, text[80];
        size_t n = 0, k;
        vec_frames f;
        long long v = 0;
        lineno++;
        format = strtok(line, " \t\r\n");
        if (!format || format[0] == '#') continue;
        hex = strtok(NULL, " \t\r\n");
        for (k = 0; hex && hex[k] && hex[k + 1] && n < sizeof vec_bytes; k += 2) {
            unsigned byte;
            if (sscanf(hex + k, "%2x", &byte) != 1) break;
            vec_bytes[n++] = (uint8_t)byte;
        }
        memset(&f, 0, sizeof f);
        while ((word = strtok(NULL, " \t\r\n")) != NULL) {
            int got;
            if (!(eq = strchr(word, '='))) { fprintf(stderr, "%s:%d: %s\n", path, lineno, word); failures++; continue; }
            *eq++ = 0;
            if (!strcmp(word, "frame")) {
                static hwfoc_foc_decoder fd; static hwfoc_dl_decoder dd; static hwfoc_v3_decoder d3;
                static hwfoc_v4_decoder d4; static hwfoc_hw5_decoder d5;
                f.want = (size_t)atoi(eq);
                if (!strcmp(format, "foc")) { hwfoc_foc_init(&fd); hwfoc_foc_feed(&fd, vec_bytes, n, vec_foc, &f); hwfoc_foc_flush(&fd, vec_foc, &f); }
                else if (!strcmp(format, "datalink")) { hwfoc_dl_init(&dd); hwfoc_dl_feed(&dd, vec_bytes, n, vec_dl, &f); hwfoc_dl_flush(&dd, vec_dl, &f); }
                else if (!strcmp(format, "v3")) { hwfoc_v3_init(&d3); hwfoc_v3_feed(&d3, vec_bytes, n, vec_v3, &f); hwfoc_v3_flush(&d3, vec_v3, &f); }
                else if (!strcmp(format, "v4")) { hwfoc_v4_init(&d4); hwfoc_v4_feed(&d4, vec_bytes, n, vec_v4, &f); hwfoc_v4_flush(&d4, vec_v4, &f); }
                else if (!strcmp(format, "hw5")) { hwfoc_hw5_init(&d5); hwfoc_hw5_feed(&d5, vec_bytes, n, vec_hw5, &f); hwfoc_hw5_flush(&d5, vec_hw5, &f); }
                if (!f.found) { fprintf(stderr, "%s:%d: no frame %s of %s\n", path, lineno, eq, format); failures++; break; }
                continue;
            }
            got = vec_key(format, &f, word, &v, text);
            if (got == 0) { fprintf(stderr, "%s:%d: %s has no %s\n", path, lineno, format, word); failures++; }
            else if (got == 2 && strcmp(text, eq)) { fprintf(stderr, "%s:%d: %s is %s, not %s\n", path, lineno, word, text, eq); failures++; }
            else if (got == 1 && v != atoll(eq)) { fprintf(stderr, "%s:%d: %s is %lld, not %s\n", path, lineno, word, v, eq); failures++; }
            values++;
        }
    }
    fclose(file);
    return values;
}

int main(int argc, char **argv) {
    int values;
    test_crcs();
    test_sequence();
    test_foc();
    test_dl();
    test_v3();
    test_v4();
    test_hw5();
    test_noise();
    test_conversions();
    test_can();
    values = test_vectors(argc > 1 ? argv[1] : "vectors.txt");
    CHECK(values >= 100);
    if (failures) {
        fprintf(stderr, "hwfoc.h C tests: %d failures\n", failures);
        return 1;
    }
    printf("hwfoc.h C tests: ok (%d golden values)\n", values);
    return 0;
}
