//! What DataLink V2 says of itself ([`DESCRIPTION`]).

use crate::format::{Check, FormatDescription, LinkKind};
use crate::wire::Checksum;

/// DataLink V2: a hub relaying up to [`CHANNELS`](super::CHANNELS) ESCs' HW-FOC payloads at
/// 115200 baud, checked by a CRC-16/XMODEM; each record carries what an HW-FOC data frame does,
/// at HW-FOC's period, with its counter and status bits.
pub const DESCRIPTION: FormatDescription = FormatDescription {
    name: "datalink",
    title: "DataLink V2",
    baud_rate: super::BAUD_RATE,
    link: LinkKind::Hub {
        channels: super::CHANNELS as u8,
    },
    data_frame_len: super::FRAME_LEN,
    check: Check::Checksum(Checksum::Crc16Xmodem),
    adopted_info: None,
    info_keys: &[],
    ..crate::foc::DESCRIPTION
};
