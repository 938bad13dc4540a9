/* SPDX-License-Identifier: MIT OR Apache-2.0 */
/* Prints the frames read from a serial port (POSIX termios) or a file, one line each.
 *
 *   cc -std=c99 -I.. serial.c -o serial
 *   ./serial /dev/ttyUSB0 foc          # HW-FOC at 19200 baud
 *   ./serial /dev/ttyUSB0 datalink     # DataLink V2 at 115200 (also v3, v4, hw5)
 *   ./serial capture.bin v4            # a file of raw bytes
 *   ./serial --self-test               # encodes a frame of every format and prints them
 *
 * Try it with the simulator: `hwfoc simulate --pty` prints the pty it writes to. */
#define HWFOC_IMPLEMENTATION
#include "hwfoc.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

static void on_foc(void *ctx, const hwfoc_foc_frame *f) {
    int16_t dc = 0;
    (void)ctx;
    if (f->kind == HWFOC_FOC_KIND_INFO) {
        printf("foc info @%llu: %.72s\n", (unsigned long long)f->offset, (const char *)f->info_text);
        return;
    }
    printf("foc data @%llu: packet %u, throttle %u/10000, %lu rpm, %lu mV, %ld mA, status 0x%04X",
           (unsigned long long)f->offset, f->data.packet, hwfoc_throttle_centipct(f->data.throttle_in_raw, 1024),
           (unsigned long)hwfoc_rpm(hwfoc_erpm_of_raw(f->data.erpm_raw), 7, 1, 1),
           (unsigned long)hwfoc_decivolts_mv(f->data.voltage_raw), (long)hwfoc_foc_current_ma(f->data.current_raw),
           f->data.status);
    if (hwfoc_temp_decidegrees(f->data.mos_adc, &dc) == 0) printf(", MOS %d.%d C", dc / 10, dc % 10);
    printf("\n");
}

static void on_dl(void *ctx, const hwfoc_dl_frame *f) {
    unsigned ch;
    (void)ctx;
    printf("datalink @%llu: counter %u", (unsigned long long)f->offset, f->counter);
    for (ch = 0; ch < HWFOC_DL_CHANNELS; ch++)
        if ((unsigned)f->present >> ch & 1u)
            printf(", esc %u: %lu erpm %ld mA", ch + 1, (unsigned long)hwfoc_erpm_of_raw(f->slots[ch].erpm_raw),
                   (long)hwfoc_foc_current_ma(f->slots[ch].current_raw));
    printf("\n");
}

static void on_v3(void *ctx, const hwfoc_v3_frame *f) {
    (void)ctx;
    printf("v3 @%llu: counter %lu, throttle %u/255, pwm %u/255, %lu erpm\n", (unsigned long long)f->offset,
           (unsigned long)f->counter, f->throttle_in_raw, f->pwm_out_raw, (unsigned long)hwfoc_v3_erpm(f->period_us));
}

static void on_v4(void *ctx, const hwfoc_v4_frame *f) {
    (void)ctx;
    if (f->kind == HWFOC_V4_KIND_INFO) {
        printf("v4 info @%llu: full scale %u, %u/%u V per step\n", (unsigned long long)f->offset,
               f->info.full_scale, f->info.v1, f->info.v2 * 10u);
        return;
    }
    printf("v4 data @%llu: counter %lu, %lu erpm, %lu mV", (unsigned long long)f->offset,
           (unsigned long)f->data.counter, (unsigned long)f->data.erpm,
           (unsigned long)(f->has_info ? hwfoc_v4_voltage_mv(f->data.voltage_adc, f->info.v1, (uint16_t)(f->info.v2 * 10u))
                                       : hwfoc_v4_voltage_mv(f->data.voltage_adc, 8, 910)));
    if (f->has_info && f->info.i1) printf(", %lu mA", (unsigned long)hwfoc_v4_current_ma(f->data.current_adc, &f->info));
    printf("\n");
}

static void on_hw5(void *ctx, const hwfoc_hw5_frame *f) {
    unsigned bit;
    (void)ctx;
    printf("hw5 @%llu: throttle %u %%, %lu erpm, %lu mV, %u.%u A, ESC %u C", (unsigned long long)f->offset,
           f->throttle, (unsigned long)hwfoc_erpm_of_raw(f->erpm_raw), (unsigned long)hwfoc_decivolts_mv(f->voltage_raw),
           f->current_raw / 10u, f->current_raw % 10u, f->esc_temp);
    for (bit = 0; bit < 8; bit++)
        if ((unsigned)f->fault >> bit & 1u) printf(" %s", hwfoc_hw5_fault_name(bit));
    printf("\n");
}

static int self_test(void) {
    static hwfoc_foc_decoder foc;
    static hwfoc_dl_decoder dl;
    static hwfoc_v3_decoder v3;
    static hwfoc_v4_decoder v4;
    static hwfoc_hw5_decoder hw5;
    uint8_t buf[HWFOC_DL_FRAME_LEN];
    hwfoc_foc_data data = {1, 512, 512, 700, 252, 640, 0, 200, 200, 0};
    hwfoc_dl_frame hub;
    hwfoc_v3_frame three = {0, 5, 100, 100, 6000};
    hwfoc_v4_data four = {7, 500, 500, 7000, 2730, 100, 1000, 1000};
    hwfoc_hw5_frame five;
    hwfoc_foc_init(&foc);
    hwfoc_foc_encode_data(&data, buf);
    hwfoc_foc_feed(&foc, buf, HWFOC_FOC_DATA_LEN, on_foc, NULL);
    hwfoc_dl_init(&dl);
    memset(&hub, 0, sizeof hub);
    hub.present = 1;
    hub.slots[0] = data;
    hwfoc_dl_encode(&hub, buf);
    hwfoc_dl_feed(&dl, buf, HWFOC_DL_FRAME_LEN, on_dl, NULL);
    hwfoc_v3_init(&v3);
    for (three.counter = 5; three.counter < 8; three.counter++) {
        hwfoc_v3_encode(&three, buf);
        hwfoc_v3_feed(&v3, buf, HWFOC_V3_FRAME_LEN, on_v3, NULL);
    }
    hwfoc_v4_init(&v4);
    for (four.counter = 7; four.counter < 10; four.counter++) {
        hwfoc_v4_encode_data(&four, buf);
        hwfoc_v4_feed(&v4, buf, HWFOC_V4_DATA_LEN, on_v4, NULL);
    }
    hwfoc_hw5_init(&hw5);
    memset(&five, 0, sizeof five);
    five.throttle = 40;
    five.fault = 0x11;
    hwfoc_hw5_encode(&five, buf);
    hwfoc_hw5_feed(&hw5, buf, HWFOC_HW5_TELEMETRY_LEN, on_hw5, NULL);
    return foc.stats.packets.count == 1 && dl.stats.counter.count == 1 && v3.stats.counts.counter.count == 3 &&
                   v4.stats.counts.counter.count == 3 && hw5.stats.frames[HWFOC_HW5_TELEMETRY] == 1
               ? 0 : 1;
}

int main(int argc, char **argv) {
    static hwfoc_foc_decoder foc;
    static hwfoc_dl_decoder dl;
    static hwfoc_v3_decoder v3;
    static hwfoc_v4_decoder v4;
    static hwfoc_hw5_decoder hw5;
    uint8_t buf[256];
    const char *format;
    speed_t speed;
    int fd, tty;
    ssize_t n;
    if (argc == 2 && strcmp(argv[1], "--self-test") == 0) return self_test();
    if (argc != 3) {
        fprintf(stderr, "usage: %s PORT-OR-FILE foc|datalink|v3|v4|hw5\n", argv[0]);
        return 2;
    }
    format = argv[2];
    if (strcmp(format, "foc") && strcmp(format, "datalink") && strcmp(format, "v3") && strcmp(format, "v4") &&
        strcmp(format, "hw5")) {
        fprintf(stderr, "%s: unknown format %s (foc, datalink, v3, v4 or hw5)\n", argv[0], format);
        return 2;
    }
    fd = open(argv[1], O_RDONLY | O_NOCTTY);
    if (fd < 0) {
        fprintf(stderr, "%s: cannot open %s: %s\n", argv[0], argv[1], strerror(errno));
        return 1;
    }
    speed = strcmp(format, "datalink") == 0 || strcmp(format, "hw5") == 0 ? B115200 : B19200;
    tty = isatty(fd);
    if (tty) {
        struct termios t;
        if (tcgetattr(fd, &t) != 0) {
            fprintf(stderr, "%s: %s: %s\n", argv[0], argv[1], strerror(errno));
            return 1;
        }
        /* Raw 8N1: no line editing, no translation, no echo. */
        t.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON);
        t.c_oflag &= ~(tcflag_t)OPOST;
        t.c_lflag &= ~(tcflag_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
        t.c_cflag &= ~(tcflag_t)(CSIZE | PARENB | CSTOPB);
        t.c_cflag |= (tcflag_t)(CS8 | CLOCAL | CREAD);
        cfsetispeed(&t, speed);
        cfsetospeed(&t, speed);
        t.c_cc[VMIN] = 1;
        t.c_cc[VTIME] = 0;
        if (tcsetattr(fd, TCSANOW, &t) != 0) {
            fprintf(stderr, "%s: %s: %s\n", argv[0], argv[1], strerror(errno));
            return 1;
        }
    }
    hwfoc_foc_init(&foc);
    hwfoc_dl_init(&dl);
    hwfoc_v3_init(&v3);
    hwfoc_v4_init(&v4);
    hwfoc_hw5_init(&hw5);
    while ((n = read(fd, buf, sizeof buf)) > 0) {
        size_t len = (size_t)n;
        switch (format[0] == 'f' ? 0 : format[0] == 'd' ? 1 : format[1] == '3' ? 2 : format[1] == '4' ? 3 : 4) {
        case 0: hwfoc_foc_feed(&foc, buf, len, on_foc, NULL); break;
        case 1: hwfoc_dl_feed(&dl, buf, len, on_dl, NULL); break;
        case 2: hwfoc_v3_feed(&v3, buf, len, on_v3, NULL); break;
        case 3: hwfoc_v4_feed(&v4, buf, len, on_v4, NULL); break;
        default: hwfoc_hw5_feed(&hw5, buf, len, on_hw5, NULL); break;
        }
        fflush(stdout);
    }
    /* A pseudo-terminal whose other side closed reads EIO: the line hung up, the stream ended. */
    if (n < 0 && !(errno == EIO && tty)) {
        fprintf(stderr, "%s: reading %s: %s\n", argv[0], argv[1], strerror(errno));
        return 1;
    }
    hwfoc_foc_flush(&foc, on_foc, NULL);
    hwfoc_dl_flush(&dl, on_dl, NULL);
    hwfoc_v3_flush(&v3, on_v3, NULL);
    hwfoc_v4_flush(&v4, on_v4, NULL);
    hwfoc_hw5_flush(&hw5, on_hw5, NULL);
    return 0;
}
