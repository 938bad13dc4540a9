//! The scanner's search window: where candidates and frame headers are in the next 64
//! positions, found at once, with no branch per byte.
//!
//! In line noise the scanner's work is finding where the next frame starts after a run of
//! garbage. A search that stops at the first candidate branches on the run's length, which the
//! processor cannot predict; a window decided at once costs the same whatever the run, and in
//! noise full of fake headers (`9B 16` with no frame behind it) it also counts them together
//! instead of one stop each.
//!
//! [`syncs`] is the scanner's first look after a run of noise, the window's sync bytes alone.
//! A scanner that reads another protocol too ([`crate::mixed`]) names that protocol's second
//! bytes, and the window marks where its candidates are (`stops`), for the scanner to stop
//! there.
//!
//! The window is four SSE2 compares per byte value and a movemask per 16 positions, on x86_64
//! (which always has SSE2). Elsewhere there is none ([`window`] gives `None`) and the scanner
//! searches a word at a time: a window computed a byte at a time would cost a microcontroller
//! more than the branches it saves. (NEON on aarch64 could give one; not written yet.)

#[cfg(any(test, all(target_arch = "x86_64", target_feature = "sse2")))]
use crate::foc::frame::{HEADERS, LENGTH_BYTES};
#[cfg(any(test, all(target_arch = "x86_64", target_feature = "sse2")))]
use crate::wire::SYNC;

/// Positions of a window.
pub(crate) const WINDOW: usize = 64;

/// Bytes a window reads: its positions and the three bytes after the last, which a header
/// at the last position ends with.
pub(crate) const WINDOW_BYTES: usize = WINDOW + 3;

/// What a window holds, bit `i` for position `i`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Window {
    /// A sync byte followed by a known length byte: where the scanner tries a frame, and,
    /// when none is there and its bytes are all in, a checksum failure.
    pub(crate) candidates: u64,
    /// A kind's whole header (sync, length byte, version, command): the candidates that can
    /// be frames.
    pub(crate) headers: u64,
    /// A sync byte followed by one of the second bytes the caller names: another protocol's
    /// candidates, where a scanner that reads both must stop (the mixed scanner's DataLink
    /// candidates; none for the HW-FOC scanner).
    pub(crate) stops: u64,
}

/// The window of `w`'s first [`WINDOW`] positions, its stops a sync byte followed by one of
/// `stops` (a constant of the caller's; with none, nothing of them is computed), where the
/// target has a vector unit this module uses (SSE2): `None` elsewhere.
#[inline(always)]
pub(crate) fn window(w: &[u8; WINDOW_BYTES], stops: &[u8]) -> Option<Window> {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        // SAFETY: the function needs SSE2, which this build enables (the `cfg` above; x86_64
        // always has it). With `syncs`, the codec's only `unsafe`: `core::arch`'s compare and
        // movemask need a target feature, and LLVM makes neither from portable code.
        #[allow(unsafe_code)]
        let window = unsafe { sse2::window(w, stops) };
        Some(window)
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        let _ = (w, stops);
        None
    }
}

/// The sync bytes of `w`, bit `i` for position `i`, where the target has a vector unit this
/// module uses (SSE2): `None` elsewhere. One compare and one movemask per 16 positions: the
/// scanner's first look after a run of garbage, whose frame usually starts at the run's first
/// sync byte.
#[inline(always)]
pub(crate) fn syncs(w: &[u8; WINDOW]) -> Option<u64> {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        // SAFETY: as in `window`: SSE2 is enabled in this build.
        #[allow(unsafe_code)]
        let syncs = unsafe { sse2::syncs(w) };
        Some(syncs)
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        let _ = w;
        None
    }
}

#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
pub(crate) mod sse2 {
    use core::arch::x86_64::{
        __m128i, _mm_and_si128, _mm_cmpeq_epi8, _mm_movemask_epi8, _mm_or_si128, _mm_set_epi64x,
        _mm_set1_epi8, _mm_setzero_si128,
    };

    use super::{HEADERS, LENGTH_BYTES, SYNC, WINDOW, WINDOW_BYTES, Window};

    /// Sixteen bytes of `w` from `at` (two little-endian words: a plain unaligned load once
    /// compiled, with no pointer). The candidate map's SSE2 code takes them here too.
    #[target_feature(enable = "sse2")]
    #[inline]
    pub(crate) fn sixteen<const N: usize>(w: &[u8; N], at: usize) -> __m128i {
        let word = |from: usize| {
            let mut b = [0; 8];
            b.copy_from_slice(&w[from..from + 8]);
            i64::from_le_bytes(b)
        };
        _mm_set_epi64x(word(at + 8), word(at))
    }

    /// [`super::syncs`] with SSE2.
    #[target_feature(enable = "sse2")]
    #[inline]
    pub(super) fn syncs(w: &[u8; WINDOW]) -> u64 {
        let sync = _mm_set1_epi8(SYNC as i8);
        let mut syncs = 0;
        for at in (0..WINDOW).step_by(16) {
            let mask = _mm_movemask_epi8(_mm_cmpeq_epi8(sixteen(w, at), sync));
            syncs |= u64::from(mask as u16) << at;
        }
        syncs
    }

    /// [`super::window`] with SSE2: per 16 positions, the bytes at offsets 0 to 3 of each
    /// position compared with the sync byte, the length bytes and the kinds' headers, and a
    /// movemask of each result.
    #[target_feature(enable = "sse2")]
    #[inline]
    pub(super) fn window(w: &[u8; WINDOW_BYTES], stops: &[u8]) -> Window {
        let mut candidates = 0;
        let mut headers = 0;
        let mut stopped = 0;
        for at in (0..WINDOW).step_by(16) {
            // Sixteen bytes from `at + k` (two little-endian words: a plain unaligned load
            // once compiled, with no pointer).
            let bytes = |k: usize| -> __m128i {
                let word = |from: usize| {
                    let mut b = [0; 8];
                    b.copy_from_slice(&w[from..from + 8]);
                    i64::from_le_bytes(b)
                };
                _mm_set_epi64x(word(at + k + 8), word(at + k))
            };
            let equal = |v: __m128i, b: u8| _mm_cmpeq_epi8(v, _mm_set1_epi8(b as i8));
            let b = [bytes(0), bytes(1), bytes(2), bytes(3)];
            let sync = equal(b[0], SYNC);
            let mut length_byte = _mm_setzero_si128();
            for l in LENGTH_BYTES {
                length_byte = _mm_or_si128(length_byte, equal(b[1], l));
            }
            let mut header = _mm_setzero_si128();
            for h in HEADERS {
                let first = _mm_and_si128(equal(b[0], h[0]), equal(b[1], h[1]));
                let last = _mm_and_si128(equal(b[2], h[2]), equal(b[3], h[3]));
                header = _mm_or_si128(header, _mm_and_si128(first, last));
            }
            let mask = |v: __m128i| u64::from(_mm_movemask_epi8(v) as u16);
            candidates |= mask(_mm_and_si128(sync, length_byte)) << at;
            headers |= mask(header) << at;
            if !stops.is_empty() {
                let mut second = _mm_setzero_si128();
                for &l in stops {
                    second = _mm_or_si128(second, equal(b[1], l));
                }
                stopped |= mask(_mm_and_si128(sync, second)) << at;
            }
        }
        Window {
            candidates,
            headers,
            stops: stopped,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The window gives what a plain search gives, over random windows dense in sync bytes,
    /// length bytes and headers (whole or with one bit flipped).
    #[test]
    #[cfg_attr(
        not(all(target_arch = "x86_64", target_feature = "sse2")),
        ignore = "needs x86_64 (the window is SSE2; other targets search a word at a time)"
    )]
    fn window_matches_a_plain_search() {
        // Stops as the mixed scanner's (DataLink's length bytes) and one that is not.
        const STOPS: [u8; 3] = [0x9E, 0xA0, 0x17];
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut w = [0u8; WINDOW_BYTES];
        for round in 0..50_000 {
            let mut i = 0;
            while i < WINDOW_BYTES {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let pick = (x >> 58) as usize % (2 + round % 9);
                let h = HEADERS[(x >> 20) as usize % HEADERS.len()];
                match pick {
                    0 => {
                        // A header, whole or with one bit flipped.
                        let n = (WINDOW_BYTES - i).min(4);
                        w[i..i + n].copy_from_slice(&h[..n]);
                        if x & 4 == 0 {
                            w[i + (x >> 8) as usize % n] ^= 1 << ((x >> 12) % 8);
                        }
                        i += n;
                        continue;
                    }
                    1 => w[i] = SYNC,
                    2 => w[i] = LENGTH_BYTES[(x >> 30) as usize % LENGTH_BYTES.len()],
                    3 => w[i] = STOPS[(x >> 30) as usize % STOPS.len()],
                    _ => w[i] = x as u8,
                }
                i += 1;
            }
            let mut plain = Window {
                candidates: 0,
                headers: 0,
                stops: 0,
            };
            let mut plain_stops = 0;
            let mut plain_syncs = 0;
            for i in 0..WINDOW {
                if w[i] == SYNC {
                    plain_syncs |= 1 << i;
                }
                if w[i] == SYNC && LENGTH_BYTES.contains(&w[i + 1]) {
                    plain.candidates |= 1 << i;
                }
                if HEADERS.iter().any(|h| w[i..i + 4] == h[..]) {
                    plain.headers |= 1 << i;
                }
                if w[i] == SYNC && STOPS.contains(&w[i + 1]) {
                    plain_stops |= 1 << i;
                }
            }
            assert_eq!(window(&w, &[]), Some(plain), "{w:02X?}");
            let with_stops = Window {
                stops: plain_stops,
                ..plain
            };
            assert_eq!(window(&w, &STOPS), Some(with_stops), "{w:02X?}");
            let first: &[u8; WINDOW] = w.first_chunk().unwrap();
            assert_eq!(syncs(first), Some(plain_syncs));
        }
    }
}
