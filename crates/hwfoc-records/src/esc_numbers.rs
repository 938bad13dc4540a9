//! ESC numbers: the one rule by which the channels of a DataLink hub are numbered, for inputs
//! read to their end ([`crate::Sources`]) and live ports
//! ([`crate::PortStreams`]) alike.
//!
//! Each stream (a file, a recording's port, a serial port) is an ESC, numbered in the order
//! given. A stream found to carry a DataLink hub keeps its number for the hub's channel 0;
//! channels 1 to 7 take the next numbers not given yet, in channel order, so that a hub read
//! alone numbers its ESCs 0 to 7 by channel and no two ESCs share a number whatever mix of
//! hubs and ESCs is read. A CAN bus is numbered alike by the slots of its ESCs on the bus
//! (`stream/can.rs`: an ESC's place, unless another ESC holds it; its own number for slot 0,
//! the next ones for the slots up to the highest heard, all at once for a file's bus read
//! ahead), so that a bus read alone numbers its ESCs by their place and two ESCs are never one. Numbers stop at [`MAX_ESCS`]: the record's
//! `esc` column is a `u8`.

/// How many ESCs the record's `esc` column (a `u8`) can number: the most ESCs any input,
/// port set or simulated fleet may have.
pub const MAX_ESCS: usize = 256;

/// The number of a hub's channel past [`MAX_ESCS`]: its frames are not handed on, the `esc`
/// column could not tell them from another ESC's.
pub(crate) const UNNUMBERED: usize = usize::MAX;

/// The ESC number of channel `channel` of the stream of ESC `own` (a DataLink hub's channel, a
/// CAN bus's slot: its ESC's place, [`hwfoc::telemetry::Data::bus_place`], unless another ESC
/// holds it) numbered when `next` numbers have been given, the channels before it numbered
/// already: `own` for channel 0, else `next` ([`UNNUMBERED`] from [`MAX_ESCS`] on). A CAN bus's
/// slots are numbered up to the highest one heard, so that a bus read alone numbers its ESCs by
/// their place (throttle channel - 1 for a mapped Hobbywing ESC, node id if never mapped, a
/// standard ESC's `esc_index`).
pub(crate) fn channel_number(own: usize, next: usize, channel: usize) -> usize {
    match channel {
        0 => own,
        _ if next < MAX_ESCS => next,
        _ => UNNUMBERED,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::datalink::CHANNELS;

    /// The numbers of a hub's eight channels found on the stream of ESC `own` when `next`
    /// numbers have been given, as the callers number them: in channel order.
    fn hub_channels(own: usize, mut next: usize) -> [usize; CHANNELS] {
        core::array::from_fn(|channel| {
            let n = channel_number(own, next, channel);
            if n != own && n != UNNUMBERED {
                next += 1;
            }
            n
        })
    }

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
