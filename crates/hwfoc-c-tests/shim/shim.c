/* SPDX-License-Identifier: MIT OR Apache-2.0 */
/* The C side of the differential test: each decoder of c/hwfoc.h behind one small interface
 * whose frames and statistics come out as flat lists of integers, laid out as
 * src/flat.rs lays out the Rust codec's. Test-only (it allocates). */
#define HWFOC_IMPLEMENTATION
#include "hwfoc.h"
#include "flat_out.h"

enum { FOC = 0, DL = 1, V3 = 2, V4 = 3, HW5 = 4 };

typedef struct shim {
    int format;
    union {
        hwfoc_foc_decoder foc;
        hwfoc_dl_decoder dl;
        hwfoc_v3_decoder v3;
        hwfoc_v4_decoder v4;
        hwfoc_hw5_decoder hw5;
    } d;
    flat_out o;
} shim;

static void put(shim *s, uint64_t v) {
    flat_put(&s->o, v);
}

static void put_seq(shim *s, const hwfoc_sequence *q, uint64_t none) {
    put(s, q->count); put(s, q->lost); put(s, q->duplicates); put(s, q->restarts); put(s, q->reordered);
    put(s, q->count ? q->last : none);
}

/* A chained scanner's counts and where its chain ends (V3 and V4). */
static void put_chain(shim *s, const hwfoc_chain_counts *c, int has_chain, uint64_t chain_end) {
    put(s, c->bytes); put(s, c->bytes_skipped); put(s, c->implausible); put(s, c->unconfirmed); put(s, c->syncs);
    put_seq(s, &c->counter, UINT64_MAX);
    put(s, has_chain ? chain_end : UINT64_MAX);
}

static void put_foc_data(shim *s, const hwfoc_foc_data *f) {
    put(s, f->packet); put(s, f->throttle_in_raw); put(s, f->throttle_out_raw); put(s, f->erpm_raw);
    put(s, f->voltage_raw); put(s, (uint16_t)f->current_raw); put(s, (uint16_t)f->phase_current_raw);
    put(s, f->mos_adc); put(s, f->cap_adc); put(s, f->status);
}

static void put_v4_info(shim *s, const hwfoc_v4_info *i) {
    put(s, i->full_scale); put(s, i->v1); put(s, i->v2); put(s, i->i1); put(s, i->i2); put(s, i->i3);
    put(s, i->t1); put(s, i->t2);
}

static void on_foc(void *ctx, const hwfoc_foc_frame *f) {
    shim *s = (shim *)ctx;
    size_t i;
    put(s, f->offset); put(s, (uint64_t)f->kind);
    if (f->kind == HWFOC_FOC_KIND_DATA) put_foc_data(s, &f->data);
    else for (i = 0; i < HWFOC_FOC_INFO_TEXT_LEN; i++) put(s, f->info_text[i]);
}

static void on_dl(void *ctx, const hwfoc_dl_frame *f) {
    shim *s = (shim *)ctx;
    unsigned ch;
    put(s, f->offset); put(s, f->counter); put(s, f->length_byte);
    put(s, f->empty_slots); put(s, f->bad_channels); put(s, f->duplicate_channels);
    for (ch = 0; ch < HWFOC_DL_CHANNELS; ch++) {
        put(s, f->present >> ch & 1u);
        if (f->present >> ch & 1u) put_foc_data(s, &f->slots[ch]);
    }
}

static void on_v3(void *ctx, const hwfoc_v3_frame *f) {
    shim *s = (shim *)ctx;
    put(s, f->offset); put(s, f->counter); put(s, f->throttle_in_raw); put(s, f->pwm_out_raw); put(s, f->period_us);
}

static void on_v4(void *ctx, const hwfoc_v4_frame *f) {
    shim *s = (shim *)ctx;
    const hwfoc_v4_data *d = &f->data;
    put(s, f->offset); put(s, (uint64_t)f->kind);
    if (f->kind == HWFOC_V4_KIND_DATA) {
        put(s, d->counter); put(s, d->throttle_in_raw); put(s, d->throttle_out_raw); put(s, d->erpm);
        put(s, d->voltage_adc); put(s, d->current_adc); put(s, d->temp_adc); put(s, d->temp2_adc);
        put(s, (uint64_t)f->has_info);
        if (f->has_info) put_v4_info(s, &f->info);
    } else {
        put_v4_info(s, &f->info);
    }
}

static void on_hw5(void *ctx, const hwfoc_hw5_frame *f) {
    shim *s = (shim *)ctx;
    put(s, f->offset); put(s, f->throttle); put(s, f->unknown[0]); put(s, f->unknown[1]); put(s, f->fault);
    put(s, f->erpm_raw); put(s, f->voltage_raw); put(s, f->current_raw); put(s, f->esc_temp);
    put(s, f->bec_temp); put(s, f->motor_temp); put(s, f->bec_voltage_raw); put(s, f->bec_current_raw);
}

shim *shim_new(int format) {
    shim *s = (shim *)calloc(1, sizeof *s);
    if (!s) return s;
    s->format = format;
    switch (format) {
    case FOC: hwfoc_foc_init(&s->d.foc); break;
    case DL: hwfoc_dl_init(&s->d.dl); break;
    case V3: hwfoc_v3_init(&s->d.v3); break;
    case V4: hwfoc_v4_init(&s->d.v4); break;
    default: hwfoc_hw5_init(&s->d.hw5); break;
    }
    return s;
}

void shim_free(shim *s) {
    if (s) free(s->o.out);
    free(s);
}

/* Feeds bytes (push: one at a time); op 1 flushes, op 2 tells of a silence of `max_frames`. */
void shim_feed(shim *s, const uint8_t *data, size_t n, int push) {
    size_t i;
    if (push) {
        for (i = 0; i < n; i++) {
            switch (s->format) {
            case FOC: hwfoc_foc_push(&s->d.foc, data[i], on_foc, s); break;
            case DL: hwfoc_dl_push(&s->d.dl, data[i], on_dl, s); break;
            case V3: hwfoc_v3_push(&s->d.v3, data[i], on_v3, s); break;
            case V4: hwfoc_v4_push(&s->d.v4, data[i], on_v4, s); break;
            default: hwfoc_hw5_push(&s->d.hw5, data[i], on_hw5, s); break;
            }
        }
        return;
    }
    switch (s->format) {
    case FOC: hwfoc_foc_feed(&s->d.foc, data, n, on_foc, s); break;
    case DL: hwfoc_dl_feed(&s->d.dl, data, n, on_dl, s); break;
    case V3: hwfoc_v3_feed(&s->d.v3, data, n, on_v3, s); break;
    case V4: hwfoc_v4_feed(&s->d.v4, data, n, on_v4, s); break;
    default: hwfoc_hw5_feed(&s->d.hw5, data, n, on_hw5, s); break;
    }
}

void shim_flush(shim *s) {
    switch (s->format) {
    case FOC: hwfoc_foc_flush(&s->d.foc, on_foc, s); break;
    case DL: hwfoc_dl_flush(&s->d.dl, on_dl, s); break;
    case V3: hwfoc_v3_flush(&s->d.v3, on_v3, s); break;
    case V4: hwfoc_v4_flush(&s->d.v4, on_v4, s); break;
    default: hwfoc_hw5_flush(&s->d.hw5, on_hw5, s); break;
    }
}

void shim_line_silent(shim *s, uint32_t max_frames) {
    switch (s->format) {
    case FOC: hwfoc_foc_line_silent(&s->d.foc, max_frames, on_foc, s); break;
    case DL: hwfoc_dl_line_silent(&s->d.dl, max_frames, on_dl, s); break;
    case V3: hwfoc_v3_line_silent(&s->d.v3, max_frames, on_v3, s); break;
    case V4: hwfoc_v4_line_silent(&s->d.v4, max_frames, on_v4, s); break;
    default: hwfoc_hw5_line_silent(&s->d.hw5, max_frames, on_hw5, s); break;
    }
}

/* The frames so far, flat (and forgets them): their count of integers, or -1 out of memory. */
long shim_take_frames(shim *s, const uint64_t **out) {
    return flat_take(&s->o, out);
}

/* The statistics, flat, after the frames' integers are taken. */
long shim_stats(shim *s, const uint64_t **out) {
    const uint64_t none = UINT64_MAX;
    unsigned i;
    s->o.len = 0;
    switch (s->format) {
    case FOC: {
        const hwfoc_foc_stats *t = &s->d.foc.stats;
        put(s, t->bytes); put(s, t->bytes_skipped); put(s, t->info_frames); put(s, t->checksum_failures);
        put_seq(s, &t->packets, none);
        break;
    }
    case DL: {
        const hwfoc_dl_stats *t = &s->d.dl.stats;
        put(s, t->bytes); put(s, t->bytes_skipped); put(s, t->crc_failures); put(s, t->bad_headers);
        put(s, t->length_bytes[0]); put(s, t->length_bytes[1]); put(s, t->bad_channels);
        put(s, t->duplicate_channels); put(s, t->empty_slots);
        put_seq(s, &t->counter, none);
        for (i = 0; i < HWFOC_DL_CHANNELS; i++) put_seq(s, &t->channels[i], none);
        break;
    }
    case V3: {
        const hwfoc_v3_stats *t = &s->d.v3.stats;
        put_chain(s, &t->counts, t->has_chain, t->chain_end);
        break;
    }
    case V4: {
        const hwfoc_v4_stats *t = &s->d.v4.stats;
        put_chain(s, &t->counts, t->has_chain, t->chain_end);
        put(s, t->info_frames); put(s, t->adoptions); put(s, t->disagreements); put(s, t->trailers);
        put(s, t->has_last_info);
        if (t->has_last_info) put_v4_info(s, &t->last_info);
        put(s, t->has_adopted);
        if (t->has_adopted) put_v4_info(s, &t->adopted);
        break;
    }
    default: {
        const hwfoc_hw5_stats *t = &s->d.hw5.stats;
        put(s, t->bytes); put(s, t->bytes_skipped);
        for (i = 0; i < HWFOC_HW5_KINDS; i++) put(s, t->frames[i]);
        put(s, t->crc_failures); put(s, t->bad_headers); put(s, t->unknown_types); put(s, t->out_of_range);
        break;
    }
    }
    return shim_take_frames(s, out);
}

static void get_foc_data(const uint64_t *p, hwfoc_foc_data *f) {
    f->packet = (uint16_t)p[0]; f->throttle_in_raw = (uint16_t)p[1]; f->throttle_out_raw = (uint16_t)p[2];
    f->erpm_raw = (uint16_t)p[3]; f->voltage_raw = (uint16_t)p[4]; f->current_raw = (int16_t)(uint16_t)p[5];
    f->phase_current_raw = (int16_t)(uint16_t)p[6]; f->mos_adc = (uint8_t)p[7]; f->cap_adc = (uint8_t)p[8];
    f->status = (uint16_t)p[9];
}

static void get_v4_info(const uint64_t *p, hwfoc_v4_info *i) {
    i->full_scale = (uint16_t)p[0]; i->v1 = (uint8_t)p[1]; i->v2 = (uint8_t)p[2]; i->i1 = (uint8_t)p[3];
    i->i2 = (uint8_t)p[4]; i->i3 = (uint8_t)p[5]; i->t1 = (uint8_t)p[6]; i->t2 = (uint8_t)p[7];
}

/* Encodes the frame whose flat form (as the callbacks above write it) is at `p`, with the
 * header's encoders; returns its length. `out` holds at least 160 bytes. */
size_t shim_encode(int format, const uint64_t *p, uint8_t *out) {
    size_t i;
    switch (format) {
    case FOC:
        if (p[1] == HWFOC_FOC_KIND_DATA) {
            hwfoc_foc_data f;
            get_foc_data(p + 2, &f);
            hwfoc_foc_encode_data(&f, out);
            return HWFOC_FOC_DATA_LEN;
        } else {
            uint8_t text[HWFOC_FOC_INFO_TEXT_LEN];
            for (i = 0; i < HWFOC_FOC_INFO_TEXT_LEN; i++) text[i] = (uint8_t)p[2 + i];
            hwfoc_foc_encode_info(text, out);
            return HWFOC_FOC_INFO_LEN;
        }
    case DL: {
        hwfoc_dl_frame f;
        const uint64_t *q = p + 6;
        unsigned ch;
        memset(&f, 0, sizeof f);
        f.counter = (uint16_t)p[1];
        f.length_byte = (uint8_t)p[2];
        for (ch = 0; ch < HWFOC_DL_CHANNELS; ch++) {
            if (*q++) {
                f.present = (uint8_t)(f.present | 1u << ch);
                get_foc_data(q, &f.slots[ch]);
                q += 10;
            }
        }
        hwfoc_dl_encode(&f, out);
        return HWFOC_DL_FRAME_LEN;
    }
    case V3: {
        hwfoc_v3_frame f;
        f.counter = (uint32_t)p[1]; f.throttle_in_raw = (uint16_t)p[2]; f.pwm_out_raw = (uint16_t)p[3];
        f.period_us = (uint16_t)p[4];
        hwfoc_v3_encode(&f, out);
        return HWFOC_V3_FRAME_LEN;
    }
    case V4:
        if (p[1] == HWFOC_V4_KIND_DATA) {
            hwfoc_v4_data f;
            f.counter = (uint32_t)p[2]; f.throttle_in_raw = (uint16_t)p[3]; f.throttle_out_raw = (uint16_t)p[4];
            f.erpm = (uint32_t)p[5]; f.voltage_adc = (uint16_t)p[6]; f.current_adc = (uint16_t)p[7];
            f.temp_adc = (uint16_t)p[8]; f.temp2_adc = (uint16_t)p[9];
            hwfoc_v4_encode_data(&f, out);
            return HWFOC_V4_DATA_LEN;
        } else {
            hwfoc_v4_info f;
            get_v4_info(p + 2, &f);
            hwfoc_v4_encode_info(&f, out);
            return HWFOC_V4_INFO_LEN;
        }
    default: {
        hwfoc_hw5_frame f;
        f.throttle = (uint8_t)p[1]; f.unknown[0] = (uint8_t)p[2]; f.unknown[1] = (uint8_t)p[3];
        f.fault = (uint8_t)p[4]; f.erpm_raw = (uint16_t)p[5]; f.voltage_raw = (uint16_t)p[6];
        f.current_raw = (uint16_t)p[7]; f.esc_temp = (uint8_t)p[8]; f.bec_temp = (uint8_t)p[9];
        f.motor_temp = (uint8_t)p[10]; f.bec_voltage_raw = (uint8_t)p[11]; f.bec_current_raw = (uint8_t)p[12];
        hwfoc_hw5_encode(&f, out);
        return HWFOC_HW5_TELEMETRY_LEN;
    }
    }
}

/* The header's DroneCAN payload codec: unpack `payload` as `type` into `fields` (returns the
 * count of fields, or -1), and pack `fields` (returns the payload's length). */
int shim_can_unpack(int type, const uint8_t *payload, size_t len, int32_t *fields) {
    if (hwfoc_can_unpack((hwfoc_can_type)type, payload, len, fields) != 0) return -1;
    return (int)hwfoc_can_fields((hwfoc_can_type)type);
}

size_t shim_can_pack(int type, const int32_t *fields, uint8_t *out) {
    return hwfoc_can_pack((hwfoc_can_type)type, fields, out);
}
