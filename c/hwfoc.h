/* SPDX-License-Identifier: MIT OR Apache-2.0 */
/*
 * hwfoc.h - Hobbywing ESC telemetry decoders in one C99 header.
 *
 * The streaming decoders of the hwfoc Rust codec (crates/hwfoc), ported line for line and
 * proven equal to it by a differential test (crates/hwfoc-c-tests): the same frames and the
 * same statistics for the same bytes, fed in any chunking.
 *
 *   HW-FOC      hwfoc_foc_*   an ESC's own wire, 19200 baud: data and device-information frames
 *   DataLink    hwfoc_dl_*    the DataLink V2 hub, 115200 baud: eight ESCs per frame
 *   V3          hwfoc_v3_*    Hobbywing V3 (Platinum Pro V3), 19200 baud
 *   V4          hwfoc_v4_*    Hobbywing V4 (Platinum V4, XRotor V4), 19200 baud, info frame
 *   HW5         hwfoc_hw5_*   HW5 telemetry, 115200 baud, CRC-16/MODBUS
 *   DroneCAN    hwfoc_can_*   payloads of com.hobbywing.esc and the standard ESC messages, for
 *                             a driver with its own transfer layer (PX4's, ArduPilot's, libcanard)
 *
 * Use: in exactly one C file, `#define HWFOC_IMPLEMENTATION` before `#include "hwfoc.h"`.
 * Leave out formats with HWFOC_NO_FOC, HWFOC_NO_DATALINK, HWFOC_NO_V3, HWFOC_NO_V4,
 * HWFOC_NO_HW5, HWFOC_NO_CAN; HWFOC_NO_FOC_INFO makes the HW-FOC decoder read data frames only,
 * its whole state 64 B (info frames counted as skipped bytes, byte counts 32-bit); HWFOC_FLOAT
 * adds float helpers (the core has no floating point).
 *
 * Every decoder is a struct the caller owns (no allocation, no stdio, no globals), fed bytes
 * one at a time (`_push`, from a UART interrupt's queue) or in chunks (`_feed`); each frame
 * found is handed to a callback with its stream offset. `_flush` decides a frame cut short at
 * the end of a stream; `_line_silent` tells the decoder that the line was silent for a time in
 * which at most `max_frames` frames could have been sent (settles the held bytes and tightens
 * the loss count of the next packet number, as the Rust decoder's `line_silent`).
 */
#ifndef HWFOC_H
#define HWFOC_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------- shared */

/** First byte of every HW-FOC, DataLink, V3 and V4 frame. */
#define HWFOC_SYNC 0x9Bu
/** The largest step of a packet counter counted as a loss is HWFOC_MAX_PACKET_GAP + 1. */
#define HWFOC_MAX_PACKET_GAP 1000u
/** Largest value of a 16-bit and of a 24-bit packet counter. */
#define HWFOC_COUNTER16_MAX 0xFFFFu
#define HWFOC_COUNTER24_MAX 0xFFFFFFu

/** The numbers of one packet counter, followed step by step (the Rust `counters::Sequence`). */
typedef struct hwfoc_sequence {
    uint32_t count;      /**< numbers seen */
    uint32_t lost;       /**< numbers missing in gaps of at most the gap limit */
    uint32_t duplicates; /**< numbers equal to the one before */
    uint32_t restarts;   /**< steps backwards or beyond the gap limit */
    uint32_t reordered;  /**< the number a gap of one skipped, right after it (a swap: its loss taken back) */
    uint32_t last;       /**< the last number (valid when count > 0) */
    uint32_t gap_limit;  /**< set by a silence; 0: HWFOC_MAX_PACKET_GAP + 1; `max`: the same after a gap of one */
} hwfoc_sequence;

/** Takes the next number of a counter whose largest value is `max` (0xFFFF or 0xFFFFFF). */
void hwfoc_sequence_next(hwfoc_sequence *s, uint32_t number, uint32_t max);
/** The line was silent for a time in which at most `max_frames` numbers could have been sent. */
void hwfoc_sequence_line_silent(hwfoc_sequence *s, uint32_t max_frames, uint32_t max);

/** The 16-bit wrapping sum of `n` bytes (HW-FOC's checksum). */
uint16_t hwfoc_sum16(const uint8_t *p, size_t n);
/** CRC-16/XMODEM (DataLink V2's check; 0x31C3 for "123456789"). */
uint16_t hwfoc_crc16_xmodem(const uint8_t *p, size_t n);
/** CRC-16/MODBUS (HW5's check; 0x4B37 for "123456789"). */
uint16_t hwfoc_crc16_modbus(const uint8_t *p, size_t n);

/* ---------------------------------------------------------------- HW-FOC */
#if !defined(HWFOC_NO_FOC) || !defined(HWFOC_NO_DATALINK)
#define HWFOC_FOC_BAUD 19200u
#define HWFOC_FOC_DATA_LEN 24u
#define HWFOC_FOC_INFO_LEN 77u
#define HWFOC_FOC_INFO_TEXT_LEN 72u
/** The longest candidate the HW-FOC decoder holds: an info frame, or with HWFOC_NO_FOC_INFO a
 * data frame. */
#ifdef HWFOC_NO_FOC_INFO
#define HWFOC_FOC_MAX_LEN HWFOC_FOC_DATA_LEN
#else
#define HWFOC_FOC_MAX_LEN HWFOC_FOC_INFO_LEN
#endif
/** The largest throttle a data frame carries (100 %); a frame over it is counted a checksum failure. */
#define HWFOC_FOC_THROTTLE_MAX_RAW 1024u

/** An HW-FOC data frame's fields, raw (also a DataLink channel's record). */
typedef struct hwfoc_foc_data {
    uint16_t packet;
    uint16_t throttle_in_raw;  /**< 0..1024 = 0..100 % */
    uint16_t throttle_out_raw; /**< 0..1024 = 0..100 % */
    uint16_t erpm_raw;         /**< eRPM / 10 */
    uint16_t voltage_raw;      /**< volts * 10 */
    int16_t current_raw;       /**< amps * 64 */
    int16_t phase_current_raw; /**< amps * 64 */
    uint8_t mos_adc;           /**< temperature code (hwfoc_temp_decidegrees) */
    uint8_t cap_adc;
    uint16_t status; /**< fault bits (hwfoc_foc_fault_name) */
} hwfoc_foc_data;

/** The name of fault bit `bit` (0..15) of a data frame's status word, e.g. "over_current". */
const char *hwfoc_foc_fault_name(unsigned bit);
#endif

#ifndef HWFOC_NO_FOC

#define HWFOC_FOC_KIND_DATA 0
#define HWFOC_FOC_KIND_INFO 1

/** A frame found: a data frame, or a device-information frame's 72 ASCII text bytes. */
typedef struct hwfoc_foc_frame {
    uint64_t offset; /**< stream offset of its first byte */
    int kind;        /**< HWFOC_FOC_KIND_DATA or HWFOC_FOC_KIND_INFO */
    hwfoc_foc_data data;
#ifndef HWFOC_NO_FOC_INFO
    uint8_t info_text[HWFOC_FOC_INFO_TEXT_LEN]; /**< product 16..32, hardware 32..48, firmware 48..64, id 64..72 */
#endif
} hwfoc_foc_frame;

/** The HW-FOC decoder's byte counts: 64-bit, wrapping at 2^48 as in Rust; with
 * HWFOC_NO_FOC_INFO 32-bit, wrapping at 2^32 (frame offsets too: 25 days at 19200 baud). */
#ifdef HWFOC_NO_FOC_INFO
typedef uint32_t hwfoc_foc_count;
#else
typedef uint64_t hwfoc_foc_count;
#endif

/** The Rust `foc::Stats`. With HWFOC_NO_FOC_INFO (data frames only, the whole decoder in 64 B):
 * no info_frames; an info frame's bytes are counted in bytes_skipped, and checksum_failures
 * counts data-frame candidates only. */
typedef struct hwfoc_foc_stats {
    hwfoc_foc_count bytes;
    hwfoc_foc_count bytes_skipped;
#ifndef HWFOC_NO_FOC_INFO
    uint32_t info_frames;
#endif
    uint32_t checksum_failures;
    hwfoc_sequence packets; /**< data frames: count, lost, duplicates, restarts */
} hwfoc_foc_stats;

/** The decoder: caller-owned, zeroed by hwfoc_foc_init. */
typedef struct hwfoc_foc_decoder {
    hwfoc_foc_stats stats;
#ifdef HWFOC_NO_FOC_INFO
    /* The candidate held starts at `len`: its first byte, always the sync byte, is not stored
     * (the count of held bytes takes its place), so that the decoder takes 64 bytes. */
    uint8_t len;
    uint8_t held[HWFOC_FOC_MAX_LEN - 1u];
#else
    uint8_t held[HWFOC_FOC_MAX_LEN];
    uint8_t len;
#endif
} hwfoc_foc_decoder;

typedef void (*hwfoc_foc_cb)(void *ctx, const hwfoc_foc_frame *frame);

void hwfoc_foc_init(hwfoc_foc_decoder *d);
void hwfoc_foc_feed(hwfoc_foc_decoder *d, const uint8_t *data, size_t n, hwfoc_foc_cb cb, void *ctx);
void hwfoc_foc_push(hwfoc_foc_decoder *d, uint8_t byte, hwfoc_foc_cb cb, void *ctx);
void hwfoc_foc_flush(hwfoc_foc_decoder *d, hwfoc_foc_cb cb, void *ctx);
void hwfoc_foc_line_silent(hwfoc_foc_decoder *d, uint32_t max_frames, hwfoc_foc_cb cb, void *ctx);
/** Writes the 24 bytes of a data frame. */
void hwfoc_foc_encode_data(const hwfoc_foc_data *f, uint8_t out[HWFOC_FOC_DATA_LEN]);
/** Writes the 77 bytes of a device-information frame carrying these 72 text bytes. */
void hwfoc_foc_encode_info(const uint8_t text[HWFOC_FOC_INFO_TEXT_LEN], uint8_t out[HWFOC_FOC_INFO_LEN]);
#endif

/* ---------------------------------------------------------------- DataLink V2 */
#ifndef HWFOC_NO_DATALINK
#define HWFOC_DL_BAUD 115200u
#define HWFOC_DL_FRAME_LEN 160u
#define HWFOC_DL_CHANNELS 8u
#define HWFOC_DL_LENGTH_COVERED 0x9Eu
#define HWFOC_DL_LENGTH_TOTAL 0xA0u

/** A hub frame: up to eight ESC records (slot i present when bit i of `present` is set). */
typedef struct hwfoc_dl_frame {
    uint64_t offset;
    uint16_t counter;
    uint8_t present;
    uint8_t length_byte; /**< HWFOC_DL_LENGTH_COVERED or _TOTAL */
    uint8_t empty_slots;
    uint8_t bad_channels;
    uint8_t duplicate_channels;
    hwfoc_foc_data slots[HWFOC_DL_CHANNELS];
} hwfoc_dl_frame;

/** The Rust `datalink::Stats`. */
typedef struct hwfoc_dl_stats {
    uint64_t bytes;
    uint64_t bytes_skipped;
    uint32_t crc_failures;
    uint32_t bad_headers;
    uint32_t length_bytes[2]; /**< frames with 0x9E, with 0xA0 */
    uint32_t bad_channels;
    uint32_t duplicate_channels;
    uint32_t empty_slots;
    hwfoc_sequence counter;
    hwfoc_sequence channels[HWFOC_DL_CHANNELS];
} hwfoc_dl_stats;

typedef struct hwfoc_dl_decoder {
    hwfoc_dl_stats stats;
    uint8_t held[HWFOC_DL_FRAME_LEN];
    uint8_t len;
} hwfoc_dl_decoder;

typedef void (*hwfoc_dl_cb)(void *ctx, const hwfoc_dl_frame *frame);

void hwfoc_dl_init(hwfoc_dl_decoder *d);
void hwfoc_dl_feed(hwfoc_dl_decoder *d, const uint8_t *data, size_t n, hwfoc_dl_cb cb, void *ctx);
void hwfoc_dl_push(hwfoc_dl_decoder *d, uint8_t byte, hwfoc_dl_cb cb, void *ctx);
void hwfoc_dl_flush(hwfoc_dl_decoder *d, hwfoc_dl_cb cb, void *ctx);
void hwfoc_dl_line_silent(hwfoc_dl_decoder *d, uint32_t max_frames, hwfoc_dl_cb cb, void *ctx);
/** Writes the 160 bytes of a hub frame (absent slots zero, every record's channel byte set). */
void hwfoc_dl_encode(const hwfoc_dl_frame *f, uint8_t out[HWFOC_DL_FRAME_LEN]);
/** ESC frames (19200 baud, 24 bytes) that fit in the time of `hub_frames` hub frames. */
uint32_t hwfoc_dl_esc_frames_in(uint32_t hub_frames);
#endif

/* ---------------------------------------------------------------- V3 and V4: chains */
#if !defined(HWFOC_NO_V3) || !defined(HWFOC_NO_V4)
/** A frame continues a chain when its counter is at most this far past the one expected. */
#define HWFOC_MAX_CHAINED_GAP 3u
/** Frames that confirm a new chain. */
#define HWFOC_CHAIN_TO_LOCK 3u
/** The counts of a chained plausibility scanner (the Rust `chain::Counts`). */
typedef struct hwfoc_chain_counts {
    uint64_t bytes;
    uint64_t bytes_skipped;
    uint32_t implausible;
    uint32_t unconfirmed;
    uint32_t syncs;
    hwfoc_sequence counter; /**< 24-bit */
} hwfoc_chain_counts;
#endif

#ifndef HWFOC_NO_V3
#define HWFOC_V3_FRAME_LEN 10u
#define HWFOC_V3_MAX_LEN 30u
#define HWFOC_V3_FULL_SCALE 255u
#define HWFOC_V3_PLACEHOLDER_PERIOD_US 35314u

typedef struct hwfoc_v3_frame {
    uint64_t offset;
    uint32_t counter; /**< 24 bits */
    uint16_t throttle_in_raw;
    uint16_t pwm_out_raw;
    uint16_t period_us;
} hwfoc_v3_frame;

typedef struct hwfoc_v3_stats {
    hwfoc_chain_counts counts;
    uint8_t has_chain;
    uint64_t chain_end;
} hwfoc_v3_stats;

typedef struct hwfoc_v3_decoder {
    hwfoc_v3_stats stats;
    uint8_t held[HWFOC_V3_MAX_LEN];
    uint8_t len;
} hwfoc_v3_decoder;

typedef void (*hwfoc_v3_cb)(void *ctx, const hwfoc_v3_frame *frame);

void hwfoc_v3_init(hwfoc_v3_decoder *d);
void hwfoc_v3_feed(hwfoc_v3_decoder *d, const uint8_t *data, size_t n, hwfoc_v3_cb cb, void *ctx);
void hwfoc_v3_push(hwfoc_v3_decoder *d, uint8_t byte, hwfoc_v3_cb cb, void *ctx);
void hwfoc_v3_flush(hwfoc_v3_decoder *d, hwfoc_v3_cb cb, void *ctx);
void hwfoc_v3_line_silent(hwfoc_v3_decoder *d, uint32_t max_frames, hwfoc_v3_cb cb, void *ctx);
void hwfoc_v3_encode(const hwfoc_v3_frame *f, uint8_t out[HWFOC_V3_FRAME_LEN]);
/** eRPM from the commutation period; 0 when the period is 0 or the idle placeholder. */
uint32_t hwfoc_v3_erpm(uint16_t period_us);
#endif

#ifndef HWFOC_NO_V4
#define HWFOC_V4_DATA_LEN 19u
#define HWFOC_V4_SLOW_DATA_LEN 20u
#define HWFOC_V4_INFO_LEN 13u
#define HWFOC_V4_MAX_LEN 60u
#define HWFOC_V4_TRAILER 0xB9u
#define HWFOC_V4_INFO_MARK 0x01u
#define HWFOC_V4_DEFAULT_FULL_SCALE 1000u
#define HWFOC_V4_ADC_LIMIT 4096u

typedef struct hwfoc_v4_data {
    uint32_t counter; /**< 24 bits */
    uint16_t throttle_in_raw;
    uint16_t throttle_out_raw;
    uint32_t erpm; /**< 24 bits */
    uint16_t voltage_adc;
    uint16_t current_adc;
    uint16_t temp_adc;
    uint16_t temp2_adc;
} hwfoc_v4_data;

/** V4's info frame: throttle full scale, volts per step v1/(v2*10), current adc*i1/i2-i3. */
typedef struct hwfoc_v4_info {
    uint16_t full_scale;
    uint8_t v1, v2, i1, i2, i3, t1, t2;
} hwfoc_v4_info;

#define HWFOC_V4_KIND_DATA 0
#define HWFOC_V4_KIND_INFO 1

typedef struct hwfoc_v4_frame {
    uint64_t offset;
    int kind;            /**< HWFOC_V4_KIND_DATA or HWFOC_V4_KIND_INFO */
    hwfoc_v4_data data;  /**< a data frame */
    int has_info;        /**< an info frame; or for a data frame, the info adopted then */
    hwfoc_v4_info info;
} hwfoc_v4_frame;

typedef struct hwfoc_v4_stats {
    hwfoc_chain_counts counts;
    uint32_t info_frames;
    uint32_t adoptions;
    uint32_t disagreements;
    uint32_t trailers;
    uint8_t has_chain, chain_has_next, chain_trailer, has_last_info, has_adopted;
    /* Data frames are decoded (and judged) under `adopted`: adopted, and the last info frame is
     * it (else another ESC's, not yet confirmed by a second copy, as after a swap: none, as
     * before any info frame; Rust: v4::Stats::in_use). Set where an info frame is accepted. */
    uint8_t in_use;
    uint32_t chain_next;
    uint64_t chain_end;
    hwfoc_v4_info last_info;
    hwfoc_v4_info adopted;
} hwfoc_v4_stats;

typedef struct hwfoc_v4_decoder {
    hwfoc_v4_stats stats;
    uint8_t held[HWFOC_V4_MAX_LEN];
    uint8_t len;
} hwfoc_v4_decoder;

typedef void (*hwfoc_v4_cb)(void *ctx, const hwfoc_v4_frame *frame);

void hwfoc_v4_init(hwfoc_v4_decoder *d);
void hwfoc_v4_feed(hwfoc_v4_decoder *d, const uint8_t *data, size_t n, hwfoc_v4_cb cb, void *ctx);
void hwfoc_v4_push(hwfoc_v4_decoder *d, uint8_t byte, hwfoc_v4_cb cb, void *ctx);
void hwfoc_v4_flush(hwfoc_v4_decoder *d, hwfoc_v4_cb cb, void *ctx);
void hwfoc_v4_line_silent(hwfoc_v4_decoder *d, uint32_t max_frames, hwfoc_v4_cb cb, void *ctx);
void hwfoc_v4_encode_data(const hwfoc_v4_data *f, uint8_t out[HWFOC_V4_DATA_LEN]);
void hwfoc_v4_encode_info(const hwfoc_v4_info *f, uint8_t out[HWFOC_V4_INFO_LEN]);
/** Millivolts of a voltage ADC value at v1/(v2*10) V per step (before an info frame: 8/910, HV 11/650). */
uint32_t hwfoc_v4_voltage_mv(uint16_t adc, uint16_t num, uint16_t den);
/** Milliamps of a current ADC value by an info frame (adc*i1/i2 - i3, at least 0); 0 if it has no sensor. */
uint32_t hwfoc_v4_current_ma(uint16_t adc, const hwfoc_v4_info *info);
#endif

/* ---------------------------------------------------------------- HW5 */
#ifndef HWFOC_NO_HW5
#define HWFOC_HW5_BAUD 115200u
#define HWFOC_HW5_TELEMETRY_LEN 32u
#define HWFOC_HW5_MAX_LEN 105u
#define HWFOC_HW5_KINDS 8u

/** The largest throttle (percent) and input voltage (0.1 V) of a telemetry frame; a frame
 * over either is counted in hwfoc_hw5_stats.out_of_range, not handed on. */
#define HWFOC_HW5_THROTTLE_MAX_PCT 100u
#define HWFOC_HW5_VOLTAGE_MAX_RAW 1000u

/** HW5 frame kinds, counted in hwfoc_hw5_stats.frames. */
enum {
    HWFOC_HW5_TELEMETRY = 0,
    HWFOC_HW5_PING = 1,
    HWFOC_HW5_DEVICE_INFO = 2,
    HWFOC_HW5_RESET = 3,
    HWFOC_HW5_PARAMETERS_READ = 4,
    HWFOC_HW5_PARAMETERS_WRITTEN = 5,
    HWFOC_HW5_PARAMETERS_WRITE_ERROR = 6,
    HWFOC_HW5_PING_REQUEST = 7
};

typedef struct hwfoc_hw5_frame {
    uint64_t offset;
    uint8_t throttle; /**< percent */
    uint8_t unknown[2];
    uint8_t fault; /**< fault bits (hwfoc_hw5_fault_name) */
    uint16_t erpm_raw;    /**< eRPM / 10 */
    uint16_t voltage_raw; /**< volts * 10 */
    uint16_t current_raw; /**< amps * 10 */
    uint8_t esc_temp, bec_temp, motor_temp; /**< degrees C */
    uint8_t bec_voltage_raw, bec_current_raw; /**< * 10 */
} hwfoc_hw5_frame;

typedef struct hwfoc_hw5_stats {
    uint64_t bytes;
    uint64_t bytes_skipped;
    uint32_t frames[HWFOC_HW5_KINDS];
    uint32_t crc_failures;
    uint32_t bad_headers;
    uint32_t unknown_types;
    uint32_t out_of_range; /**< telemetry frames whose CRC matched with a value over its maximum */
} hwfoc_hw5_stats;

typedef struct hwfoc_hw5_decoder {
    hwfoc_hw5_stats stats;
    uint8_t held[HWFOC_HW5_MAX_LEN];
    uint8_t len;
} hwfoc_hw5_decoder;

typedef void (*hwfoc_hw5_cb)(void *ctx, const hwfoc_hw5_frame *frame);

void hwfoc_hw5_init(hwfoc_hw5_decoder *d);
void hwfoc_hw5_feed(hwfoc_hw5_decoder *d, const uint8_t *data, size_t n, hwfoc_hw5_cb cb, void *ctx);
void hwfoc_hw5_push(hwfoc_hw5_decoder *d, uint8_t byte, hwfoc_hw5_cb cb, void *ctx);
void hwfoc_hw5_flush(hwfoc_hw5_decoder *d, hwfoc_hw5_cb cb, void *ctx);
void hwfoc_hw5_line_silent(hwfoc_hw5_decoder *d, uint32_t max_frames, hwfoc_hw5_cb cb, void *ctx);
void hwfoc_hw5_encode(const hwfoc_hw5_frame *f, uint8_t out[HWFOC_HW5_TELEMETRY_LEN]);
/** The name of fault bit `bit` (0..7), e.g. "motor_locked". */
const char *hwfoc_hw5_fault_name(unsigned bit);
#endif

/* ---------------------------------------------------------------- DroneCAN payloads */
#ifndef HWFOC_NO_CAN
/** The longest payload of these data types. */
#define HWFOC_CAN_MAX_PAYLOAD 14u

/** The data types of fixed layout whose payloads hwfoc_can_pack and hwfoc_can_unpack handle:
 *  Hobbywing's com.hobbywing.esc messages and services, and the standard uavcan ones an ESC
 *  sends. Their fields, in DSDL order, are given as int32 (unsigned fields in their width;
 *  signed fields sign-extended; EscStatus's float16 fields as their 16 raw bits). */
typedef enum hwfoc_can_type {
    HWFOC_CAN_STATUS_MSG1,                /**< rpm u16, pwm u16, status u16 */
    HWFOC_CAN_STATUS_MSG2,                /**< input_voltage i16 (0.1 V), current i16 (0.1 A), temperature u8 */
    HWFOC_CAN_STATUS_MSG3,                /**< mos_t u8, cap_t u8, motor_t u8 */
    HWFOC_CAN_NODE_STATUS,                /**< uptime_sec u32, health u2, mode u3, sub_mode u3, vendor u16 */
    HWFOC_CAN_ESC_STATUS,                 /**< error_count u32, voltage f16, current f16, temperature f16 (K), rpm i18, power_rating_pct u7, esc_index u5 */
    HWFOC_CAN_ESC_STATUS_EXTENDED,        /**< input_pct u7, output_pct u7, motor_temperature_deg_c i9, motor_angle u9, status_flags u19, esc_index u5 */
    HWFOC_CAN_SET_ID_REQUEST,             /**< node_id u8, throttle_channel u8 (1-indexed) */
    HWFOC_CAN_SET_ID_RESPONSE,            /**< node_id u8, throttle_channel u8 */
    HWFOC_CAN_SET_BAUD_REQUEST,           /**< baud u8 */
    HWFOC_CAN_SET_BAUD_RESPONSE,          /**< (empty) */
    HWFOC_CAN_SET_LED_REQUEST,            /**< option u8, color u8, blink u8 */
    HWFOC_CAN_SET_LED_RESPONSE,           /**< option u8, color u8, blink u8 */
    HWFOC_CAN_SET_DIRECTION_REQUEST,      /**< direction u8 */
    HWFOC_CAN_SET_DIRECTION_RESPONSE,     /**< direction u8 */
    HWFOC_CAN_SET_REPORTING_FREQUENCY_REQUEST,  /**< option u8, msg_id u16, rate u8 */
    HWFOC_CAN_SET_REPORTING_FREQUENCY_RESPONSE, /**< option u8, msg_id u16, rate u8 */
    HWFOC_CAN_SET_THROTTLE_SOURCE_REQUEST,  /**< source u8 */
    HWFOC_CAN_SET_THROTTLE_SOURCE_RESPONSE, /**< source u8 */
    HWFOC_CAN_SELF_TEST_REQUEST,          /**< (empty) */
    HWFOC_CAN_SELF_TEST_RESPONSE,         /**< status u8 */
    HWFOC_CAN_SET_ANGLE_REQUEST,          /**< option u8, angle u16 */
    HWFOC_CAN_GET_MAINTENANCE_INFORMATION_REQUEST,  /**< option u8 */
    HWFOC_CAN_GET_MAINTENANCE_INFORMATION_RESPONSE, /**< total_rotation_time_min u32, time_since_maintenance_min u24 */
    HWFOC_CAN_GET_MAJOR_CONFIG_REQUEST,   /**< option u8 */
    HWFOC_CAN_GET_MAJOR_CONFIG_RESPONSE,  /**< direction u1, throttle_source u1, throttle_channel u6, led_status u5, led_color u3, msg2_rate u4, msg1_rate u4, positioning_angle u16, reserved u16 */
    HWFOC_CAN_TYPES
} hwfoc_can_type;

/** The most fields of any of these types. */
#define HWFOC_CAN_MAX_FIELDS 9u

/** How many fields `type` has (0 for an unknown type). */
unsigned hwfoc_can_fields(hwfoc_can_type type);
/** Packs the fields into `out`; returns the payload's length. A value beyond its field's range
 *  is saturated (as the Rust codec does). */
size_t hwfoc_can_pack(hwfoc_can_type type, const int32_t *fields, uint8_t out[HWFOC_CAN_MAX_PAYLOAD]);
/** Unpacks a payload of exactly the type's length into `fields`; returns 0, or -1 for another
 *  length or an unknown type. */
int hwfoc_can_unpack(hwfoc_can_type type, const uint8_t *payload, size_t len, int32_t *fields);
#endif

/* ---------------------------------------------------------------- conversions (integer) */
/** Hundredths of a percent of `raw` out of `full_scale` (HW-FOC: 1024; V3: 255; V4: info's). */
uint32_t hwfoc_throttle_centipct(uint32_t raw, uint32_t full_scale);
/** Mechanical RPM = eRPM / (pole pairs * gear), the gear ratio given as gear_num/gear_den. */
uint32_t hwfoc_rpm(uint32_t erpm, uint16_t pole_pairs, uint16_t gear_num, uint16_t gear_den);
/** eRPM of a raw HW-FOC, DataLink or HW5 eRPM field: raw * 10. */
uint32_t hwfoc_erpm_of_raw(uint16_t raw);
/** Millivolts of a raw volts*10 field (HW-FOC, DataLink, HW5). */
uint32_t hwfoc_decivolts_mv(uint16_t raw);
/** Milliamps of an HW-FOC current field, amps * 64 (truncated toward zero). */
int32_t hwfoc_foc_current_ma(int16_t raw);
/** HW-FOC's temperature code as tenths of a degree C (rounded); returns 0, or -1 when colder
 *  than the table (code > 241), 1 when hotter (code < 33). */
int hwfoc_temp_decidegrees(uint8_t code, int16_t *decidegrees);

#ifdef HWFOC_FLOAT
float hwfoc_foc_current_a(int16_t raw, float current_scale);
#ifndef HWFOC_NO_V4
float hwfoc_v4_voltage_v(uint16_t adc, uint16_t num, uint16_t den);
/** V4's NTC temperature in degrees C (beta 3950, R25/reference 4.7); NaN out of range. */
float hwfoc_v4_ntc_celsius(uint16_t adc);
#endif
#endif

#ifdef __cplusplus
}
#endif
#endif /* HWFOC_H */

/* ==================================================================== implementation */
#ifdef HWFOC_IMPLEMENTATION
#ifndef HWFOC_IMPLEMENTED
#define HWFOC_IMPLEMENTED

#include <string.h>
#ifdef HWFOC_FLOAT
#include <math.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define HWFOC__BYTES_MASK 0xFFFFFFFFFFFFull /* byte counts wrap at 2^48, as in Rust */
#if defined(__GNUC__) || defined(__clang__)
#define HWFOC__OUT_OF_LINE __attribute__((noinline)) /* called from several places: smaller */
#else
#define HWFOC__OUT_OF_LINE
#endif

static inline uint32_t hwfoc__sat(uint32_t a, uint32_t b) { return a > 0xFFFFFFFFu - b ? 0xFFFFFFFFu : a + b; }
static inline void hwfoc__inc(uint32_t *a) { *a = hwfoc__sat(*a, 1u); }
static inline void hwfoc__add_bytes(uint64_t *count, size_t n) { *count = (*count + (uint64_t)n) & HWFOC__BYTES_MASK; }
static inline uint16_t hwfoc__be16(const uint8_t *p) { return (uint16_t)((unsigned)p[0] << 8 | p[1]); }
static inline uint16_t hwfoc__le16(const uint8_t *p) { return (uint16_t)((unsigned)p[1] << 8 | p[0]); }
static inline uint32_t hwfoc__be24(const uint8_t *p) { return (uint32_t)p[0] << 16 | (uint32_t)p[1] << 8 | p[2]; }
static inline void hwfoc__put_be16(uint8_t *p, uint16_t v) { p[0] = (uint8_t)(v >> 8); p[1] = (uint8_t)v; }
static inline void hwfoc__put_le16(uint8_t *p, uint16_t v) { p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); }
static inline void hwfoc__put_be24(uint8_t *p, uint32_t v) { p[0] = (uint8_t)(v >> 16); p[1] = (uint8_t)(v >> 8); p[2] = (uint8_t)v; }

void hwfoc_sequence_next(hwfoc_sequence *s, uint32_t number, uint32_t max) {
    uint32_t gap = s->gap_limit, step = (number - s->last) & max, add = 1u, *counter = &s->restarts;
    number &= max;
    s->gap_limit = 0;
    if (s->count != 0) {
        if (step == 0) {
            counter = &s->duplicates;
        } else if (step == max && gap == max) {
            /* The number the gap of one before skipped: a swap. That gap counted one loss (so
             * lost > 0), taken back; the last number stays. */
            s->lost--;
            counter = &s->reordered;
            number = s->last;
        } else if (step <= (gap - 1u < max - 1u ? gap : HWFOC_MAX_PACKET_GAP + 1u)) {
            /* (a gap limit of 0 or the swap mark max means HWFOC_MAX_PACKET_GAP + 1) */
            counter = &s->lost;
            add = step - 1u;
            if (step == 2u) s->gap_limit = max; /* a gap of one: the next number may fill it */
        }
        *counter = hwfoc__sat(*counter, add);
    }
    hwfoc__inc(&s->count);
    s->last = number;
}

void hwfoc_sequence_line_silent(hwfoc_sequence *s, uint32_t max_frames, uint32_t max) {
    /* 0 and the swap mark (max: a number after a silence is no swap) mean 1 */
    uint32_t limit = s->gap_limit - 1u < max - 1u ? s->gap_limit : 1u;
    uint32_t most = max / 2u + 1u;
    limit = hwfoc__sat(limit, max_frames);
    s->gap_limit = limit < most ? limit : most;
}

uint16_t hwfoc_sum16(const uint8_t *p, size_t n) {
    uint32_t sum = 0;
    size_t i;
    for (i = 0; i < n; i++) sum += p[i];
    return (uint16_t)sum;
}

/* Both CRCs bit by bit, without a table: on a Cortex-M4 each is about 45 bytes smaller than by
 * nibbles (a 32-byte table; a byte table takes 512), and fast enough for a 160-byte DataLink
 * frame at 115200 baud or a 32-byte HW5 frame at 19200. */
uint16_t hwfoc_crc16_xmodem(const uint8_t *p, size_t n) {
    unsigned crc = 0, bit;
    size_t i;
    for (i = 0; i < n; i++) {
        crc ^= (unsigned)p[i] << 8;
        for (bit = 0; bit < 8u; bit++) crc = (crc & 0x8000u ? crc << 1 ^ 0x1021u : crc << 1) & 0xFFFFu;
    }
    return (uint16_t)crc;
}

uint16_t hwfoc_crc16_modbus(const uint8_t *p, size_t n) {
    unsigned crc = 0xFFFFu, bit;
    size_t i;
    for (i = 0; i < n; i++) {
        crc ^= p[i];
        for (bit = 0; bit < 8u; bit++) crc = crc & 1u ? crc >> 1 ^ 0xA001u : crc >> 1;
    }
    return (uint16_t)crc;
}

#if !defined(HWFOC_NO_FOC) || !defined(HWFOC_NO_DATALINK) || !defined(HWFOC_NO_V3) || \
    !defined(HWFOC_NO_V4) || !defined(HWFOC_NO_HW5)
/* The streaming layer (the Rust `scan::StreamDecoder`), shared by every format: bytes are taken
 * one at a time, as the Rust decoder's `push` takes them (the same frames and statistics for any
 * chunking), onto the candidate held (at most max_len bytes), which is scanned as soon as its
 * bytes may decide it; what stays undecided is held for the next byte. A format's scan(d, data, n, base,
 * at_end, cb, ctx) returns where it stopped (n, or an undecided candidate's start, none of
 * whose bytes is counted); candidate_len(held, n) is how many bytes may decide it. Callbacks
 * pass through as `void (*)(void)` and are converted back to their own type before a call. */
typedef void (*hwfoc__any_cb)(void);
typedef size_t (*hwfoc__len_fn)(const uint8_t *held, size_t n);
typedef size_t (*hwfoc__find_fn)(const uint8_t *h, size_t n);
/* Decides the candidate at c[0..n], stream offset `at`: HWFOC__FRAME (handed on, its length in
 * *len), HWFOC__REJECTED (counted) or HWFOC__UNDECIDED (nothing counted; rejected at_end). */
typedef int (*hwfoc__take_fn)(void *d, const uint8_t *c, size_t n, uint64_t at, int at_end, size_t *len,
                              hwfoc__any_cb cb, void *ctx);
/* Before each search: V4 takes a data frame's trailer byte; returns the new position. */
typedef size_t (*hwfoc__pre_fn)(void *d, const uint8_t *data, size_t n, uint64_t base, size_t pos);
typedef struct hwfoc__format {
    uint16_t bytes_at, skipped_at, held_at, len_at; /* offsets in the decoder */
    hwfoc__len_fn candidate_len;
    hwfoc__find_fn find;
    hwfoc__take_fn take;
    hwfoc__pre_fn pre;
#ifdef HWFOC_NO_FOC_INFO
    uint8_t narrow; /* 32-bit byte counts (HW-FOC's in this build) */
#endif
} hwfoc__format;

/* Whether a format's byte counts are 32-bit: only HW-FOC's with HWFOC_NO_FOC_INFO, so the
 * default build pays nothing for it. */
#ifdef HWFOC_NO_FOC_INFO
#define HWFOC__NARROW(fmt) ((fmt)->narrow)
#define HWFOC__NARROW_INIT(DEC, BYTES) , sizeof(((DEC *)0)->stats.BYTES) == 4
#else
#define HWFOC__NARROW(fmt) ((void)(fmt), 0)
#define HWFOC__NARROW_INIT(DEC, BYTES)
#endif
/* Where a format's byte counts (and so its frame offsets) wrap. */
#define HWFOC__MASK(fmt) (HWFOC__NARROW(fmt) ? 0xFFFFFFFFu : HWFOC__BYTES_MASK)

/* The Rust scanners' candidate verdicts. */
enum { HWFOC__FRAME, HWFOC__REJECTED, HWFOC__UNDECIDED };

#define HWFOC__AT(d, off, T) ((T *)(void *)((char *)(d) + (off)))

/* A byte count of the decoder at `off`, 64-bit or (HWFOC__NARROW) 32-bit. */
static inline uint64_t hwfoc__count(const hwfoc__format *fmt, void *d, uint16_t off) {
    return HWFOC__NARROW(fmt) ? *HWFOC__AT(d, off, uint32_t) : *HWFOC__AT(d, off, uint64_t);
}
static inline void hwfoc__count_add(const hwfoc__format *fmt, void *d, uint16_t off, size_t n) {
    if (HWFOC__NARROW(fmt)) *HWFOC__AT(d, off, uint32_t) += (uint32_t)n;
    else hwfoc__add_bytes(HWFOC__AT(d, off, uint64_t), n);
}

/* The search loop of every scanner (the Rust `scan::next_candidate` and `scan_all`): from each
 * candidate start `find` gives, `take` decides; the bytes before a candidate, and a rejected
 * candidate's first byte, are skipped. Returns where it stopped: n, or an undecided start. */
static size_t hwfoc__scan(const hwfoc__format *fmt, void *d, const uint8_t *data, size_t n, uint64_t base,
                          int at_end, hwfoc__any_cb cb, void *ctx) {
    size_t pos = 0, k, i, len = 0;
    for (;;) {
        if (fmt->pre) pos = fmt->pre(d, data, n, base, pos);
        for (;;) {
            k = fmt->find(data + pos, n - pos);
            hwfoc__count_add(fmt, d, fmt->skipped_at, k);
            if (pos + k == n) return n;
            i = pos + k;
            switch (fmt->take(d, data + i, n - i, (base + i) & HWFOC__MASK(fmt), at_end, &len, cb, ctx)) {
            case HWFOC__FRAME: pos = i + len; break;
            case HWFOC__UNDECIDED: return i;
            default:
                hwfoc__count_add(fmt, d, fmt->skipped_at, 1);
                pos = i + 1;
                continue;
            }
            break;
        }
    }
}

/* With HWFOC_NO_FOC_INFO, HW-FOC's held candidate starts at its count of held bytes (held_at ==
 * len_at): the sync byte it stands for is put back before the candidate is read. */
static inline void hwfoc__held_sync(const hwfoc__format *fmt, uint8_t *held, size_t m) {
#ifdef HWFOC_NO_FOC_INFO
    if (fmt->held_at == fmt->len_at && m > 0) held[0] = HWFOC_SYNC;
#else
    (void)fmt, (void)held, (void)m;
#endif
}

static void hwfoc__feed(const hwfoc__format *fmt, void *d, const uint8_t *data, size_t n, hwfoc__any_cb cb, void *ctx) {
    uint8_t *held = HWFOC__AT(d, fmt->held_at, uint8_t);
    uint8_t *len = HWFOC__AT(d, fmt->len_at, uint8_t);
    size_t i, m, pos;
    for (i = 0; i < n; i++) {
        m = *len;
        hwfoc__held_sync(fmt, held, m);
        held[m] = data[i];
        hwfoc__count_add(fmt, d, fmt->bytes_at, 1);
        /* The held candidate cannot be decided with this byte yet: just keep it. */
        if (m > 0 && m + 1u < fmt->candidate_len(held, m)) {
            *len = (uint8_t)(m + 1u);
            continue;
        }
        m++;
        pos = hwfoc__scan(fmt, d, held, m, (hwfoc__count(fmt, d, fmt->bytes_at) - m) & HWFOC__MASK(fmt), 0, cb, ctx);
        memmove(held, held + pos, m - pos);
        *len = (uint8_t)(m - pos);
    }
}

/* A candidate of V3, V4 and HW5 is scanned again with every byte (the Rust decoders' byte
 * counts that decide one are a speed-up only: an undecided candidate changes nothing). */
static inline size_t hwfoc__next_byte(const uint8_t *held, size_t n) {
    (void)held;
    return n + 1u;
}

static void hwfoc__flush(const hwfoc__format *fmt, void *d, hwfoc__any_cb cb, void *ctx) {
    uint8_t *len = HWFOC__AT(d, fmt->len_at, uint8_t);
    size_t held = *len;
    hwfoc__held_sync(fmt, HWFOC__AT(d, fmt->held_at, uint8_t), held);
    (void)hwfoc__scan(fmt, d, HWFOC__AT(d, fmt->held_at, uint8_t), held,
                      (hwfoc__count(fmt, d, fmt->bytes_at) - held) & HWFOC__MASK(fmt), 1, cb, ctx);
    *len = 0;
}

/* A format's public streaming functions over the shared layer. */
/* HELD: the member the candidate held starts at (`held`, or HW-FOC's HWFOC__FOC_HELD). */
#define HWFOC__STREAM(PFX, DEC, CB, BYTES, SKIPPED, HELD, LEN_FN, FIND, PRE, SILENT)        \
    static const hwfoc__format PFX##_format = {offsetof(DEC, stats.BYTES), offsetof(DEC, stats.SKIPPED), \
                                               offsetof(DEC, HELD), offsetof(DEC, len), LEN_FN,     \
                                               FIND, PFX##_take, PRE HWFOC__NARROW_INIT(DEC, BYTES)};                              \
    void PFX##_feed(DEC *d, const uint8_t *data, size_t n, CB cb, void *ctx) {                      \
        hwfoc__feed(&PFX##_format, d, data, n, (hwfoc__any_cb)cb, ctx);                             \
    }                                                                                               \
    void PFX##_push(DEC *d, uint8_t byte, CB cb, void *ctx) {                                       \
        hwfoc__feed(&PFX##_format, d, &byte, 1, (hwfoc__any_cb)cb, ctx);                            \
    }                                                                                               \
    void PFX##_flush(DEC *d, CB cb, void *ctx) { hwfoc__flush(&PFX##_format, d, (hwfoc__any_cb)cb, ctx); } \
    void PFX##_line_silent(DEC *d, uint32_t max_frames, CB cb, void *ctx) {                         \
        PFX##_flush(d, cb, ctx);                                                                    \
        SILENT;                                                                                     \
    }                                                                                               \
    void PFX##_init(DEC *d) { memset(d, 0, sizeof *d); }
#endif

/* ---------------------------------------------------------------- HW-FOC implementation */
#if !defined(HWFOC_NO_FOC) || !defined(HWFOC_NO_DATALINK)

static const char *const hwfoc__foc_faults[16] = {
    "input_voltage_high", "input_voltage_low", "over_current", "reserved_3",
    "throttle_signal_lost", "throttle_not_zeroed", "mos_overheat", "cap_overheat",
    "motor_blocked", "upper_bridge_open", "mos_short", "lower_bridge_open",
    "opamp_phase_c", "opamp_phase_b", "opamp_phase_a", "reserved_15"};

const char *hwfoc_foc_fault_name(unsigned bit) { return bit < 16u ? hwfoc__foc_faults[bit] : "?"; }

static void hwfoc__foc_read_payload(const uint8_t *p, hwfoc_foc_data *f) {
    f->packet = hwfoc__be16(p);
    f->throttle_in_raw = hwfoc__be16(p + 2);
    f->throttle_out_raw = hwfoc__be16(p + 4);
    f->erpm_raw = hwfoc__be16(p + 6);
    f->voltage_raw = hwfoc__be16(p + 8);
    f->current_raw = (int16_t)hwfoc__be16(p + 10);
    f->phase_current_raw = (int16_t)hwfoc__be16(p + 12);
    f->mos_adc = p[14];
    f->cap_adc = p[15];
    f->status = hwfoc__be16(p + 16);
}

static void hwfoc__foc_write_payload(const hwfoc_foc_data *f, uint8_t *p) {
    hwfoc__put_be16(p, f->packet);
    hwfoc__put_be16(p + 2, f->throttle_in_raw);
    hwfoc__put_be16(p + 4, f->throttle_out_raw);
    hwfoc__put_be16(p + 6, f->erpm_raw);
    hwfoc__put_be16(p + 8, f->voltage_raw);
    hwfoc__put_be16(p + 10, (uint16_t)f->current_raw);
    hwfoc__put_be16(p + 12, (uint16_t)f->phase_current_raw);
    p[14] = f->mos_adc;
    p[15] = f->cap_adc;
    hwfoc__put_be16(p + 16, f->status);
}
#endif

#ifndef HWFOC_NO_FOC

void hwfoc_foc_encode_data(const hwfoc_foc_data *f, uint8_t out[HWFOC_FOC_DATA_LEN]) {
    out[0] = HWFOC_SYNC; out[1] = 0x16; out[2] = 0x01; out[3] = 0x02;
    hwfoc__foc_write_payload(f, out + 4);
    hwfoc__put_le16(out + 22, hwfoc_sum16(out, 22));
}

void hwfoc_foc_encode_info(const uint8_t text[HWFOC_FOC_INFO_TEXT_LEN], uint8_t out[HWFOC_FOC_INFO_LEN]) {
    out[0] = HWFOC_SYNC; out[1] = 0x4C; out[2] = 0x01; out[3] = 0x01;
    memcpy(out + 4, text, HWFOC_FOC_INFO_TEXT_LEN);
    out[76] = (uint8_t)hwfoc_sum16(out, 76);
}

/* The length byte's frame length; 0 for an unknown one. */
#ifdef HWFOC_NO_FOC_INFO
static size_t hwfoc__foc_len_of(uint8_t b) { return b == 0x16 ? 24u : 0u; }
#else
static size_t hwfoc__foc_len_of(uint8_t b) { return b == 0x16 ? 24u : b == 0x4C ? 77u : 0u; }
#endif

static size_t hwfoc_foc_candidate_len(const uint8_t *c, size_t n) {
    size_t len;
    if (n < 2) return 2;
    len = hwfoc__foc_len_of(c[1]);
    return len ? len : HWFOC_FOC_MAX_LEN;
}

/* The first sync byte followed by a known length byte (or by the end). */
static size_t hwfoc__foc_find(const uint8_t *h, size_t n) {
    size_t j;
    for (j = 0; j < n; j++)
        if (h[j] == HWFOC_SYNC && (j + 1 == n || hwfoc__foc_len_of(h[j + 1]))) return j;
    return n;
}

static int hwfoc__foc_take(hwfoc_foc_decoder *d, const uint8_t *c, size_t n, int at_end, hwfoc_foc_frame *f) {
#ifndef HWFOC_NO_FOC_INFO
    size_t i;
#endif
    if (n >= 24 && c[1] == 0x16 && c[2] == 0x01 && c[3] == 0x02 && hwfoc_sum16(c, 22) == hwfoc__le16(c + 22)) {
        f->kind = HWFOC_FOC_KIND_DATA;
        hwfoc__foc_read_payload(c + 4, &f->data);
        if (f->data.throttle_in_raw <= HWFOC_FOC_THROTTLE_MAX_RAW && f->data.throttle_out_raw <= HWFOC_FOC_THROTTLE_MAX_RAW) {
            hwfoc_sequence_next(&d->stats.packets, f->data.packet, HWFOC_COUNTER16_MAX);
            return HWFOC__FRAME;
        } /* else a corrupted frame whose checksum still matches: a checksum failure below */
    }
#ifndef HWFOC_NO_FOC_INFO
    if (n >= 77 && c[1] == 0x4C && c[2] == 0x01 && c[3] == 0x01 && (uint8_t)hwfoc_sum16(c, 76) == c[76]) {
        for (i = 4; i < 76 && c[i] < 0x80u; i++) {}
        if (i == 76) {
            f->kind = HWFOC_FOC_KIND_INFO;
            memcpy(f->info_text, c + 4, HWFOC_FOC_INFO_TEXT_LEN);
            hwfoc__inc(&d->stats.info_frames);
            return HWFOC__FRAME;
        }
    }
#endif
    if (n >= HWFOC_FOC_MAX_LEN || n >= hwfoc_foc_candidate_len(c, n)) {
        hwfoc__inc(&d->stats.checksum_failures);
        return HWFOC__REJECTED;
    }
    return at_end ? HWFOC__REJECTED : HWFOC__UNDECIDED;
}

static int hwfoc_foc_take(void *dec, const uint8_t *c, size_t n, uint64_t at, int at_end, size_t *len,
                          hwfoc__any_cb any, void *ctx) {
    hwfoc_foc_frame f;
    int v = hwfoc__foc_take((hwfoc_foc_decoder *)dec, c, n, at_end, &f);
    if (v == HWFOC__FRAME) {
        f.offset = at;
        *len = f.kind == HWFOC_FOC_KIND_DATA ? HWFOC_FOC_DATA_LEN : HWFOC_FOC_MAX_LEN;
        if (any) ((hwfoc_foc_cb)any)(ctx, &f);
    }
    return v;
}

#ifdef HWFOC_NO_FOC_INFO
#define HWFOC__FOC_HELD len
#else
#define HWFOC__FOC_HELD held
#endif
HWFOC__STREAM(hwfoc_foc, hwfoc_foc_decoder, hwfoc_foc_cb, bytes, bytes_skipped, HWFOC__FOC_HELD,
              hwfoc_foc_candidate_len, hwfoc__foc_find, NULL,
              hwfoc_sequence_line_silent(&d->stats.packets, max_frames, HWFOC_COUNTER16_MAX))
#endif

/* ---------------------------------------------------------------- DataLink implementation */
#ifndef HWFOC_NO_DATALINK

/* A hub frame lasts 160 bytes at 115200 baud, an ESC frame 24 bytes at 19200: 10/9 of one. */
typedef char hwfoc__hub_to_esc_is_10_9[HWFOC_DL_FRAME_LEN * HWFOC_FOC_BAUD * 9u ==
                                       HWFOC_FOC_DATA_LEN * HWFOC_DL_BAUD * 10u ? 1 : -1];

uint32_t hwfoc_dl_esc_frames_in(uint32_t hub_frames) {
    /* ceil(hub_frames * 10 / 9), saturated, in 32 bits (no 64-bit division on a Cortex-M). */
    uint32_t q = hub_frames / 9u, extra = (hub_frames % 9u * 10u + 8u) / 9u;
    return q > (0xFFFFFFFFu - extra) / 10u ? 0xFFFFFFFFu : q * 10u + extra;
}

void hwfoc_dl_encode(const hwfoc_dl_frame *f, uint8_t out[HWFOC_DL_FRAME_LEN]) {
    unsigned ch;
    memset(out, 0, HWFOC_DL_FRAME_LEN);
    out[0] = HWFOC_SYNC;
    out[1] = f->length_byte == HWFOC_DL_LENGTH_TOTAL ? (uint8_t)HWFOC_DL_LENGTH_TOTAL : (uint8_t)HWFOC_DL_LENGTH_COVERED;
    out[2] = 0x01;
    out[3] = 0x02;
    hwfoc__put_be16(out + 4, f->counter);
    for (ch = 0; ch < HWFOC_DL_CHANNELS; ch++) {
        uint8_t *r = out + 6 + 19 * ch;
        r[0] = (uint8_t)ch;
        if ((unsigned)f->present >> ch & 1u) hwfoc__foc_write_payload(&f->slots[ch], r + 1);
    }
    hwfoc__put_le16(out + 158, hwfoc_crc16_xmodem(out, 158));
}

static size_t hwfoc_dl_candidate_len(const uint8_t *c, size_t n) {
    (void)c;
    return n < 2 ? 2u : n < 4 ? 4u : HWFOC_DL_FRAME_LEN;
}

static int hwfoc__dl_is_length(uint8_t b) { return b == HWFOC_DL_LENGTH_COVERED || b == HWFOC_DL_LENGTH_TOTAL; }

static size_t hwfoc__dl_find(const uint8_t *h, size_t n) {
    size_t j;
    for (j = 0; j < n; j++)
        if (h[j] == HWFOC_SYNC && (j + 1 == n || hwfoc__dl_is_length(h[j + 1]))) return j;
    return n;
}

static void hwfoc__dl_read(const uint8_t *c, hwfoc_dl_frame *f) {
    unsigned r, k;
    memset(f, 0, sizeof *f);
    f->counter = hwfoc__be16(c + 4);
    f->length_byte = c[1];
    for (r = 0; r < HWFOC_DL_CHANNELS; r++) {
        const uint8_t *rec = c + 6 + 19 * r;
        uint8_t ch = rec[0], any = 0;
        for (k = 1; k < 19; k++) any |= rec[k];
        if (!any) {
            f->empty_slots++;
        } else if (ch >= HWFOC_DL_CHANNELS) {
            f->bad_channels++;
        } else if ((unsigned)f->present >> ch & 1u) {
            f->duplicate_channels++;
        } else {
            f->present = (uint8_t)(f->present | 1u << ch);
            hwfoc__foc_read_payload(rec + 1, &f->slots[ch]);
        }
    }
}

static int hwfoc_dl_take(void *dec, const uint8_t *c, size_t n, uint64_t at, int at_end, size_t *len,
                         hwfoc__any_cb any, void *ctx) {
    hwfoc_dl_stats *s = &((hwfoc_dl_decoder *)dec)->stats;
    hwfoc_dl_frame f;
    unsigned ch;
    if (n < 4 || (n < HWFOC_DL_FRAME_LEN && c[2] == 0x01 && c[3] == 0x02))
        return at_end ? HWFOC__REJECTED : HWFOC__UNDECIDED;
    if (c[2] != 0x01 || c[3] != 0x02) {
        hwfoc__inc(&s->bad_headers);
        return HWFOC__REJECTED;
    }
    if (hwfoc_crc16_xmodem(c, 158) != hwfoc__le16(c + 158)) {
        hwfoc__inc(&s->crc_failures);
        return HWFOC__REJECTED;
    }
    if (!hwfoc__dl_is_length(c[1])) { /* the search stops at no other */
        hwfoc__inc(&s->bad_headers);
        return HWFOC__REJECTED;
    }
    hwfoc__dl_read(c, &f);
    f.offset = at;
    hwfoc_sequence_next(&s->counter, f.counter, HWFOC_COUNTER16_MAX);
    hwfoc__inc(&s->length_bytes[c[1] == HWFOC_DL_LENGTH_TOTAL]);
    s->empty_slots = hwfoc__sat(s->empty_slots, f.empty_slots);
    s->bad_channels = hwfoc__sat(s->bad_channels, f.bad_channels);
    s->duplicate_channels = hwfoc__sat(s->duplicate_channels, f.duplicate_channels);
    for (ch = 0; ch < HWFOC_DL_CHANNELS; ch++)
        if ((unsigned)f.present >> ch & 1u) hwfoc_sequence_next(&s->channels[ch], f.slots[ch].packet, HWFOC_COUNTER16_MAX);
    *len = HWFOC_DL_FRAME_LEN;
    if (any) ((hwfoc_dl_cb)any)(ctx, &f);
    return HWFOC__FRAME;
}

static void hwfoc__dl_silent(hwfoc_dl_stats *s, uint32_t max_frames) {
    unsigned ch;
    uint32_t esc = hwfoc_dl_esc_frames_in(max_frames);
    hwfoc_sequence_line_silent(&s->counter, max_frames, HWFOC_COUNTER16_MAX);
    for (ch = 0; ch < HWFOC_DL_CHANNELS; ch++) hwfoc_sequence_line_silent(&s->channels[ch], esc, HWFOC_COUNTER16_MAX);
}

HWFOC__STREAM(hwfoc_dl, hwfoc_dl_decoder, hwfoc_dl_cb, bytes, bytes_skipped, held,
              hwfoc_dl_candidate_len, hwfoc__dl_find, NULL,
              hwfoc__dl_silent(&d->stats, max_frames))
#endif

/* ---------------------------------------------------------------- V3 and V4 implementation */
#if !defined(HWFOC_NO_V3) || !defined(HWFOC_NO_V4)
/* Whether `counter` is at most HWFOC_MAX_CHAINED_GAP past `next`. */
static int hwfoc__continues(uint32_t next, uint32_t counter) {
    return ((counter - next) & HWFOC_COUNTER24_MAX) <= HWFOC_MAX_CHAINED_GAP;
}
static size_t hwfoc__find_sync(const uint8_t *h, size_t n) {
    size_t j;
    for (j = 0; j < n && h[j] != HWFOC_SYNC; j++) {}
    return j;
}
enum { HWFOC__CHAIN_FRAME, HWFOC__IMPLAUSIBLE, HWFOC__UNCONFIRMED, HWFOC__CHAIN_UNDECIDED };
/* Counts a rejected or undecided verdict; returns the scan's HWFOC__REJECTED/UNDECIDED. */
static int hwfoc__chain_reject(hwfoc_chain_counts *c, int verdict, int at_end) {
    if (verdict == HWFOC__IMPLAUSIBLE) hwfoc__inc(&c->implausible);
    else if (verdict == HWFOC__UNCONFIRMED) hwfoc__inc(&c->unconfirmed);
    else if (!at_end) return HWFOC__UNDECIDED;
    return HWFOC__REJECTED;
}
#endif

#ifndef HWFOC_NO_V3

uint32_t hwfoc_v3_erpm(uint16_t period_us) {
    return period_us == 0 || period_us == HWFOC_V3_PLACEHOLDER_PERIOD_US ? 0u : 60000000u / period_us;
}

void hwfoc_v3_encode(const hwfoc_v3_frame *f, uint8_t out[HWFOC_V3_FRAME_LEN]) {
    out[0] = HWFOC_SYNC;
    hwfoc__put_be24(out + 1, f->counter);
    hwfoc__put_be16(out + 4, f->throttle_in_raw);
    hwfoc__put_be16(out + 6, f->pwm_out_raw);
    hwfoc__put_be16(out + 8, f->period_us);
}

static void hwfoc__v3_read(const uint8_t *b, hwfoc_v3_frame *f) {
    f->counter = hwfoc__be24(b + 1);
    f->throttle_in_raw = hwfoc__be16(b + 4);
    f->pwm_out_raw = hwfoc__be16(b + 6);
    f->period_us = hwfoc__be16(b + 8);
}

static int hwfoc__v3_plausible(const hwfoc_v3_frame *f) {
    return f->throttle_in_raw <= HWFOC_V3_FULL_SCALE && f->pwm_out_raw <= HWFOC_V3_FULL_SCALE;
}



/* Returns a verdict; *synced is set for a frame that starts a chain. */
static int hwfoc__v3_judge(const hwfoc_v3_stats *s, const uint8_t *c, size_t n, uint64_t at,
                           hwfoc_v3_frame *f, int *synced) {
    hwfoc_v3_frame next;
    uint32_t counter;
    size_t k;
    if (n < HWFOC_V3_FRAME_LEN) return HWFOC__CHAIN_UNDECIDED;
    hwfoc__v3_read(c, f);
    if (!hwfoc__v3_plausible(f)) return HWFOC__IMPLAUSIBLE;
    if (s->has_chain && s->counts.counter.count != 0 && s->chain_end == at &&
        hwfoc__continues((s->counts.counter.last + 1u) & HWFOC_COUNTER24_MAX, f->counter)) {
        *synced = 0;
        return HWFOC__CHAIN_FRAME;
    }
    counter = f->counter;
    for (k = 1; k < HWFOC_CHAIN_TO_LOCK; k++) {
        size_t at_k = k * HWFOC_V3_FRAME_LEN;
        if (at_k >= n) return HWFOC__CHAIN_UNDECIDED;
        if (c[at_k] != HWFOC_SYNC) return HWFOC__UNCONFIRMED;
        if (n - at_k < HWFOC_V3_FRAME_LEN) return HWFOC__CHAIN_UNDECIDED;
        hwfoc__v3_read(c + at_k, &next);
        counter = (counter + 1u) & HWFOC_COUNTER24_MAX;
        if (!hwfoc__v3_plausible(&next) || next.counter != counter) return HWFOC__UNCONFIRMED;
    }
    *synced = 1;
    return HWFOC__CHAIN_FRAME;
}

static int hwfoc_v3_take(void *dec, const uint8_t *c, size_t n, uint64_t at, int at_end, size_t *len,
                         hwfoc__any_cb any, void *ctx) {
    hwfoc_v3_stats *s = &((hwfoc_v3_decoder *)dec)->stats;
    hwfoc_v3_frame f;
    int synced = 0, v = hwfoc__v3_judge(s, c, n, at, &f, &synced);
    if (v != HWFOC__CHAIN_FRAME) return hwfoc__chain_reject(&s->counts, v, at_end);
    if (synced) hwfoc__inc(&s->counts.syncs);
    hwfoc_sequence_next(&s->counts.counter, f.counter, HWFOC_COUNTER24_MAX);
    s->has_chain = 1;
    s->chain_end = at + HWFOC_V3_FRAME_LEN;
    f.offset = at;
    *len = HWFOC_V3_FRAME_LEN;
    if (any) ((hwfoc_v3_cb)any)(ctx, &f);
    return HWFOC__FRAME;
}

HWFOC__STREAM(hwfoc_v3, hwfoc_v3_decoder, hwfoc_v3_cb, counts.bytes, counts.bytes_skipped, held,
              hwfoc__next_byte, hwfoc__find_sync, NULL,
              hwfoc_sequence_line_silent(&d->stats.counts.counter, max_frames, HWFOC_COUNTER24_MAX))
#endif

#ifndef HWFOC_NO_V4

void hwfoc_v4_encode_data(const hwfoc_v4_data *f, uint8_t out[HWFOC_V4_DATA_LEN]) {
    out[0] = HWFOC_SYNC;
    hwfoc__put_be24(out + 1, f->counter);
    hwfoc__put_be16(out + 4, f->throttle_in_raw);
    hwfoc__put_be16(out + 6, f->throttle_out_raw);
    hwfoc__put_be24(out + 8, f->erpm);
    hwfoc__put_be16(out + 11, f->voltage_adc);
    hwfoc__put_be16(out + 13, f->current_adc);
    hwfoc__put_be16(out + 15, f->temp_adc);
    hwfoc__put_be16(out + 17, f->temp2_adc);
}

void hwfoc_v4_encode_info(const hwfoc_v4_info *f, uint8_t out[HWFOC_V4_INFO_LEN]) {
    out[0] = HWFOC_SYNC;
    out[1] = HWFOC_SYNC;
    hwfoc__put_be16(out + 2, f->full_scale);
    out[4] = HWFOC_V4_INFO_MARK;
    out[5] = f->v1; out[6] = f->v2; out[7] = f->i1; out[8] = f->i2; out[9] = f->i3;
    out[10] = f->t1; out[11] = f->t2;
    out[12] = HWFOC_V4_TRAILER;
}

uint32_t hwfoc_v4_voltage_mv(uint16_t adc, uint16_t num, uint16_t den) {
    return den ? (uint32_t)((uint64_t)adc * num * 1000u / den) : 0u;
}

uint32_t hwfoc_v4_current_ma(uint16_t adc, const hwfoc_v4_info *info) {
    uint64_t ma, offset;
    if (!info->i1 || !info->i2) return 0;
    ma = (uint64_t)adc * info->i1 * 1000u / info->i2;
    offset = (uint64_t)info->i3 * 1000u;
    return ma > offset ? (uint32_t)(ma - offset) : 0u;
}

enum { HWFOC__V4_DATA, HWFOC__V4_INFO, HWFOC__V4_NOTHING, HWFOC__V4_UNDECIDED };

HWFOC__OUT_OF_LINE static int hwfoc__v4_info_eq(const hwfoc_v4_info *a, const hwfoc_v4_info *b) {
    return a->full_scale == b->full_scale && a->v1 == b->v1 && a->v2 == b->v2 && a->i1 == b->i1 &&
           a->i2 == b->i2 && a->i3 == b->i3 && a->t1 == b->t1 && a->t2 == b->t2;
}



/* What is found at c[at..n]: a plausible data frame, a plausible info frame, nothing, or too few bytes. */
static int hwfoc__v4_found_at(const uint8_t *c, size_t n, size_t at, unsigned full_scale,
                              hwfoc_v4_data *data, hwfoc_v4_info *info) {
    const uint8_t *b = c + at;
    if (at >= n) return HWFOC__V4_UNDECIDED;
    if (b[0] != HWFOC_SYNC) return HWFOC__V4_NOTHING;
    if (n - at < HWFOC_V4_INFO_LEN) return HWFOC__V4_UNDECIDED;
    /* An info frame: its fixed bytes and plausible constants (full scale, V2 not 0; I2 not 0
     * where I1 is not). Otherwise a data frame, which may carry the same fixed bytes: a counter
     * 0x9Bxxxx, an input throttle of 256 to 511, a voltage reading whose low byte is B9. */
    if (b[1] == HWFOC_SYNC && b[4] == HWFOC_V4_INFO_MARK && b[12] == HWFOC_V4_TRAILER &&
        (b[2] | b[3]) != 0 && b[6] != 0 && (b[7] == 0 || b[8] != 0)) {
        info->full_scale = hwfoc__be16(b + 2);
        info->v1 = b[5]; info->v2 = b[6]; info->i1 = b[7]; info->i2 = b[8]; info->i3 = b[9];
        info->t1 = b[10]; info->t2 = b[11];
        return HWFOC__V4_INFO;
    }
    if (n - at < HWFOC_V4_DATA_LEN) return HWFOC__V4_UNDECIDED;
    data->counter = hwfoc__be24(b + 1);
    data->throttle_in_raw = hwfoc__be16(b + 4);
    data->throttle_out_raw = hwfoc__be16(b + 6);
    data->erpm = hwfoc__be24(b + 8);
    data->voltage_adc = hwfoc__be16(b + 11);
    data->current_adc = hwfoc__be16(b + 13);
    data->temp_adc = hwfoc__be16(b + 15);
    data->temp2_adc = hwfoc__be16(b + 17);
    return data->throttle_in_raw <= full_scale && data->throttle_out_raw <= full_scale &&
                   (data->voltage_adc | data->current_adc | data->temp_adc | data->temp2_adc) < HWFOC_V4_ADC_LIMIT
               ? HWFOC__V4_DATA : HWFOC__V4_NOTHING;
}

/* Judges the candidate at stream offset `at`; a frame's kind and fields go to *f. */
static int hwfoc__v4_judge(const hwfoc_v4_stats *s, const uint8_t *c, size_t n, uint64_t at,
                           hwfoc_v4_frame *f, int *synced) {
    /* Judged by the scale it would be decoded under (Rust: v4::Stats::full_scale). */
    unsigned full_scale = s->in_use ? s->adopted.full_scale : HWFOC_V4_DEFAULT_FULL_SCALE;
    hwfoc_v4_data next_data;
    hwfoc_v4_info next_info;
    int chained = s->has_chain && s->chain_end == at;
    size_t frame_at = 0, k;
    uint32_t counter;
    switch (hwfoc__v4_found_at(c, n, 0, full_scale, &f->data, &f->info)) {
    case HWFOC__V4_UNDECIDED: return HWFOC__CHAIN_UNDECIDED;
    case HWFOC__V4_NOTHING: return HWFOC__IMPLAUSIBLE;
    case HWFOC__V4_INFO:
        f->kind = HWFOC_V4_KIND_INFO;
        switch (hwfoc__v4_found_at(c, n, HWFOC_V4_INFO_LEN, full_scale, &next_data, &next_info)) {
        case HWFOC__V4_DATA: *synced = !chained; return HWFOC__CHAIN_FRAME;
        case HWFOC__V4_INFO:
            if (chained) { *synced = 0; return HWFOC__CHAIN_FRAME; }
            return HWFOC__UNCONFIRMED;
        case HWFOC__V4_UNDECIDED: return HWFOC__CHAIN_UNDECIDED;
        default: return HWFOC__UNCONFIRMED;
        }
    default: break;
    }
    f->kind = HWFOC_V4_KIND_DATA;
    if (chained && (!s->chain_has_next || hwfoc__continues(s->chain_next, f->data.counter))) {
        *synced = 0;
        return HWFOC__CHAIN_FRAME;
    }
    counter = f->data.counter;
    for (k = 1; k < HWFOC_CHAIN_TO_LOCK; k++) {
        size_t after = frame_at + HWFOC_V4_DATA_LEN;
        if (after >= n) return HWFOC__CHAIN_UNDECIDED;
        if (c[after] == HWFOC_V4_TRAILER) frame_at = after + 1;
        else if (c[after] == HWFOC_SYNC) frame_at = after;
        else return HWFOC__UNCONFIRMED;
        counter = (counter + 1u) & HWFOC_COUNTER24_MAX;
        switch (hwfoc__v4_found_at(c, n, frame_at, full_scale, &next_data, &next_info)) {
        case HWFOC__V4_UNDECIDED: return HWFOC__CHAIN_UNDECIDED;
        case HWFOC__V4_NOTHING: return HWFOC__UNCONFIRMED;
        case HWFOC__V4_INFO: *synced = 1; return HWFOC__CHAIN_FRAME;
        default:
            if (next_data.counter != counter) return HWFOC__UNCONFIRMED;
        }
    }
    *synced = 1;
    return HWFOC__CHAIN_FRAME;
}

static void hwfoc__v4_accept(hwfoc_v4_stats *s, hwfoc_v4_frame *f, int synced) {
    if (synced) hwfoc__inc(&s->counts.syncs);
    if (f->kind == HWFOC_V4_KIND_DATA) {
        hwfoc_sequence_next(&s->counts.counter, f->data.counter, HWFOC_COUNTER24_MAX);
        s->has_chain = 1;
        s->chain_end = f->offset + HWFOC_V4_DATA_LEN;
        s->chain_has_next = 1;
        s->chain_next = (f->data.counter + 1u) & HWFOC_COUNTER24_MAX;
        s->chain_trailer = 1;
        f->has_info = s->in_use;
        if (f->has_info) f->info = s->adopted;
        else memset(&f->info, 0, sizeof f->info);
    } else {
        int same = s->has_last_info && hwfoc__v4_info_eq(&s->last_info, &f->info);
        hwfoc__inc(&s->info_frames);
        if (same && !(s->has_adopted && hwfoc__v4_info_eq(&s->adopted, &f->info))) {
            s->adopted = f->info;
            s->has_adopted = 1;
            hwfoc__inc(&s->adoptions);
        } else if (!same && s->has_last_info) {
            hwfoc__inc(&s->disagreements);
        }
        s->last_info = f->info;
        s->has_last_info = 1;
        s->in_use = s->has_adopted && hwfoc__v4_info_eq(&s->adopted, &f->info);
        if (!(s->has_chain && !synced)) s->chain_has_next = 0;
        s->has_chain = 1;
        s->chain_end = f->offset + HWFOC_V4_INFO_LEN;
        s->chain_trailer = 0;
        f->has_info = 1;
        memset(&f->data, 0, sizeof f->data);
    }
}

static size_t hwfoc_v4_trailer(void *dec, const uint8_t *data, size_t n, uint64_t base, size_t pos) {
    hwfoc_v4_stats *s = &((hwfoc_v4_decoder *)dec)->stats;
    if (pos < n && data[pos] == HWFOC_V4_TRAILER && s->has_chain && s->chain_trailer &&
        s->chain_end == ((base + pos) & HWFOC__BYTES_MASK)) {
        s->chain_end += 1;
        s->chain_trailer = 0;
        hwfoc__inc(&s->trailers);
        return pos + 1;
    }
    return pos;
}

static int hwfoc_v4_take(void *dec, const uint8_t *c, size_t n, uint64_t at, int at_end, size_t *len,
                         hwfoc__any_cb any, void *ctx) {
    hwfoc_v4_stats *s = &((hwfoc_v4_decoder *)dec)->stats;
    hwfoc_v4_frame f;
    int synced = 0, v;
    f.offset = at;
    v = hwfoc__v4_judge(s, c, n, at, &f, &synced);
    if (v != HWFOC__CHAIN_FRAME) return hwfoc__chain_reject(&s->counts, v, at_end);
    hwfoc__v4_accept(s, &f, synced);
    *len = f.kind == HWFOC_V4_KIND_DATA ? HWFOC_V4_DATA_LEN : HWFOC_V4_INFO_LEN;
    if (any) ((hwfoc_v4_cb)any)(ctx, &f);
    return HWFOC__FRAME;
}

HWFOC__STREAM(hwfoc_v4, hwfoc_v4_decoder, hwfoc_v4_cb, counts.bytes, counts.bytes_skipped, held,
              hwfoc__next_byte, hwfoc__find_sync, hwfoc_v4_trailer,
              hwfoc_sequence_line_silent(&d->stats.counts.counter, max_frames, HWFOC_COUNTER24_MAX))
#endif

/* ---------------------------------------------------------------- HW5 implementation */
#ifndef HWFOC_NO_HW5

static const char *const hwfoc__hw5_faults[8] = {
    "motor_locked", "over_temperature", "throttle_not_zero_at_start", "throttle_signal_lost",
    "over_current", "low_voltage", "input_voltage_error", "motor_connection_error"};

const char *hwfoc_hw5_fault_name(unsigned bit) { return bit < 8u ? hwfoc__hw5_faults[bit] : "?"; }

static const uint8_t hwfoc__hw5_len[HWFOC_HW5_KINDS] = {32, 11, 73, 10, 105, 58, 9, 10};

void hwfoc_hw5_encode(const hwfoc_hw5_frame *f, uint8_t out[HWFOC_HW5_TELEMETRY_LEN]) {
    static const uint8_t header[9] = {0xFE, 0x01, 0x00, 0x03, 0x30, 0x5C, 0x17, 0x06, 0x00};
    memcpy(out, header, sizeof header);
    out[9] = f->throttle;
    out[10] = f->unknown[0];
    out[11] = f->unknown[1];
    out[12] = f->fault;
    hwfoc__put_le16(out + 13, f->erpm_raw);
    hwfoc__put_le16(out + 15, f->voltage_raw);
    hwfoc__put_le16(out + 17, f->current_raw);
    out[19] = f->esc_temp;
    out[20] = f->bec_temp;
    out[21] = f->motor_temp;
    out[22] = f->bec_voltage_raw;
    out[23] = f->bec_current_raw;
    memset(out + 24, 0xFF, 6);
    hwfoc__put_le16(out + 30, hwfoc_crc16_modbus(out, 30));
}

/* 1: from the ESC (FE 01), 2: to it (01 FD), 0: neither. */
static int hwfoc__hw5_direction(uint8_t a, uint8_t b) { return a == 0xFE && b == 0x01 ? 1 : a == 0x01 && b == 0xFD ? 2 : 0; }

/* The kinds a header may be, in the order they are tried: *count of them from *first. */
static void hwfoc__hw5_kinds(int dir, uint8_t code, uint16_t type, unsigned *first, unsigned *count) {
    *count = 1;
    if (dir == 1 && type == 0x5C30 && code == 0x03) *first = HWFOC_HW5_TELEMETRY;
    else if (dir == 1 && type == 0x242C) *first = HWFOC_HW5_PING;
    else if (dir == 1 && type == 0x252C) *first = HWFOC_HW5_DEVICE_INFO;
    else if (dir == 1 && type == 0x022B) *first = HWFOC_HW5_RESET;
    else if (dir == 1 && type == 0x3835) { *first = 0; *count = 3; } /* write error, written, read */
    else if (dir == 2 && type == 0x242C) *first = HWFOC_HW5_PING_REQUEST;
    else *count = 0;
}
static const uint8_t hwfoc__hw5_parameters[3] = {HWFOC_HW5_PARAMETERS_WRITE_ERROR, HWFOC_HW5_PARAMETERS_WRITTEN,
                                                 HWFOC_HW5_PARAMETERS_READ};
static unsigned hwfoc__hw5_kind(unsigned first, unsigned count, unsigned j) {
    return count == 3 ? hwfoc__hw5_parameters[j] : first;
}



static size_t hwfoc__hw5_find(const uint8_t *h, size_t n) {
    size_t j;
    for (j = 0; j < n; j++) {
        if (j + 1 < n ? hwfoc__hw5_direction(h[j], h[j + 1]) != 0 : (h[j] == 0xFE || h[j] == 0x01)) return j;
    }
    return n;
}

/* Judges a candidate: a frame (its kind in *kind), or why not. */
static int hwfoc__hw5_judge(hwfoc_hw5_stats *s, const uint8_t *c, size_t n, int at_end, unsigned *kind) {
    unsigned first = 0, count = 0, j;
    int dir;
    if (n < 2) return at_end ? HWFOC__REJECTED : HWFOC__UNDECIDED;
    dir = hwfoc__hw5_direction(c[0], c[1]);
    if (!dir) return HWFOC__REJECTED;
    if (n < 3) return at_end ? HWFOC__REJECTED : HWFOC__UNDECIDED;
    if (c[2] != (dir == 1 ? 0x00 : 0x03)) { hwfoc__inc(&s->bad_headers); return HWFOC__REJECTED; }
    if (n < 6) return at_end ? HWFOC__REJECTED : HWFOC__UNDECIDED;
    hwfoc__hw5_kinds(dir, c[3], hwfoc__le16(c + 4), &first, &count);
    if (!count) { hwfoc__inc(&s->unknown_types); return HWFOC__REJECTED; }
    if (first == HWFOC_HW5_TELEMETRY && count == 1) {
        if (n < 7) return at_end ? HWFOC__REJECTED : HWFOC__UNDECIDED;
        if (c[6] != 0x17) { hwfoc__inc(&s->bad_headers); return HWFOC__REJECTED; }
    }
    for (j = 0; j < count; j++) {
        unsigned k = hwfoc__hw5_kind(first, count, j);
        size_t len = hwfoc__hw5_len[k];
        if (n < len) return at_end ? HWFOC__REJECTED : HWFOC__UNDECIDED;
        if (hwfoc_crc16_modbus(c, len - 2) == hwfoc__le16(c + len - 2)) { *kind = k; return HWFOC__FRAME; }
    }
    hwfoc__inc(&s->crc_failures);
    return HWFOC__REJECTED;
}

static int hwfoc_hw5_take(void *dec, const uint8_t *c, size_t n, uint64_t at, int at_end, size_t *len,
                          hwfoc__any_cb any, void *ctx) {
    hwfoc_hw5_stats *s = &((hwfoc_hw5_decoder *)dec)->stats;
    hwfoc_hw5_frame f;
    unsigned kind = 0;
    uint32_t *counter;
    int v = hwfoc__hw5_judge(s, c, n, at_end, &kind);
    if (v != HWFOC__FRAME) return v;
    *len = hwfoc__hw5_len[kind];
    counter = &s->frames[kind];
    if (kind == HWFOC_HW5_TELEMETRY) {
        f.offset = at;
        f.throttle = c[9];
        f.unknown[0] = c[10];
        f.unknown[1] = c[11];
        f.fault = c[12];
        f.erpm_raw = hwfoc__le16(c + 13);
        f.voltage_raw = hwfoc__le16(c + 15);
        f.current_raw = hwfoc__le16(c + 17);
        f.esc_temp = c[19];
        f.bec_temp = c[20];
        f.motor_temp = c[21];
        f.bec_voltage_raw = c[22];
        f.bec_current_raw = c[23];
        if (f.throttle > HWFOC_HW5_THROTTLE_MAX_PCT || f.voltage_raw > HWFOC_HW5_VOLTAGE_MAX_RAW) {
            counter = &s->out_of_range; /* a corrupted frame whose CRC still matches */
            v = HWFOC__REJECTED;
        }
    }
    hwfoc__inc(counter);
    /* other kinds are counted, not handed on */
    if (v == HWFOC__FRAME && kind == HWFOC_HW5_TELEMETRY && any) ((hwfoc_hw5_cb)any)(ctx, &f);
    return v;
}

HWFOC__STREAM(hwfoc_hw5, hwfoc_hw5_decoder, hwfoc_hw5_cb, bytes, bytes_skipped, held,
              hwfoc__next_byte, hwfoc__hw5_find, NULL,
              (void)d; (void)max_frames)
#endif

/* ---------------------------------------------------------------- DroneCAN implementation */
#ifndef HWFOC_NO_CAN
/* Each type's fields: a width of 1..32 bits, 0x40 added for a signed field, 0x80 for a float16
 * (packed as the Rust codec packs it from a float: infinities saturated to +-65504, any NaN
 * made 0x7FFF with its sign); 0 ends the list. */
#define HWFOC__S 0x40u
#define HWFOC__F 0x80u
static const uint8_t hwfoc__can_layout[HWFOC_CAN_TYPES][HWFOC_CAN_MAX_FIELDS + 1] = {
    {16, 16, 16},
    {16 | HWFOC__S, 16 | HWFOC__S, 8},
    {8, 8, 8},
    {32, 2, 3, 3, 16},
    {32, 16 | HWFOC__F, 16 | HWFOC__F, 16 | HWFOC__F, 18 | HWFOC__S, 7, 5},
    {7, 7, 9 | HWFOC__S, 9, 19, 5},
    {8, 8},
    {8, 8},
    {8},
    {0},
    {8, 8, 8},
    {8, 8, 8},
    {8},
    {8},
    {8, 16, 8},
    {8, 16, 8},
    {8},
    {8},
    {0},
    {8},
    {8, 16},
    {8},
    {32, 24},
    {8},
    {1, 1, 6, 5, 3, 4, 4, 16, 16}};

unsigned hwfoc_can_fields(hwfoc_can_type type) {
    unsigned n = 0;
    if ((unsigned)type >= HWFOC_CAN_TYPES) return 0;
    while (n < HWFOC_CAN_MAX_FIELDS && hwfoc__can_layout[type][n]) n++;
    return n;
}

static unsigned hwfoc__can_bits(hwfoc_can_type type) {
    unsigned i, bits = 0;
    for (i = 0; i < hwfoc_can_fields(type); i++) bits += hwfoc__can_layout[type][i] & 0x3Fu;
    return bits;
}

/* DroneCAN's bit order: a value's bytes little-endian, each byte's bits (the last byte's low
 * bits only) most significant first. */
size_t hwfoc_can_pack(hwfoc_can_type type, const int32_t *fields, uint8_t out[HWFOC_CAN_MAX_PAYLOAD]) {
    unsigned i, k, bit = 0;
    memset(out, 0, HWFOC_CAN_MAX_PAYLOAD);
    for (i = 0; i < hwfoc_can_fields(type); i++) {
        unsigned width = hwfoc__can_layout[type][i] & 0x3Fu, left = width;
        uint32_t max = width == 32 ? 0xFFFFFFFFu : (1u << width) - 1u, value;
        if (hwfoc__can_layout[type][i] & HWFOC__S) {
            int32_t most = (int32_t)(max >> 1), v = fields[i];
            v = v > most ? most : v < -most - 1 ? -most - 1 : v;
            value = (uint32_t)v & max;
        } else {
            value = (uint32_t)fields[i] > max ? max : (uint32_t)fields[i];
            if ((hwfoc__can_layout[type][i] & HWFOC__F) && (value & 0x7C00u) == 0x7C00u)
                value = (value & 0x8000u) | (value & 0x03FFu ? 0x7FFFu : 0x7BFFu);
        }
        while (left) {
            unsigned n = left < 8 ? left : 8;
            for (k = n; k-- > 0; bit++)
                if (value >> k & 1u) out[bit / 8] = (uint8_t)(out[bit / 8] | 0x80u >> (bit % 8));
            value >>= 8;
            left -= n;
        }
    }
    return (hwfoc__can_bits(type) + 7u) / 8u;
}

int hwfoc_can_unpack(hwfoc_can_type type, const uint8_t *payload, size_t len, int32_t *fields) {
    unsigned i, k, bit = 0;
    if ((unsigned)type >= HWFOC_CAN_TYPES || len != (hwfoc__can_bits(type) + 7u) / 8u) return -1;
    for (i = 0; i < hwfoc_can_fields(type); i++) {
        unsigned width = hwfoc__can_layout[type][i] & 0x3Fu, left = width, shift = 0;
        uint32_t value = 0;
        while (left) {
            unsigned n = left < 8 ? left : 8, byte = 0;
            for (k = 0; k < n; k++, bit++) byte = byte << 1 | ((unsigned)payload[bit / 8] >> (7u - bit % 8) & 1u);
            value |= (uint32_t)byte << shift;
            shift += 8;
            left -= n;
        }
        if ((hwfoc__can_layout[type][i] & HWFOC__S) && width < 32 && (value >> (width - 1) & 1u))
            value |= ~0u << width; /* sign-extended */
        fields[i] = (int32_t)value;
    }
    return 0;
}
#undef HWFOC__S
#undef HWFOC__F
#endif

/* ---------------------------------------------------------------- conversions */
uint32_t hwfoc_throttle_centipct(uint32_t raw, uint32_t full_scale) {
    return full_scale ? (uint32_t)((uint64_t)raw * 10000u / full_scale) : 0u;
}

uint32_t hwfoc_rpm(uint32_t erpm, uint16_t pole_pairs, uint16_t gear_num, uint16_t gear_den) {
    uint64_t div = (uint64_t)pole_pairs * gear_num;
    return div ? (uint32_t)((uint64_t)erpm * gear_den / div) : 0u;
}

uint32_t hwfoc_erpm_of_raw(uint16_t raw) { return (uint32_t)raw * 10u; }

uint32_t hwfoc_decivolts_mv(uint16_t raw) { return (uint32_t)raw * 100u; }

int32_t hwfoc_foc_current_ma(int16_t raw) { return (int32_t)raw * 125 / 8; }

/* Temperature (degrees C) of each table index 0..129: the code HW-FOC sends. */
static const uint8_t hwfoc__adc_table[130] = {
    241, 240, 239, 238, 237, 236, 235, 234, 233, 232, 231, 230, 229, 228, 227, 226, 224, 223, 222, 220,
    219, 217, 216, 214, 213, 211, 209, 208, 206, 204, 202, 201, 199, 197, 195, 193, 191, 189, 187, 185,
    183, 181, 179, 177, 174, 172, 170, 168, 166, 164, 161, 159, 157, 154, 152, 150, 148, 146, 143, 141,
    139, 136, 134, 132, 130, 128, 125, 123, 121, 119, 117, 115, 113, 111, 109, 106, 105, 103, 101, 99,
    97, 95, 93, 91, 90, 88, 85, 84, 82, 81, 79, 77, 76, 74, 73, 72, 69, 68, 66, 65,
    64, 62, 62, 61, 59, 58, 56, 54, 54, 53, 51, 51, 50, 48, 48, 46, 46, 44, 43, 43,
    41, 41, 39, 39, 39, 37, 37, 35, 35, 33};

/* Tenths of a degree of an exact code (the mean of its run of table entries); -1 if none. */
static int32_t hwfoc__exact_dc(unsigned code) {
    unsigned t, end;
    for (t = 0; t < 130; t++) {
        if (hwfoc__adc_table[t] == code) {
            for (end = t; end + 1 < 130 && hwfoc__adc_table[end + 1] == code; end++) {}
            return (int32_t)(t + end) * 5;
        }
    }
    return -1;
}

int hwfoc_temp_decidegrees(uint8_t code, int16_t *decidegrees) {
    unsigned lo, hi;
    int32_t tlo, thi, v;
    if (code > 241) return -1;
    if (code < 33) return 1;
    v = hwfoc__exact_dc(code);
    if (v < 0) {
        for (lo = code; (tlo = hwfoc__exact_dc(lo)) < 0; lo--) {}
        for (hi = code; (thi = hwfoc__exact_dc(hi)) < 0; hi++) {}
        /* Linear between the neighbours, rounded to the nearest tenth (thi < tlo). */
        v = tlo - (int32_t)(((tlo - thi) * (int32_t)(code - lo) * 2 + (int32_t)(hi - lo)) / (2 * (int32_t)(hi - lo)));
    }
    *decidegrees = (int16_t)v;
    return 0;
}

#ifdef HWFOC_FLOAT
float hwfoc_foc_current_a(int16_t raw, float current_scale) { return (float)raw / current_scale; }
#ifndef HWFOC_NO_V4
float hwfoc_v4_voltage_v(uint16_t adc, uint16_t num, uint16_t den) { return (float)adc * (float)num / (float)den; }
float hwfoc_v4_ntc_celsius(uint16_t adc) {
    double ratio, kelvin;
    if (adc == 0 || adc >= HWFOC_V4_ADC_LIMIT) return (float)NAN;
    ratio = (double)adc / (4096.0 - (double)adc) / 4.7;
    kelvin = 1.0 / (log(ratio) / 3950.0 + 1.0 / 298.15);
    return (float)(kelvin - 273.15);
}
#endif
#endif

#ifdef __cplusplus
}
#endif
#endif /* HWFOC_IMPLEMENTED */
#endif /* HWFOC_IMPLEMENTATION */
