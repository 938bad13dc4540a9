//! The candidate map: where candidates may start in the next [`MAP_BLOCK`] positions, a bit
//! per position, for the bulk scanner to go from one candidate to the next through line noise
//! ([`crate::foc::follow`]) with no branch on the noise between them.
//!
//! A position is in the map when its byte is the sync byte and the next byte agrees with the
//! length bytes in every bit in which they agree with each other (`0x16` and `0x4C` differ in
//! four bits: sixteen bytes pass, two of them length bytes). One compare for the second byte
//! where one per length byte would be exact: the scanner tries a frame at each position of the
//! map and checks the length byte before counting a candidate rejected.
//!
//! The map is made a block at a time: with AVX2 where the processor has it (checked once, with
//! `cpuid`; two compares and a movemask per 32 positions), else with SSE2 (per 16). x86_64
//! only: elsewhere the module is not built, and the scanner searches after noise as it always
//! has (`crate::foc::window`, a word at a time), with no map on a microcontroller's stack.

use crate::foc::frame::LENGTH_BYTES;
use crate::wire::SYNC;

/// Positions a map covers in full: the scanner reads it from any of its first `MAP_BLOCK`
/// positions, 64 positions from there (57 whole ones after the shift within a byte).
pub(crate) const MAP_BLOCK: usize = 4096;

/// Positions a map records: [`MAP_BLOCK`] and the 64 a read from its last one reaches.
pub(crate) const MAP_POSITIONS: usize = MAP_BLOCK + 64;

/// Bytes a map is made from: its positions and the 32 after them (the last position's second
/// byte, and the rest of the last vector's load).
pub(crate) const MAP_READ: usize = MAP_POSITIONS + 32;

/// Bytes of a map: bit `i % 8` of byte `i / 8` for position `i`.
pub(crate) const MAP_BYTES: usize = MAP_POSITIONS / 8;

/// What the second byte of a position in the map agrees with: the bits in which the length
/// bytes agree (`KEEP`), as they are in them (`SECOND`).
const KEEP: u8 = {
    let (mut any, mut all) = (0u8, 0xFFu8);
    let mut i = 0;
    while i < LENGTH_BYTES.len() {
        any |= LENGTH_BYTES[i];
        all &= LENGTH_BYTES[i];
        i += 1;
    }
    !(any ^ all)
};

/// See [`KEEP`].
const SECOND: u8 = LENGTH_BYTES[0] & KEEP;

/// Whether a byte after a sync byte puts its position in the map.
#[cfg(test)]
fn second_fits(b: u8) -> bool {
    b & KEEP == SECOND
}

/// Makes the map of `w`'s first [`MAP_POSITIONS`] positions into `map`.
#[inline]
pub(crate) fn candidate_map(w: &[u8; MAP_READ], map: &mut [u8; MAP_BYTES]) {
    if avx2::available() {
        // SAFETY: the processor has AVX2, and the operating system saves its registers
        // (`avx2::available`). With the search window's, the codec's only `unsafe`:
        // `core::arch`'s compares and movemasks need a target feature.
        #[allow(unsafe_code)]
        unsafe {
            avx2::candidate_map(w, map);
        }
    } else {
        // SAFETY: x86_64 always has SSE2.
        #[allow(unsafe_code)]
        unsafe {
            sse2::candidate_map(w, map);
        }
    }
}

mod sse2 {
    use core::arch::x86_64::{_mm_and_si128, _mm_cmpeq_epi8, _mm_movemask_epi8, _mm_set1_epi8};

    use super::{KEEP, MAP_BYTES, MAP_POSITIONS, MAP_READ, SECOND, SYNC};
    use crate::foc::window::sse2::sixteen;

    /// [`super::candidate_map`] with SSE2.
    #[target_feature(enable = "sse2")]
    pub(super) fn candidate_map(w: &[u8; MAP_READ], map: &mut [u8; MAP_BYTES]) {
        let sync = _mm_set1_epi8(SYNC as i8);
        let (keep, second) = (_mm_set1_epi8(KEEP as i8), _mm_set1_epi8(SECOND as i8));
        for (at, out) in (0..MAP_POSITIONS).step_by(64).zip(map.chunks_exact_mut(8)) {
            let mut word = 0;
            for part in 0..4 {
                let at = at + 16 * part;
                let first = _mm_cmpeq_epi8(sixteen(w, at), sync);
                let next = _mm_cmpeq_epi8(_mm_and_si128(sixteen(w, at + 1), keep), second);
                let bits = _mm_movemask_epi8(_mm_and_si128(first, next)) as u16;
                word |= u64::from(bits) << (16 * part);
            }
            out.copy_from_slice(&word.to_le_bytes());
        }
    }
}

mod avx2 {
    use core::arch::x86_64::{
        __cpuid, __cpuid_count, __m256i, _mm256_and_si256, _mm256_cmpeq_epi8, _mm256_movemask_epi8,
        _mm256_set_epi64x, _mm256_set1_epi8, _xgetbv,
    };
    use core::sync::atomic::{AtomicU8, Ordering};

    use super::{KEEP, MAP_BYTES, MAP_POSITIONS, MAP_READ, SECOND, SYNC};

    /// Whether the processor has AVX2 and the operating system saves the AVX registers:
    /// `cpuid` and `xgetbv` asked once, the answer kept (0 not asked yet, 1 no, 2 yes).
    ///
    /// Written here because the standard library's `is_x86_feature_detected!` is not in
    /// `core`, and the codec is `no_std`.
    pub(super) fn available() -> bool {
        static AVX2: AtomicU8 = AtomicU8::new(0);
        match AVX2.load(Ordering::Relaxed) {
            0 => {
                let yes = detect();
                AVX2.store(if yes { 2 } else { 1 }, Ordering::Relaxed);
                yes
            }
            known => known == 2,
        }
    }

    /// Asks the processor (see [`available`]).
    #[cold]
    fn detect() -> bool {
        // `cpuid` exists on every x86_64 processor; `unsafe` before Rust 1.89.
        #[allow(unused_unsafe, unsafe_code)]
        // SAFETY: `cpuid` has no precondition on x86_64.
        let (basic, extended) = unsafe { (__cpuid(1), __cpuid_count(7, 0)) };
        let os_saves = basic.ecx & (1 << 27) != 0; // OSXSAVE: `xgetbv` may be used
        let avx = basic.ecx & (1 << 28) != 0;
        let avx2 = extended.ebx & (1 << 5) != 0;
        if !(os_saves && avx && avx2) {
            return false;
        }
        // SAFETY: OSXSAVE is set, so `xgetbv` exists and is enabled.
        #[allow(unsafe_code)]
        let enabled = unsafe { xcr0() };
        // The SSE and AVX register states both saved by the operating system.
        enabled & 0b110 == 0b110
    }

    /// The XCR0 register: which register states the operating system saves. Call it only
    /// where `cpuid` says OSXSAVE.
    #[target_feature(enable = "xsave")]
    fn xcr0() -> u64 {
        // SAFETY: the caller checked OSXSAVE (see above).
        #[allow(unsafe_code)]
        unsafe {
            _xgetbv(0)
        }
    }

    /// Thirty-two bytes of `w` from `at` (four little-endian words: a plain unaligned load
    /// once compiled, with no pointer).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn thirty_two(w: &[u8; MAP_READ], at: usize) -> __m256i {
        let word = |from: usize| {
            let mut b = [0; 8];
            b.copy_from_slice(&w[from..from + 8]);
            i64::from_le_bytes(b)
        };
        _mm256_set_epi64x(word(at + 24), word(at + 16), word(at + 8), word(at))
    }

    /// [`super::candidate_map`] with AVX2. Call it only where [`available`].
    #[target_feature(enable = "avx2")]
    pub(super) fn candidate_map(w: &[u8; MAP_READ], map: &mut [u8; MAP_BYTES]) {
        let sync = _mm256_set1_epi8(SYNC as i8);
        let (keep, second) = (_mm256_set1_epi8(KEEP as i8), _mm256_set1_epi8(SECOND as i8));
        for (at, out) in (0..MAP_POSITIONS).step_by(64).zip(map.chunks_exact_mut(8)) {
            let mut word = 0;
            for part in 0..2 {
                let at = at + 32 * part;
                let first = _mm256_cmpeq_epi8(thirty_two(w, at), sync);
                let next = _mm256_cmpeq_epi8(_mm256_and_si256(thirty_two(w, at + 1), keep), second);
                let bits = _mm256_movemask_epi8(_mm256_and_si256(first, next)) as u32;
                word |= u64::from(bits) << (32 * part);
            }
            out.copy_from_slice(&word.to_le_bytes());
        }
    }

    /// [`candidate_map`] for the tests, where [`available`].
    #[cfg(test)]
    pub(super) fn map_if_available(w: &[u8; MAP_READ], map: &mut [u8; MAP_BYTES]) -> bool {
        if !available() {
            return false;
        }
        // SAFETY: checked just above.
        #[allow(unsafe_code)]
        unsafe {
            candidate_map(w, map);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The length bytes pass the map's test of a second byte, and the bytes that differ from
    /// them only where they differ from each other (16 in all for `0x16` and `0x4C`).
    #[test]
    fn the_second_byte_test_passes_the_length_bytes() {
        let passing = (0..=255u8).filter(|&b| second_fits(b)).count();
        assert!(LENGTH_BYTES.iter().all(|&l| second_fits(l)));
        assert_eq!(passing, 1 << (!KEEP).count_ones());
        assert_eq!(passing, 16);
    }

    /// Each way of making the map gives what a plain search gives, over random blocks dense in
    /// sync bytes, length bytes and bytes near them.
    #[test]
    fn the_map_matches_a_plain_search() {
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        let mut w = [0u8; MAP_READ];
        for round in 0..40 {
            for b in w.iter_mut() {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                *b = match (x >> 59) as usize % (2 + round % 5) {
                    0 => SYNC,
                    1 => {
                        LENGTH_BYTES[(x >> 8) as usize % LENGTH_BYTES.len()]
                            ^ (x >> 40) as u8 & 0x44
                    }
                    _ => x as u8,
                };
            }
            let mut plain = [0u8; MAP_BYTES];
            for i in 0..MAP_POSITIONS {
                if w[i] == SYNC && second_fits(w[i + 1]) {
                    plain[i / 8] |= 1 << (i % 8);
                }
            }
            let mut map = [0xA5; MAP_BYTES];
            candidate_map(&w, &mut map);
            assert_eq!(
                map, plain,
                "round {round}: the map as made on this processor"
            );
            let mut map = [0xA5; MAP_BYTES];
            // SAFETY: x86_64 always has SSE2.
            #[allow(unsafe_code)]
            unsafe {
                sse2::candidate_map(&w, &mut map);
            }
            assert_eq!(map, plain, "round {round}: SSE2");
            let mut map = [0xA5; MAP_BYTES];
            // The development and CI machines have AVX2: its map is checked there.
            assert!(
                avx2::map_if_available(&w, &mut map),
                "this processor has no AVX2: the AVX2 map cannot be checked here \
                 (the SSE2 one was)"
            );
            assert_eq!(map, plain, "round {round}: AVX2");
        }
    }
}
