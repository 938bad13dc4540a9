//! A Vector BLF log (binary logging format: CANoe, CANalyzer, python-can's `BLFWriter`) as an
//! input: one CAN stream per channel, named `channel N` as the file numbers it.
//!
//! A file header (`LOGG`, its size, the start as a SYSTEMTIME: UTC as python-can writes and
//! reads it, to the millisecond), then objects (`LOBJ`, header size, header version, object
//! size, object type), each padded to 4 bytes. Log containers (type 10) hold the objects of the
//! log, zlib-compressed or not, one object possibly running on into the next container. Of the
//! objects inside, CAN messages (types 1 and 86) are frames, CAN FD messages (100, 101) are
//! CAN FD frames unless they say they are classic; the rest (error frames, markers, texts) is
//! passed over. An object's time is after the start, in nanoseconds or 10 µs (its flags).
//!
//! Written here: `ablf` reads neither type 1 (python-can's CAN message) nor CAN FD messages,
//! needs a seekable file (not standard input), and panics or prints on a damaged container;
//! `blf_asc` has no documentation and one release. Inflated by `flate2`.

use std::io::Read;

use flate2::read::ZlibDecoder;

use super::can_log::{CanLogReader, Entry, Frames};
use super::{InputError, InputFormat};
use crate::can::candump::Logged;
use crate::time::Clock;
use hwfoc::dronecan::CanFrame;

impl InputFormat {
    /// A Vector BLF log: one CAN stream per channel, times its own (Unix seconds).
    pub const BLF: InputFormat = InputFormat {
        name: "Vector BLF log",
        short_name: "blf",
        clock: Clock::Wall,
        live: false,
        recorded_ports: true,
    };
}

/// The file's magic.
const MAGIC: &[u8; 4] = b"LOGG";
/// An object's magic.
const OBJECT: &[u8; 4] = b"LOBJ";
/// The largest object or container read: python-can's containers are 128 KiB, Vector's
/// smaller; a CAN object is under 200 bytes.
const MAX_OBJECT: usize = 16 << 20;
/// Object types read.
const LOG_CONTAINER: u32 = 10;
const CAN_MESSAGE: u32 = 1;
const CAN_MESSAGE2: u32 = 86;
const CAN_FD_MESSAGE: u32 = 100;
const CAN_FD_MESSAGE_64: u32 = 101;

/// Whether `head`, an input's first bytes, may still be the start of a BLF log.
pub(super) fn may_start(head: &[u8]) -> bool {
    MAGIC.starts_with(head) || is_start(head)
}

/// Whether `head`, an input's first bytes, starts a BLF log.
pub(super) fn is_start(head: &[u8]) -> bool {
    head.starts_with(MAGIC)
}

/// A BLF log's objects, read as frames.
pub(super) struct BlfObjects {
    reader: Box<dyn Read>,
    /// The start, Unix nanoseconds; `None` before the header is read.
    start_ns: Option<u64>,
    /// The inflated objects of the containers read, from `at` on.
    held: Vec<u8>,
    at: usize,
    /// Where in the file (for errors).
    offset: u64,
}

impl BlfObjects {
    /// Reads the log `reader` gives, from its first byte.
    pub(super) fn reader(reader: Box<dyn Read>) -> CanLogReader<BlfObjects> {
        CanLogReader::new(BlfObjects {
            reader,
            start_ns: None,
            held: Vec::new(),
            at: 0,
            offset: 0,
        })
    }

    /// An error at the present offset.
    fn error(&self, name: &str, what: &str) -> InputError {
        InputError::Binary {
            input: name.to_string(),
            offset: self.offset,
            message: format!("{what}: not a Vector BLF log this reads"),
        }
    }

    /// Reads exactly `n` bytes; `None` at the end of the file before the first.
    fn read(&mut self, name: &str, n: usize) -> Result<Option<Vec<u8>>, InputError> {
        let mut buf = Vec::with_capacity(n);
        let got = (&mut self.reader)
            .take(n as u64)
            .read_to_end(&mut buf)
            .map_err(|source| InputError::Read {
                input: name.to_string(),
                source,
            })?;
        self.offset += got as u64;
        match got {
            0 if n > 0 => Ok(None),
            g if g < n => Err(self.error(name, "the file ends inside an object")),
            _ => Ok(Some(buf)),
        }
    }

    /// Reads the file header.
    fn header(&mut self, name: &str) -> Result<(), InputError> {
        let head = self
            .read(name, 8)?
            .ok_or_else(|| self.error(name, "no file header"))?;
        let size = u32_at(&head, 4) as usize;
        if !(72..=MAX_OBJECT).contains(&size) {
            return Err(self.error(name, "the file header's size is wrong"));
        }
        let rest = self
            .read(name, size - 8)?
            .ok_or_else(|| self.error(name, "the file header is cut short"))?;
        // SYSTEMTIME: year, month, day of week, day, hour, minute, second, milliseconds.
        let w = |i: usize| u16::from_le_bytes([rest[32 + 2 * i], rest[33 + 2 * i]]);
        let start = (|| {
            let date = jiff::civil::Date::new(w(0) as i16, w(1) as i8, w(3) as i8).ok()?;
            let time = jiff::civil::Time::new(
                w(4) as i8,
                w(5) as i8,
                w(6) as i8,
                i32::from(w(7)) * 1_000_000,
            )
            .ok()?;
            let t = date
                .to_datetime(time)
                .to_zoned(jiff::tz::TimeZone::UTC)
                .ok()?;
            u64::try_from(t.timestamp().as_nanosecond()).ok()
        })();
        self.start_ns = Some(
            start.ok_or_else(|| self.error(name, "the file's start is not a date after 1970"))?,
        );
        Ok(())
    }

    /// Reads the next log container into `held`; false at the end of the file.
    fn container(&mut self, name: &str) -> Result<bool, InputError> {
        let Some(base) = self.read(name, 16)? else {
            return Ok(false);
        };
        if &base[..4] != OBJECT {
            return Err(self.error(name, "an object does not start with LOBJ"));
        }
        let (kind, size) = (u32_at(&base, 12), u32_at(&base, 8) as usize);
        if !(16..=MAX_OBJECT).contains(&size) {
            return Err(self.error(name, "an object's size is wrong"));
        }
        let body = self
            .read(name, size - 16 + size % 4)?
            .ok_or_else(|| self.error(name, "the file ends inside an object"))?;
        if kind != LOG_CONTAINER {
            // An object outside containers: read as one inside.
            self.held.drain(..self.at);
            self.at = 0;
            self.held.extend_from_slice(&base);
            self.held.extend_from_slice(&body);
            return Ok(true);
        }
        if body.len() < 16 {
            return Err(self.error(name, "a log container is cut short"));
        }
        let method = u16::from_le_bytes([body[0], body[1]]);
        let inflated = u32_at(&body, 8) as usize;
        if inflated > MAX_OBJECT {
            return Err(self.error(name, "a log container is larger than 16 MiB"));
        }
        let data = &body[16..size - 16];
        self.held.drain(..self.at);
        self.at = 0;
        match method {
            0 => self.held.extend_from_slice(data),
            2 => {
                let before = self.held.len();
                let read = ZlibDecoder::new(data)
                    .take(inflated as u64)
                    .read_to_end(&mut self.held);
                if read.is_err() || self.held.len() - before != inflated {
                    return Err(self.error(name, "a log container's zlib data is damaged"));
                }
            }
            _ => return Err(self.error(name, "a log container's compression is unknown")),
        }
        Ok(true)
    }

    /// The next frame of the objects held, passing over other objects; `None` where the held
    /// bytes end before an object does.
    fn held_frame(&mut self, name: &str, bus: &mut String) -> Result<Option<Entry>, InputError> {
        let start_ns = self.start_ns.unwrap_or(0);
        loop {
            let rest = &self.held[self.at..];
            if rest.len() < 16 {
                return Ok(None);
            }
            if &rest[..4] != OBJECT {
                return Err(self.error(name, "an object in a container does not start with LOBJ"));
            }
            let header = u16::from_le_bytes([rest[4], rest[5]]) as usize;
            let version = u16::from_le_bytes([rest[6], rest[7]]);
            let (size, kind) = (u32_at(rest, 8) as usize, u32_at(rest, 12));
            if size < header || !(32..=MAX_OBJECT).contains(&size) {
                return Err(self.error(name, "an object's size in a container is wrong"));
            }
            let padded = size + size % 4;
            if rest.len() < size {
                return Ok(None);
            }
            let object = &rest[..size];
            self.at += padded.min(rest.len());
            // Object header v1: flags, client index, version, time; v2: flags, time status,
            // version, time (and the original time).
            let flags = u32_at(object, 16);
            let time = match version {
                1 => u64_at(object, 24),
                2 => u64_at(object, 24),
                _ => continue,
            };
            let after_ns = match flags {
                1 => time.saturating_mul(10_000),
                _ => time,
            };
            let data = &object[header..];
            let Some(logged) = frame_of(kind, data) else {
                continue;
            };
            let channel = match kind {
                CAN_FD_MESSAGE_64 => u16::from(data[0]),
                _ => u16::from_le_bytes([data[0], data[1]]),
            };
            bus.push_str("channel ");
            bus.push_str(&channel.to_string());
            return Ok(Some(Entry {
                t_ns: Some(start_ns.saturating_add(after_ns)),
                frame: logged,
            }));
        }
    }
}

/// The frame of an object of type `kind` whose data (after its header) is `data`; `None` for
/// an object that is no CAN frame, or too short to be one.
fn frame_of(kind: u32, data: &[u8]) -> Option<Logged> {
    let frame = |id: u32, remote: bool, data: &[u8]| {
        let extended = id & 0x8000_0000 != 0;
        let id = id & 0x1FFF_FFFF;
        if remote {
            CanFrame::remote(id, extended, data.len() as u8)
        } else if extended {
            CanFrame::extended(id, data)
        } else {
            CanFrame::standard(id, data)
        }
        .map(Logged::Classic)
    };
    match kind {
        CAN_MESSAGE | CAN_MESSAGE2 if data.len() >= 16 => {
            let (flags, dlc, id) = (data[2], usize::from(data[3]).min(8), u32_at(data, 4));
            frame(id, flags & 0x80 != 0, &data[8..8 + dlc])
        }
        CAN_FD_MESSAGE if data.len() >= 84 => {
            let (flags, dlc, id, fd_flags) =
                (data[2], usize::from(data[3]), u32_at(data, 4), data[13]);
            if fd_flags & 1 != 0 || dlc > 8 {
                return Some(Logged::Fd);
            }
            frame(id, flags & 0x80 != 0, &data[20..20 + dlc])
        }
        CAN_FD_MESSAGE_64 if data.len() >= 40 => {
            let (valid, id, flags) = (usize::from(data[2]), u32_at(data, 4), u32_at(data, 12));
            if flags & 0x1000 != 0 || valid > 8 || data.len() < 40 + valid {
                return Some(Logged::Fd);
            }
            frame(id, flags & 0x10 != 0, &data[40..40 + valid])
        }
        _ => None,
    }
}

fn u32_at(b: &[u8], i: usize) -> u32 {
    u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]])
}

fn u64_at(b: &[u8], i: usize) -> u64 {
    u64::from_le_bytes(b[i..i + 8].try_into().unwrap_or_default())
}

impl Frames for BlfObjects {
    fn format(&self) -> InputFormat {
        InputFormat::BLF
    }

    fn next(&mut self, name: &str, bus: &mut String) -> Result<Option<Entry>, InputError> {
        if self.start_ns.is_none() {
            self.header(name)?;
        }
        loop {
            if let Some(entry) = self.held_frame(name, bus)? {
                return Ok(Some(entry));
            }
            if !self.container(name)? {
                return match self.held.len() - self.at {
                    0 => Ok(None),
                    _ => Err(self.error(name, "the file ends inside an object")),
                };
            }
        }
    }
}
