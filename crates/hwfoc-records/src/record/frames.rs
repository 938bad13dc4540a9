//! [`DataFrames`]: data frames held in order for a block of records, HW-FOC's as the codec's
//! frames while every frame is one.

use std::ops::Range;

use hwfoc::foc::DataFrame;
use hwfoc::telemetry::Data;

/// Data frames in the order they came, for a block of records (an export's row group, a batch
/// of `hwfoc.read`).
///
/// While every frame is an HW-FOC frame (a raw file's: nearly every block of a large input)
/// they are kept as the codec's frames, 18 bytes each where a [`Data`] takes 44; the first
/// frame of another protocol moves them all to [`Data`]. A writer converts a block a column at a
/// time, reading every frame again for each column, so their size is memory traffic (the
/// Parquet export's cache misses halved with it), and a block known to be all HW-FOC is
/// converted without a match on the protocol per value.
#[derive(Debug, Clone, Default)]
pub struct DataFrames {
    /// The frames while all are HW-FOC (`any` is then empty).
    hwfoc: Vec<DataFrame>,
    /// The frames once one is not HW-FOC (`hwfoc` is then empty).
    any: Vec<Data>,
}

/// Some of the frames of a [`DataFrames`].
#[derive(Debug, Clone, Copy)]
pub enum FrameSlice<'a> {
    /// Every one an HW-FOC frame.
    HwFoc(&'a [DataFrame]),
    /// Of any protocol.
    Any(&'a [Data]),
}

impl DataFrames {
    /// Room for `n` HW-FOC frames (other frames' room is made when one comes).
    pub fn with_capacity(n: usize) -> DataFrames {
        DataFrames {
            hwfoc: Vec::with_capacity(n),
            any: Vec::new(),
        }
    }

    /// The number of frames.
    pub fn len(&self) -> usize {
        self.hwfoc.len() + self.any.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Adds a frame.
    #[inline]
    pub fn push(&mut self, frame: &Data) {
        if let Data::HwFoc(f) = frame
            && self.any.is_empty()
        {
            self.hwfoc.push(*f);
        } else {
            self.any.extend(self.hwfoc.drain(..).map(Data::HwFoc));
            self.any.push(*frame);
        }
    }

    /// Adds HW-FOC frames (a raw input's run).
    #[inline]
    pub fn extend_hwfoc(&mut self, frames: &[DataFrame]) {
        if self.any.is_empty() {
            self.hwfoc.extend_from_slice(frames);
        } else {
            self.any.extend(frames.iter().map(|&f| Data::HwFoc(f)));
        }
    }

    /// The frames `rows` (a range within `0..len()`).
    #[inline]
    pub fn slice(&self, rows: Range<usize>) -> FrameSlice<'_> {
        if self.any.is_empty() {
            FrameSlice::HwFoc(&self.hwfoc[rows])
        } else {
            FrameSlice::Any(&self.any[rows])
        }
    }

    /// Frame `i` (within `0..len()`).
    #[inline]
    pub fn get(&self, i: usize) -> Data {
        if self.any.is_empty() {
            Data::HwFoc(self.hwfoc[i])
        } else {
            self.any[i]
        }
    }

    /// The frames `rows`, as frames of their own.
    pub fn to_owned_range(&self, rows: Range<usize>) -> DataFrames {
        match self.slice(rows) {
            FrameSlice::HwFoc(f) => DataFrames {
                hwfoc: f.to_vec(),
                any: Vec::new(),
            },
            FrameSlice::Any(f) => DataFrames {
                hwfoc: Vec::new(),
                any: f.to_vec(),
            },
        }
    }

    /// Empties it, keeping its room.
    pub fn clear(&mut self) {
        self.hwfoc.clear();
        self.any.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_keep_their_order_when_one_of_another_protocol_comes() {
        let foc = |packet| {
            Data::HwFoc(DataFrame {
                packet,
                ..Default::default()
            })
        };
        let v3 = Data::HwV3(hwfoc::v3::V3Frame::default());
        let mut frames = DataFrames::with_capacity(4);
        frames.push(&foc(1));
        frames.extend_hwfoc(&[DataFrame {
            packet: 2,
            ..Default::default()
        }]);
        // HW-FOC frames only so far: held as such.
        assert!(matches!(frames.slice(0..2), FrameSlice::HwFoc(f) if f.len() == 2));
        frames.push(&v3);
        frames.extend_hwfoc(&[DataFrame {
            packet: 3,
            ..Default::default()
        }]);
        let all = [foc(1), foc(2), v3, foc(3)];
        assert!(matches!(frames.slice(0..4), FrameSlice::Any(f) if f == all));
        assert_eq!(frames.len(), 4);
        assert_eq!((0..4).map(|i| frames.get(i)).collect::<Vec<_>>(), all);
        let part = frames.to_owned_range(1..3);
        assert_eq!((part.len(), part.get(0), part.get(1)), (2, all[1], all[2]));
        let first = frames.to_owned_range(0..1);
        assert!(matches!(first.slice(0..1), FrameSlice::Any(_)));
        frames.clear();
        assert!(frames.is_empty());
        assert_eq!(first.get(0), all[0]);
    }
}
