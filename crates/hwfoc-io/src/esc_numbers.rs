//! ESC numbers: the one rule by which the channels of a DataLink hub are numbered, for inputs
//! read to their end ([`crate::Sources`]) and live ports
//! ([`crate::PortStreams`]) alike.
//!
//! Each stream (a file, a recording's port, a serial port) is an ESC, numbered in the order
//! given. A stream found to carry a DataLink hub keeps its number for the hub's channel 0;
//! channels 1 to 7 take the next numbers not given yet, in channel order, so that a hub read
//! alone numbers its ESCs 0 to 7 by channel and no two ESCs share a number whatever mix of
//! hubs and ESCs is read. Numbers stop at [`MAX_ESCS`]: the record's `esc` column is a `u8`.

use hwfoc::datalink::CHANNELS;

/// How many ESCs the record's `esc` column (a `u8`) can number.
pub(crate) const MAX_ESCS: usize = 256;

/// The number of a hub's channel past [`MAX_ESCS`]: its frames are not handed on, the `esc`
/// column could not tell them from another ESC's.
pub(crate) const UNNUMBERED: usize = usize::MAX;

/// The ESC numbers of the channels of a hub found on the stream of ESC `own`, when `next`
/// numbers have been given: `own` for channel 0, `next`, `next + 1`, ... for channels 1 to 7,
/// [`UNNUMBERED`] from [`MAX_ESCS`] on. The caller gives the numbered channels their ESCs, in
/// channel order.
pub(crate) fn hub_channels(own: usize, next: usize) -> [usize; CHANNELS] {
    let mut escs = [own; CHANNELS];
    for (channel, esc) in escs.iter_mut().enumerate().skip(1) {
        let n = next + channel - 1;
        *esc = if n < MAX_ESCS { n } else { UNNUMBERED };
    }
    escs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hubs_channels_take_the_next_numbers_up_to_the_last() {
        // A hub read alone: its ESCs are 0 to 7 by channel.
        assert_eq!(hub_channels(0, 1), [0, 1, 2, 3, 4, 5, 6, 7]);
        // Port 2 of three, a hub: channel 0 is ESC 2, the others after the three ports.
        assert_eq!(hub_channels(2, 3), [2, 3, 4, 5, 6, 7, 8, 9]);
        // Near the end of what the `esc` column numbers.
        let u = UNNUMBERED;
        assert_eq!(hub_channels(7, 253), [7, 253, 254, 255, u, u, u, u]);
        assert_eq!(hub_channels(255, 256), [255, u, u, u, u, u, u, u]);
    }
}
