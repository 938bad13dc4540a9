/* SPDX-License-Identifier: MIT OR Apache-2.0 */
/* The growing list of integers both shims hand their frames and statistics out in. */
#ifndef FLAT_OUT_H
#define FLAT_OUT_H
#include <stdint.h>
#include <stdlib.h>

typedef struct flat_out {
    uint64_t *out;
    size_t len, cap;
    int oom;
} flat_out;

static void flat_put(flat_out *o, uint64_t v) {
    if (o->len == o->cap) {
        size_t cap = o->cap ? 2 * o->cap : 1024;
        uint64_t *out = (uint64_t *)realloc(o->out, cap * sizeof *out);
        if (!out) { o->oom = 1; return; }
        o->out = out;
        o->cap = cap;
    }
    o->out[o->len++] = v;
}

/* The integers so far (and forgets them): their count, or -1 out of memory. */
static long flat_take(flat_out *o, const uint64_t **out) {
    long n = o->oom ? -1 : (long)o->len;
    *out = o->out;
    o->len = 0;
    return n;
}
#endif
