//! SLCAN (the Lawicel ASCII protocol of serial CAN adapters), the part a transmitter needs.
//!
//! Commands end with `\r`. `C` closes the channel, `S0`..`S8` set the bitrate (below), `O`
//! opens it, `T` + 8 hex digits of ID + 1 digit of length + 2 hex digits per byte sends an
//! extended frame. The adapter answers `\r` (done), `\x07` (BEL: refused), `Z\r` (an extended
//! frame sent): all read and ignored here, except that refusals are counted.

/// The CAN bitrates of the SLCAN `S` command, in bit/s, indexed by their code (`S0` = 10 kbit/s
/// ... `S8` = 1 Mbit/s).
pub const BITRATES: [u32; 9] = [
    10_000, 20_000, 50_000, 100_000, 125_000, 250_000, 500_000, 800_000, 1_000_000,
];

/// The `S` code of `bitrate` (bit/s), if SLCAN has one.
pub fn bitrate_code(bitrate: u32) -> Option<u8> {
    BITRATES.iter().position(|&b| b == bitrate).map(|i| i as u8)
}

/// The commands that set an adapter up at `code`, from whatever state it is in: an empty
/// command (ends a command a previous program left half-written), close, set the bitrate,
/// open. (`C` on a closed channel is refused with BEL by some adapters: harmless.)
pub fn setup(code: u8) -> Vec<u8> {
    format!("\rC\rS{code}\rO\r").into_bytes()
}

/// The command that closes the channel.
pub const CLOSE: &[u8] = b"C\r";

/// The answer of an adapter that refused a command.
pub const BEL: u8 = 0x07;

const HEX: &[u8; 16] = b"0123456789ABCDEF";

/// Appends the `T` command sending the extended frame `id` (29 bits) with `data` (0 to 8
/// bytes) to `out`.
pub fn push_extended(out: &mut Vec<u8>, id: u32, data: &[u8]) {
    debug_assert!(data.len() <= 8 && id < 1 << 29);
    out.push(b'T');
    for shift in (0..8).rev() {
        out.push(HEX[((id >> (shift * 4)) & 0xF) as usize]);
    }
    out.push(b'0' + data.len() as u8);
    for &b in data {
        out.push(HEX[usize::from(b >> 4)]);
        out.push(HEX[usize::from(b & 0xF)]);
    }
    out.push(b'\r');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes() {
        assert_eq!(bitrate_code(1_000_000), Some(8));
        assert_eq!(bitrate_code(500_000), Some(6));
        assert_eq!(bitrate_code(10_000), Some(0));
        assert_eq!(bitrate_code(800_000), Some(7));
        assert_eq!(bitrate_code(83_333), None);
        assert_eq!(setup(8), b"\rC\rS8\rO\r");
    }

    #[test]
    fn lines() {
        let mut out = Vec::new();
        push_extended(
            &mut out,
            0x1004_0A64,
            &[0x5C, 0xC7, 0x07, 0x00, 0x00, 0x00, 0x20, 0x85],
        );
        push_extended(&mut out, 0x1F, &[]);
        assert_eq!(out, b"T10040A6485CC7070000002085\rT0000001F0\r");
    }
}
