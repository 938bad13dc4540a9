/* SPDX-License-Identifier: MIT OR Apache-2.0 */
/* The HW-FOC decoder of c/hwfoc.h built with HWFOC_NO_FOC_INFO (data frames only), beside
 * shim.c's default build in the same test binary: its external names are renamed with a
 * noinfo_ prefix so that the two builds link together. Frames and statistics come out flat,
 * as shim.c's FOC ones (without info_frames). Test-only (it allocates). */
#define HWFOC_NO_FOC_INFO
#define HWFOC_NO_DATALINK
#define HWFOC_NO_V3
#define HWFOC_NO_V4
#define HWFOC_NO_HW5
#define HWFOC_NO_CAN
#define hwfoc_foc_fault_name noinfo_hwfoc_foc_fault_name
#define hwfoc_hw5_fault_name noinfo_hwfoc_hw5_fault_name
#define hwfoc_can_fields noinfo_hwfoc_can_fields
#define hwfoc_can_pack noinfo_hwfoc_can_pack
#define hwfoc_can_unpack noinfo_hwfoc_can_unpack
#define hwfoc_crc16_modbus noinfo_hwfoc_crc16_modbus
#define hwfoc_crc16_xmodem noinfo_hwfoc_crc16_xmodem
#define hwfoc_decivolts_mv noinfo_hwfoc_decivolts_mv
#define hwfoc_dl_encode noinfo_hwfoc_dl_encode
#define hwfoc_dl_esc_frames_in noinfo_hwfoc_dl_esc_frames_in
#define hwfoc_dl_feed noinfo_hwfoc_dl_feed
#define hwfoc_dl_flush noinfo_hwfoc_dl_flush
#define hwfoc_dl_init noinfo_hwfoc_dl_init
#define hwfoc_dl_line_silent noinfo_hwfoc_dl_line_silent
#define hwfoc_dl_push noinfo_hwfoc_dl_push
#define hwfoc_erpm_of_raw noinfo_hwfoc_erpm_of_raw
#define hwfoc_foc_current_a noinfo_hwfoc_foc_current_a
#define hwfoc_foc_current_ma noinfo_hwfoc_foc_current_ma
#define hwfoc_foc_encode_data noinfo_hwfoc_foc_encode_data
#define hwfoc_foc_encode_info noinfo_hwfoc_foc_encode_info
#define hwfoc_foc_feed noinfo_hwfoc_foc_feed
#define hwfoc_foc_flush noinfo_hwfoc_foc_flush
#define hwfoc_foc_init noinfo_hwfoc_foc_init
#define hwfoc_foc_line_silent noinfo_hwfoc_foc_line_silent
#define hwfoc_foc_push noinfo_hwfoc_foc_push
#define hwfoc_hw5_encode noinfo_hwfoc_hw5_encode
#define hwfoc_hw5_feed noinfo_hwfoc_hw5_feed
#define hwfoc_hw5_flush noinfo_hwfoc_hw5_flush
#define hwfoc_hw5_init noinfo_hwfoc_hw5_init
#define hwfoc_hw5_line_silent noinfo_hwfoc_hw5_line_silent
#define hwfoc_hw5_push noinfo_hwfoc_hw5_push
#define hwfoc_rpm noinfo_hwfoc_rpm
#define hwfoc_sequence_line_silent noinfo_hwfoc_sequence_line_silent
#define hwfoc_sequence_next noinfo_hwfoc_sequence_next
#define hwfoc_sum16 noinfo_hwfoc_sum16
#define hwfoc_temp_decidegrees noinfo_hwfoc_temp_decidegrees
#define hwfoc_throttle_centipct noinfo_hwfoc_throttle_centipct
#define hwfoc_v3_encode noinfo_hwfoc_v3_encode
#define hwfoc_v3_erpm noinfo_hwfoc_v3_erpm
#define hwfoc_v3_feed noinfo_hwfoc_v3_feed
#define hwfoc_v3_flush noinfo_hwfoc_v3_flush
#define hwfoc_v3_init noinfo_hwfoc_v3_init
#define hwfoc_v3_line_silent noinfo_hwfoc_v3_line_silent
#define hwfoc_v3_push noinfo_hwfoc_v3_push
#define hwfoc_v4_current_ma noinfo_hwfoc_v4_current_ma
#define hwfoc_v4_encode_data noinfo_hwfoc_v4_encode_data
#define hwfoc_v4_encode_info noinfo_hwfoc_v4_encode_info
#define hwfoc_v4_feed noinfo_hwfoc_v4_feed
#define hwfoc_v4_flush noinfo_hwfoc_v4_flush
#define hwfoc_v4_init noinfo_hwfoc_v4_init
#define hwfoc_v4_line_silent noinfo_hwfoc_v4_line_silent
#define hwfoc_v4_ntc_celsius noinfo_hwfoc_v4_ntc_celsius
#define hwfoc_v4_push noinfo_hwfoc_v4_push
#define hwfoc_v4_voltage_mv noinfo_hwfoc_v4_voltage_mv
#define hwfoc_v4_voltage_v noinfo_hwfoc_v4_voltage_v
#define HWFOC_IMPLEMENTATION
#include "hwfoc.h"
#include "flat_out.h"

typedef struct noinfo {
    hwfoc_foc_decoder d;
    flat_out o;
} noinfo;

static void put(noinfo *s, uint64_t v) {
    flat_put(&s->o, v);
}

static void on_frame(void *ctx, const hwfoc_foc_frame *f) {
    noinfo *s = (noinfo *)ctx;
    const hwfoc_foc_data *d = &f->data;
    put(s, f->offset); put(s, (uint64_t)f->kind);
    put(s, d->packet); put(s, d->throttle_in_raw); put(s, d->throttle_out_raw); put(s, d->erpm_raw);
    put(s, d->voltage_raw); put(s, (uint16_t)d->current_raw); put(s, (uint16_t)d->phase_current_raw);
    put(s, d->mos_adc); put(s, d->cap_adc); put(s, d->status);
}

/* sizeof(hwfoc_foc_decoder) in this build. */
size_t noinfo_state_size(void) { return sizeof(hwfoc_foc_decoder); }

noinfo *noinfo_new(void) {
    noinfo *s = (noinfo *)calloc(1, sizeof *s);
    if (s) hwfoc_foc_init(&s->d);
    return s;
}

void noinfo_free(noinfo *s) {
    if (s) free(s->o.out);
    free(s);
}

void noinfo_feed(noinfo *s, const uint8_t *data, size_t n, int push) {
    size_t i;
    if (push) for (i = 0; i < n; i++) hwfoc_foc_push(&s->d, data[i], on_frame, s);
    else hwfoc_foc_feed(&s->d, data, n, on_frame, s);
}

void noinfo_flush(noinfo *s) { hwfoc_foc_flush(&s->d, on_frame, s); }

void noinfo_line_silent(noinfo *s, uint32_t max_frames) { hwfoc_foc_line_silent(&s->d, max_frames, on_frame, s); }

/* The frames so far, flat (and forgets them): their count of integers, or -1 out of memory. */
long noinfo_take_frames(noinfo *s, const uint64_t **out) {
    return flat_take(&s->o, out);
}

/* The statistics, flat (bytes, bytes_skipped, checksum_failures, the packet sequence), after
 * the frames' integers are taken. */
long noinfo_stats(noinfo *s, const uint64_t **out) {
    const hwfoc_foc_stats *t = &s->d.stats;
    const hwfoc_sequence *q = &t->packets;
    s->o.len = 0;
    put(s, t->bytes); put(s, t->bytes_skipped); put(s, t->checksum_failures);
    put(s, q->count); put(s, q->lost); put(s, q->duplicates); put(s, q->restarts); put(s, q->reordered);
    put(s, q->count ? q->last : UINT64_MAX);
    return noinfo_take_frames(s, out);
}
