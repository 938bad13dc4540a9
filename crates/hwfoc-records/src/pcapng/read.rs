//! The pcapng reader: every complete block read, damage skipped and reported.

use std::collections::HashMap;
use std::fmt;
use std::io::{self, Read};
use std::ops::Range;

use super::{
    EPB, IDB, IF_DESCRIPTION, IF_NAME, IF_SPEED, IF_TSOFFSET, IF_TSRESOL, ISB, MAX_CHUNK, NRB,
    OPT_COMMENT, OPT_END, PB, RecordingId, SHB, SPB,
};

/// Longest block the reader accepts (a sanity bound on a length field that may be damaged).
const MAX_BLOCK: usize = 16 << 20;
/// Longest block accepted while searching for the next valid block after damage.
const MAX_RESYNC_BLOCK: usize = MAX_CHUNK + 4096;
/// Bytes asked of the source per read.
const READ_SIZE: usize = 1 << 16;

/// One port (capture interface) of a recording.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Interface {
    /// The port's name (`if_name`), or `interface N` when the file gives none.
    pub name: String,
    /// The free-text description (`if_description`), empty when absent.
    pub description: String,
    /// The baud rate: `if_speed`, or "N baud" in the description; `None` when neither says.
    pub baud: Option<u32>,
    /// The link type; [`super::LINKTYPE`] for HW-FOC telemetry.
    pub link_type: u16,
}

impl Interface {
    /// Nanoseconds per byte on this interface (at [`crate::serial::DEFAULT_BAUD`], the HW-FOC rate, when the baud is unknown).
    pub fn byte_ns(&self) -> f64 {
        hwfoc::wire::byte_ns(self.baud.unwrap_or(crate::serial::DEFAULT_BAUD))
    }

    /// Whether the interface carries CAN frames ([`super::LINKTYPE_CAN_SOCKETCAN`]).
    pub fn is_can(&self) -> bool {
        u32::from(self.link_type) == super::LINKTYPE_CAN_SOCKETCAN
    }

    /// Whether the link type is in the user range (147..=162), where HW-FOC bytes are stored.
    pub fn is_user_link_type(&self) -> bool {
        (147..=162).contains(&self.link_type)
    }
}

/// One chunk of received bytes (or a note) read from a recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Packet<'a> {
    /// Index into [`Reader::interfaces`]. Interfaces of later sections (concatenated
    /// recordings) that repeat an earlier section's port, link type and baud share its index.
    pub iface: u32,
    /// Receive time of the first byte: Unix time in nanoseconds.
    pub t_ns: u64,
    /// The bytes as received (empty for a note).
    pub data: &'a [u8],
    /// The packet's comment, if any (a gap note, for example).
    pub comment: Option<&'a str>,
    /// The interface `iface`.
    pub interface: &'a Interface,
}

impl Packet<'_> {
    /// The classic CAN frame a packet of a CAN interface ([`Interface::is_can`]) holds: its 16
    /// bytes (SocketCAN's `struct can_frame`, identifier big-endian), or the 8-byte header and
    /// only the data bytes its length says. `None` for any other packet (a CAN FD frame, a
    /// note, a packet cut short).
    pub fn can_frame(&self) -> Option<hwfoc::dronecan::CanFrame> {
        let header = self.data.get(..8)?;
        let len = usize::from(header[4]);
        let data = self.data.get(8..8 + len)?;
        if len > 8 || (self.data.len() != 8 + len && self.data.len() != 16) {
            return None;
        }
        let can_id = u32::from_be_bytes([header[0], header[1], header[2], header[3]]);
        hwfoc::dronecan::CanFrame::from_socketcan(can_id, data)
    }
}

/// A place in a recording that could not be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Damage {
    /// Byte offset in the file where reading failed.
    pub offset: u64,
    /// Where reading resumed (the next valid block), or `None` when nothing readable followed.
    pub resumed_at: Option<u64>,
    /// What was wrong.
    pub reason: String,
}

impl fmt::Display for Damage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.resumed_at {
            Some(to) => write!(
                f,
                "damaged at byte {} ({}): skipped {} bytes to the next valid block at byte {to}",
                self.offset,
                self.reason,
                to - self.offset
            ),
            None => write!(
                f,
                "stopped at byte {} ({}); everything before it was read",
                self.offset, self.reason
            ),
        }
    }
}

/// Timestamp units of one interface: raw value * `num` / `den` + `offset_ns`.
#[derive(Debug, Clone, Copy)]
pub(super) struct TsUnit {
    num: u128,
    den: u128,
    offset_ns: i128,
}

impl TsUnit {
    /// From `if_tsresol` (default 6: microseconds) and `if_tsoffset` (seconds).
    pub(super) fn new(tsresol: u8, tsoffset: i64) -> TsUnit {
        let exp = u32::from(tsresol & 0x7F);
        let (num, den) = if tsresol & 0x80 != 0 {
            (1_000_000_000, 1u128.checked_shl(exp).unwrap_or(0))
        } else if exp <= 9 {
            (10u128.pow(9 - exp), 1)
        } else {
            (1, 10u128.checked_pow(exp - 9).unwrap_or(0))
        };
        TsUnit {
            num,
            den,
            offset_ns: i128::from(tsoffset) * 1_000_000_000,
        }
    }

    pub(super) fn to_ns(self, raw: u64) -> u64 {
        let ns = (u128::from(raw) * self.num)
            .checked_div(self.den)
            .map_or(0, |ns| ns as i128);
        (ns + self.offset_ns).clamp(0, i128::from(u64::MAX)) as u64
    }
}

/// An interface of the current section: its timestamps' `if_tsresol` and `if_tsoffset`, kept
/// as given (16 bytes, where a [`TsUnit`] takes 48: a section may declare a million).
#[derive(Debug, Clone, Copy)]
struct Local {
    global: u32,
    tsresol: u8,
    tsoffset: i64,
}

/// The interfaces of one port (the same name, link type and baud), in the order declared, and
/// how many of them the current section uses: a section's interfaces of a port are its first
/// `used`, so the next one declared is found without a search.
#[derive(Debug, Default)]
struct SamePort {
    globals: Vec<u32>,
    /// The section `used` counts in.
    section: u64,
    used: usize,
}

/// Where the packet just read lies in the reader's buffer.
struct Found {
    iface: u32,
    t_ns: u64,
    data: Range<usize>,
    comment: Option<Range<usize>>,
}

/// The outcome of looking at the block at the read position.
enum Step {
    /// A packet (consumed).
    Packet(Found),
    /// Some other block (consumed).
    Other,
    /// Damage: the reason; nothing consumed.
    Bad(String),
    /// The end of the file, exactly at a block boundary.
    End,
}

/// Reads a pcapng recording block by block with bounded memory, tolerating damage.
///
/// Every complete, valid block is read. A damaged block (an impossible length, mismatched
/// lengths, a packet for an undeclared interface, …) is skipped to the next valid block; a block
/// cut off by the end of the file ends reading. Each such place is kept as a [`Damage`], to be
/// collected with [`Reader::take_damage`]; only an I/O error of the source is an error.
pub struct Reader<R: Read> {
    src: R,
    buf: Vec<u8>,
    /// Start of the unread bytes in `buf`.
    pos: usize,
    /// File offset of `buf[0]`.
    base: u64,
    eof: bool,
    done: bool,
    big_endian: bool,
    /// The current section's interfaces, by local id.
    local: Vec<Local>,
    interfaces: Vec<Interface>,
    /// The interfaces (global indices) by what makes a port the same: name, link type, baud.
    by_port: HashMap<(String, u16, Option<u32>), SamePort>,
    /// The number of the current section (1 for the first).
    section: u64,
    damage: Vec<Damage>,
    /// The recording the first section header names, if it names one.
    recording: Option<RecordingId>,
}

impl<R: Read> Reader<R> {
    /// A reader over `src`, which should start with a section header block.
    pub fn new(src: R) -> Reader<R> {
        Reader {
            src,
            buf: Vec::new(),
            pos: 0,
            base: 0,
            eof: false,
            done: false,
            big_endian: false,
            local: Vec::new(),
            interfaces: Vec::new(),
            by_port: HashMap::new(),
            section: 0,
            damage: Vec::new(),
            recording: None,
        }
    }

    /// The interfaces (ports) declared so far.
    pub fn interfaces(&self) -> &[Interface] {
        &self.interfaces
    }

    /// The interfaces declared so far, the reader let go.
    pub fn into_interfaces(self) -> Vec<Interface> {
        self.interfaces
    }

    /// The recording the file's first section header names (`hwfoc recording UUID`), once it
    /// is read: `None` for a file another program wrote.
    pub fn recording_id(&self) -> Option<RecordingId> {
        self.recording
    }

    /// The places that could not be read since the last call.
    pub fn take_damage(&mut self) -> Vec<Damage> {
        std::mem::take(&mut self.damage)
    }

    /// File offset of the next unread byte.
    pub fn offset(&self) -> u64 {
        self.base + self.pos as u64
    }

    /// The next packet, or `None` at the end of the file (or at a block cut off by it).
    pub fn next_packet(&mut self) -> io::Result<Option<Packet<'_>>> {
        let found = loop {
            if self.done {
                return Ok(None);
            }
            match self.step()? {
                Step::Packet(found) => break found,
                Step::Other => {}
                Step::End => {
                    self.done = true;
                    return Ok(None);
                }
                Step::Bad(reason) => self.resync(reason)?,
            }
        };
        Ok(Some(Packet {
            iface: found.iface,
            t_ns: found.t_ns,
            data: &self.buf[found.data],
            comment: found
                .comment
                .and_then(|r| std::str::from_utf8(&self.buf[r]).ok()),
            interface: &self.interfaces[found.iface as usize],
        }))
    }

    /// Makes at least `n` unread bytes available; false if the file ends first.
    fn fill(&mut self, n: usize) -> io::Result<bool> {
        if self.buf.len() - self.pos >= n {
            return Ok(true);
        }
        if self.pos > 0 {
            self.buf.drain(..self.pos);
            self.base += self.pos as u64;
            self.pos = 0;
        }
        while self.buf.len() < n && !self.eof {
            let have = self.buf.len();
            self.buf.resize(have + READ_SIZE.max(n - have), 0);
            let got = loop {
                match self.src.read(&mut self.buf[have..]) {
                    Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                    other => break other,
                }
            };
            match got {
                Ok(0) => {
                    self.buf.truncate(have);
                    self.eof = true;
                }
                Ok(got) => self.buf.truncate(have + got),
                Err(e) => {
                    self.buf.truncate(have);
                    return Err(e);
                }
            }
        }
        Ok(self.buf.len() >= n)
    }

    fn u16_at(&self, at: usize) -> u16 {
        let b = [self.buf[at], self.buf[at + 1]];
        if self.big_endian {
            u16::from_be_bytes(b)
        } else {
            u16::from_le_bytes(b)
        }
    }

    fn u32_at(&self, at: usize) -> u32 {
        let b = [
            self.buf[at],
            self.buf[at + 1],
            self.buf[at + 2],
            self.buf[at + 3],
        ];
        if self.big_endian {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        }
    }

    /// Looks at the block at the read position, consuming it if it is valid.
    fn step(&mut self) -> io::Result<Step> {
        if !self.fill(8)? {
            return Ok(if self.buf.len() == self.pos {
                Step::End
            } else {
                Step::Bad(cut_off(self.buf.len() - self.pos, None))
            });
        }
        let p = self.pos;
        // A section header's type reads the same in either byte order, so the current order
        // (perhaps that of the previous section) recognises it.
        if self.u32_at(p) == SHB {
            if !self.fill(12)? {
                return Ok(Step::Bad(cut_off(self.buf.len() - self.pos, None)));
            }
            let p = self.pos; // `fill` may have moved the unread bytes
            match self.buf[p + 8..p + 12] {
                [0x4D, 0x3C, 0x2B, 0x1A] => self.big_endian = false,
                [0x1A, 0x2B, 0x3C, 0x4D] => self.big_endian = true,
                _ => return Ok(Step::Bad("bad byte-order magic in a section header".into())),
            }
        } else if self.base == 0 && p == 0 {
            return Ok(Step::Bad(
                "not a pcapng file: it does not start with a section header".into(),
            ));
        }
        let p = self.pos;
        let block_type = self.u32_at(p);
        let len = self.u32_at(p + 4) as usize;
        if len < 12 || !len.is_multiple_of(4) || len > MAX_BLOCK {
            return Ok(Step::Bad(format!("impossible block length {len}")));
        }
        if !self.fill(len)? {
            return Ok(Step::Bad(cut_off(self.buf.len() - self.pos, Some(len))));
        }
        let p = self.pos;
        let trailer = self.u32_at(p + len - 4) as usize;
        if trailer != len {
            return Ok(Step::Bad(format!(
                "block length {len} at its start but {trailer} at its end"
            )));
        }
        let body = p + 8..p + len - 4;
        let step = match block_type {
            SHB => self.section_header(body),
            IDB => self.interface(body),
            EPB | PB => self.packet(block_type, body),
            _ => Ok(Step::Other), // statistics, name resolution, custom blocks, …
        };
        if !matches!(step, Ok(Step::Bad(_))) {
            self.pos = p + len;
        }
        step
    }

    fn section_header(&mut self, body: Range<usize>) -> io::Result<Step> {
        if body.len() < 16 {
            return Ok(Step::Bad("section header too short".into()));
        }
        let major = self.u16_at(body.start + 4);
        if major != 1 {
            return Ok(Step::Bad(format!("unsupported pcapng version {major}")));
        }
        self.local.clear();
        self.section += 1;
        if self.section == 1 {
            let recording = self
                .options(body.start + 16..body.end)
                .filter(|(code, _)| *code == OPT_COMMENT)
                .find_map(|(_, value)| {
                    RecordingId::from_comment(std::str::from_utf8(&self.buf[value]).ok()?)
                });
            self.recording = recording;
        }
        Ok(Step::Other)
    }

    fn interface(&mut self, body: Range<usize>) -> io::Result<Step> {
        if body.len() < 8 {
            return Ok(Step::Bad("interface description too short".into()));
        }
        let link_type = self.u16_at(body.start);
        let (mut name, mut description, mut speed) = (None, String::new(), None);
        let (mut tsresol, mut tsoffset) = (6u8, 0i64);
        for (code, value) in self.options(body.start + 8..body.end) {
            let bytes = &self.buf[value.clone()];
            match code {
                IF_NAME => name = Some(String::from_utf8_lossy(bytes).into_owned()),
                IF_DESCRIPTION => description = String::from_utf8_lossy(bytes).into_owned(),
                IF_SPEED if bytes.len() == 8 => {
                    let v = u64::from_le_bytes(bytes.try_into().unwrap_or([0; 8]));
                    let v = if self.big_endian { v.swap_bytes() } else { v };
                    speed = u32::try_from(v).ok().filter(|&b| b > 0);
                }
                IF_TSRESOL if bytes.len() == 1 => tsresol = bytes[0],
                IF_TSOFFSET if bytes.len() == 8 => {
                    let v = i64::from_le_bytes(bytes.try_into().unwrap_or([0; 8]));
                    tsoffset = if self.big_endian { v.swap_bytes() } else { v };
                }
                _ => {}
            }
        }
        let baud = speed.or_else(|| baud_in(&description));
        let name = name.unwrap_or_else(|| format!("interface {}", self.interfaces.len()));
        // A later section repeating a port (recordings concatenated with `cat`) continues its
        // stream, unless this section already uses that interface. (Looked up by port, and a
        // section's interfaces of a port counted rather than searched: a file of a million
        // interface blocks, in one section or in many, is read in linear time.)
        let same = self
            .by_port
            .entry((name.clone(), link_type, baud))
            .or_default();
        if same.section != self.section {
            same.section = self.section;
            same.used = 0;
        }
        let global = match same.globals.get(same.used) {
            Some(&g) => g,
            None => {
                let g = self.interfaces.len() as u32;
                same.globals.push(g);
                self.interfaces.push(Interface {
                    name,
                    description,
                    baud,
                    link_type,
                });
                g
            }
        };
        same.used += 1;
        self.local.push(Local {
            global,
            tsresol,
            tsoffset,
        });
        Ok(Step::Other)
    }

    fn packet(&mut self, block_type: u32, body: Range<usize>) -> io::Result<Step> {
        if body.len() < 20 {
            return Ok(Step::Bad("packet block too short".into()));
        }
        let b = body.start;
        let local_id = if block_type == EPB {
            self.u32_at(b) as usize
        } else {
            usize::from(self.u16_at(b))
        };
        let Some(local) = self.local.get(local_id).copied() else {
            return Ok(Step::Bad(format!(
                "a packet for interface {local_id}, which was never declared"
            )));
        };
        let raw_t = (u64::from(self.u32_at(b + 4)) << 32) | u64::from(self.u32_at(b + 8));
        let caplen = self.u32_at(b + 12) as usize;
        let data = b + 20..b + 20 + caplen;
        if data.end > body.end {
            return Ok(Step::Bad(format!(
                "a packet of {caplen} bytes in a block of {} bytes",
                body.len() + 12
            )));
        }
        let opts_start = (b + 20 + caplen.next_multiple_of(4)).min(body.end);
        let comment = self
            .options(opts_start..body.end)
            .find(|(code, _)| *code == OPT_COMMENT)
            .map(|(_, value)| value);
        Ok(Step::Packet(Found {
            iface: local.global,
            t_ns: TsUnit::new(local.tsresol, local.tsoffset).to_ns(raw_t),
            data,
            comment,
        }))
    }

    /// The options in `range` of the buffer as (code, value range); stops at the end marker or
    /// at an option that does not fit.
    fn options(&self, range: Range<usize>) -> impl Iterator<Item = (u16, Range<usize>)> + '_ {
        let mut at = range.start;
        std::iter::from_fn(move || {
            if at + 4 > range.end {
                return None;
            }
            let code = self.u16_at(at);
            let len = usize::from(self.u16_at(at + 2));
            let value = at + 4..at + 4 + len;
            if code == OPT_END || value.end > range.end {
                return None;
            }
            at = value.start + len.next_multiple_of(4);
            Some((code, value))
        })
    }

    /// After damage at the read position: searches, 4 bytes at a time, for the next valid
    /// block and records the damage.
    fn resync(&mut self, reason: String) -> io::Result<()> {
        let offset = self.offset();
        loop {
            self.pos += 4;
            if self.pos > self.buf.len() {
                self.pos = self.buf.len();
            }
            if !self.fill(12)? {
                break;
            }
            if self.plausible_block()? {
                self.damage.push(Damage {
                    offset,
                    resumed_at: Some(self.offset()),
                    reason,
                });
                return Ok(());
            }
        }
        self.damage.push(Damage {
            offset,
            resumed_at: None,
            reason,
        });
        self.done = true;
        Ok(())
    }

    /// Whether a valid block of a known type starts at the read position (checked without
    /// consuming it or changing any state).
    fn plausible_block(&mut self) -> io::Result<bool> {
        let p = self.pos;
        if self.u32_at(p) == SHB {
            return Ok(matches!(
                self.buf[p + 8..p + 12],
                [0x4D, 0x3C, 0x2B, 0x1A] | [0x1A, 0x2B, 0x3C, 0x4D]
            ));
        }
        let block_type = self.u32_at(p);
        let len = self.u32_at(p + 4) as usize;
        if !matches!(block_type, IDB | PB | SPB | NRB | ISB | EPB)
            || len < 12
            || !len.is_multiple_of(4)
            || len > MAX_RESYNC_BLOCK
            || !self.fill(len)?
        {
            return Ok(false);
        }
        let p = self.pos;
        if self.u32_at(p + len - 4) as usize != len {
            return Ok(false);
        }
        Ok(match block_type {
            EPB => {
                len >= 32
                    && (self.u32_at(p + 8) as usize) < self.local.len()
                    && 32 + self.u32_at(p + 20) as usize <= len
            }
            PB => {
                len >= 32
                    && usize::from(self.u16_at(p + 8)) < self.local.len()
                    && 32 + self.u32_at(p + 20) as usize <= len
            }
            IDB => len >= 20,
            _ => true,
        })
    }
}

/// The reason given for a block cut off by the end of the file, `have` bytes into it.
fn cut_off(have: usize, len: Option<usize>) -> String {
    let block = match len {
        Some(len) => format!("a {len}-byte block"),
        None => "a block".to_string(),
    };
    format!(
        "the file ends {have} bytes into {block}: the recording was cut short, by a crash, a \
         kill, or copying a file still being written"
    )
}

/// The baud rate in a description like "HW-FOC telemetry, 19200 baud 8N1".
pub(super) fn baud_in(description: &str) -> Option<u32> {
    let words: Vec<&str> = description
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|w| !w.is_empty())
        .collect();
    words
        .windows(2)
        .find(|w| w[1].eq_ignore_ascii_case("baud"))
        .and_then(|w| w[0].parse().ok())
        .filter(|&b| b > 0)
}
