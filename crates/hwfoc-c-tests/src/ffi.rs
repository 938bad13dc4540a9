//! The shim's C interface (`shim/shim.c`) and [`CDecoder`], a C decoder owned from Rust.

use core::ffi::{c_int, c_long};

#[repr(C)]
struct Shim {
    _private: [u8; 0],
}

unsafe extern "C" {
    fn shim_new(format: c_int) -> *mut Shim;
    fn shim_free(s: *mut Shim);
    fn shim_feed(s: *mut Shim, data: *const u8, n: usize, push: c_int);
    fn shim_flush(s: *mut Shim);
    fn shim_line_silent(s: *mut Shim, max_frames: u32);
    fn shim_take_frames(s: *mut Shim, out: *mut *const u64) -> c_long;
    fn shim_stats(s: *mut Shim, out: *mut *const u64) -> c_long;
    fn shim_encode(format: c_int, flat: *const u64, out: *mut u8) -> usize;
    fn shim_can_unpack(kind: c_int, payload: *const u8, len: usize, fields: *mut i32) -> c_int;
    fn shim_can_pack(kind: c_int, fields: *const i32, out: *mut u8) -> usize;
}

/// The most fields of a DroneCAN type (`HWFOC_CAN_MAX_FIELDS`).
pub const CAN_MAX_FIELDS: usize = 9;

/// `hwfoc_can_unpack` of `payload` as the header's type number `kind`: its fields, or `None`
/// for a payload of another length.
pub fn can_unpack(kind: i32, payload: &[u8]) -> Option<Vec<i32>> {
    let mut fields = [0i32; CAN_MAX_FIELDS];
    // SAFETY: `payload` is valid for its length; the header writes at most 9 fields.
    let n = unsafe { shim_can_unpack(kind, payload.as_ptr(), payload.len(), fields.as_mut_ptr()) };
    usize::try_from(n).ok().map(|n| fields[..n].to_vec())
}

/// `hwfoc_can_pack` of `fields` (padded with zeros to 9) as type `kind`: the payload.
pub fn can_pack(kind: i32, fields: &[i32]) -> Vec<u8> {
    let mut padded = [0i32; CAN_MAX_FIELDS];
    padded[..fields.len()].copy_from_slice(fields);
    let mut out = [0u8; 14];
    // SAFETY: the header reads at most 9 fields and writes at most 14 bytes.
    let n = unsafe { shim_can_pack(kind, padded.as_ptr(), out.as_mut_ptr()) };
    out[..n].to_vec()
}

/// The bytes the header's encoder of `format` writes for the frame whose flat form
/// ([`crate::flat`], offset first) is `flat`.
pub fn encode(format: Format, flat: &[u64]) -> Vec<u8> {
    // The longest flat frame is a hub frame's, 6 + 8 * 11 integers: padded to that, the shim
    // reads nothing beyond, whatever `flat` holds.
    let mut padded = flat.to_vec();
    padded.resize(padded.len().max(6 + 8 * 11), 0);
    let mut out = [0u8; 160];
    // SAFETY: the shim reads at most 94 integers of `padded` and writes at most 160 bytes.
    let n = unsafe { shim_encode(format as c_int, padded.as_ptr(), out.as_mut_ptr()) };
    out[..n].to_vec()
}

/// Which decoder of the header: the shim's format numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(i32)]
pub enum Format {
    /// `hwfoc_foc_*`.
    Foc = 0,
    /// `hwfoc_dl_*`.
    DataLink = 1,
    /// `hwfoc_v3_*`.
    V3 = 2,
    /// `hwfoc_v4_*`.
    V4 = 3,
    /// `hwfoc_hw5_*`.
    Hw5 = 4,
}

/// One C decoder with the frames it has handed on since they were last taken.
pub struct CDecoder {
    shim: *mut Shim,
}

impl CDecoder {
    /// A new decoder of `format`.
    pub fn new(format: Format) -> CDecoder {
        // SAFETY: shim_new takes any format number; null only when out of memory.
        let shim = unsafe { shim_new(format as c_int) };
        assert!(!shim.is_null(), "shim_new: out of memory");
        CDecoder { shim }
    }

    /// `_feed` (or `_push` byte by byte when `push`).
    pub fn feed(&mut self, data: &[u8], push: bool) {
        // SAFETY: `data` is valid for `data.len()` bytes for the call.
        unsafe { shim_feed(self.shim, data.as_ptr(), data.len(), c_int::from(push)) }
    }

    /// `_flush`.
    pub fn flush(&mut self) {
        // SAFETY: a live shim.
        unsafe { shim_flush(self.shim) }
    }

    /// `_line_silent`.
    pub fn line_silent(&mut self, max_frames: u32) {
        // SAFETY: a live shim.
        unsafe { shim_line_silent(self.shim, max_frames) }
    }

    /// The frames handed on since the last call, flat ([`crate::flat`]).
    pub fn take_frames(&mut self) -> Vec<u64> {
        let mut out = core::ptr::null();
        // SAFETY: the shim returns its buffer and the count of integers in it, valid until
        // the next call on it; copied at once.
        let n = unsafe { shim_take_frames(self.shim, &mut out) };
        copy(out, n)
    }

    /// The statistics, flat ([`crate::flat`]); call after [`CDecoder::take_frames`].
    pub fn stats(&mut self) -> Vec<u64> {
        let mut out = core::ptr::null();
        // SAFETY: as in take_frames.
        let n = unsafe { shim_stats(self.shim, &mut out) };
        copy(out, n)
    }
}

fn copy(out: *const u64, n: c_long) -> Vec<u64> {
    let n = usize::try_from(n).expect("the C shim ran out of memory");
    if n == 0 {
        return Vec::new();
    }
    // SAFETY: `out` holds `n` integers (checked non-empty above).
    unsafe { core::slice::from_raw_parts(out, n) }.to_vec()
}

impl Drop for CDecoder {
    fn drop(&mut self) {
        // SAFETY: created by shim_new, freed once.
        unsafe { shim_free(self.shim) }
    }
}

#[repr(C)]
struct NoInfo {
    _private: [u8; 0],
}

unsafe extern "C" {
    fn noinfo_state_size() -> usize;
    fn noinfo_new() -> *mut NoInfo;
    fn noinfo_free(s: *mut NoInfo);
    fn noinfo_feed(s: *mut NoInfo, data: *const u8, n: usize, push: c_int);
    fn noinfo_flush(s: *mut NoInfo);
    fn noinfo_line_silent(s: *mut NoInfo, max_frames: u32);
    fn noinfo_take_frames(s: *mut NoInfo, out: *mut *const u64) -> c_long;
    fn noinfo_stats(s: *mut NoInfo, out: *mut *const u64) -> c_long;
}

/// The HW-FOC decoder built with `HWFOC_NO_FOC_INFO` (`shim/noinfo.c`): data frames only.
pub struct NoInfoDecoder {
    shim: *mut NoInfo,
}

impl NoInfoDecoder {
    /// `sizeof(hwfoc_foc_decoder)` in that build, on this machine.
    pub fn state_size() -> usize {
        // SAFETY: a constant of the C build.
        unsafe { noinfo_state_size() }
    }

    /// A new decoder.
    pub fn new() -> NoInfoDecoder {
        // SAFETY: null only when out of memory.
        let shim = unsafe { noinfo_new() };
        assert!(!shim.is_null(), "noinfo_new: out of memory");
        NoInfoDecoder { shim }
    }

    /// `hwfoc_foc_feed` (or `_push` byte by byte when `push`).
    pub fn feed(&mut self, data: &[u8], push: bool) {
        // SAFETY: `data` is valid for `data.len()` bytes for the call.
        unsafe { noinfo_feed(self.shim, data.as_ptr(), data.len(), c_int::from(push)) }
    }

    /// `hwfoc_foc_flush`.
    pub fn flush(&mut self) {
        // SAFETY: a live shim.
        unsafe { noinfo_flush(self.shim) }
    }

    /// `hwfoc_foc_line_silent`.
    pub fn line_silent(&mut self, max_frames: u32) {
        // SAFETY: a live shim.
        unsafe { noinfo_line_silent(self.shim, max_frames) }
    }

    /// The data frames handed on since the last call, flat as [`crate::flat`]'s HW-FOC ones.
    pub fn take_frames(&mut self) -> Vec<u64> {
        let mut out = core::ptr::null();
        // SAFETY: as in CDecoder::take_frames.
        let n = unsafe { noinfo_take_frames(self.shim, &mut out) };
        copy(out, n)
    }

    /// The statistics, flat: bytes, bytes skipped, checksum failures, the packet sequence.
    pub fn stats(&mut self) -> Vec<u64> {
        let mut out = core::ptr::null();
        // SAFETY: as in CDecoder::take_frames.
        let n = unsafe { noinfo_stats(self.shim, &mut out) };
        copy(out, n)
    }
}

impl Default for NoInfoDecoder {
    fn default() -> NoInfoDecoder {
        NoInfoDecoder::new()
    }
}

impl Drop for NoInfoDecoder {
    fn drop(&mut self) {
        // SAFETY: created by noinfo_new, freed once.
        unsafe { noinfo_free(self.shim) }
    }
}
