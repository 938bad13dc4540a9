//! Recordings in pcapng, the capture format of Wireshark and tshark.
//!
//! A recording holds the bytes received on one or more serial ports exactly as they arrived,
//! every byte in order, with its receive time:
//! - a section header block (SHB) naming the writing application (`shb_userappl` = `hwfoc` and
//!   its version);
//! - one interface description block (IDB) per port: link type [`LINKTYPE`] (`LINKTYPE_USER0`,
//!   raw HW-FOC UART bytes), `if_name` = the port, `if_description` = "HW-FOC telemetry, 19200
//!   baud 8N1", `if_speed` = the baud rate, `if_tsresol` = 9 (nanoseconds);
//! - one enhanced packet block (EPB) per frame, holding exactly the frame's bytes, timestamped
//!   with the Unix time in nanoseconds of its first byte; the bytes between frames (line noise,
//!   frames that fail their checksum) in packets of their own, one per read of the port they
//!   came in, each timestamped with its first byte's time. Byte `i` of a packet arrived at
//!   `t_ns + i * 10e9 / baud` ns (8N1: ten bits per byte). The EPBs carry no options: 32 bytes
//!   of block around the frame (a data frame of 24 bytes takes 56 bytes of file);
//! - notes such as a gap while a port was unplugged are an EPB with no bytes and an
//!   `opt_comment` (Wireshark shows them as a 0-byte packet carrying the comment).
//!
//! The cut at frames ([`Writer::write`]; the frames are found by the codec's decoder, module
//! `cut`) makes each packet one frame in Wireshark (with the dissector `hwfoc wireshark install`
//! puts in place) and the file small: about 2.4 times the bytes on the wire, where the earlier
//! layout (one packet per read of the port, cut anywhere in the frames) took 4.8. A reader needs
//! no change for either: the bytes of each port, concatenated in file order, are the stream, and
//! every frame's first byte has the same time in both (to a nanosecond's rounding). Files of the
//! earlier layout read exactly as before. Packets of different ports may be a frame's length out
//! of time order in the file, since a frame is written when it is complete.
//!
//! The blocks are written and read here by hand rather than with the `pcap-file` crate (2.0):
//! its EPB reader takes the raw timestamp as nanoseconds whatever the interface's `if_tsresol`
//! says (so a file at the default microsecond resolution reads 1000 times too early), and its
//! streaming reader stops at the first damaged or cut-off block without telling at which byte.
//! A recording cut short by a crash or `kill -9` is exactly the case this format must survive:
//! [`Reader`] reads every complete block, skips over damaged ones to the next valid block, and
//! reports each place it could not read, with its byte offset, as [`Damage`]. The three block
//! types the writer needs are a few lines each.

mod cut;

use std::collections::HashMap;
use std::fmt;
use std::io::{self, Read, Write};
use std::ops::Range;

use cut::{Cutter, Emit};

/// `LINKTYPE_USER0`: raw HW-FOC UART bytes (the user range 147..=162 is for private use).
pub const LINKTYPE: u32 = 147;

/// Receive time in Unix seconds of byte `i` of a chunk whose first byte arrived at `t_ns`, the
/// bytes `per_byte_ns` apart. The one conversion from recording timestamps to `t_s`: the
/// simulator's ground truth uses it too, so that the two agree to the last bit.
pub fn byte_time_s(t_ns: u64, i: usize, per_byte_ns: f64) -> f64 {
    (t_ns as f64 + i as f64 * per_byte_ns) * 1e-9
}

/// The first four bytes of every pcapng file (the section header block's type; the same in
/// both byte orders).
pub const MAGIC: [u8; 4] = [0x0A, 0x0D, 0x0D, 0x0A];

/// Longest run of bytes written as one packet: longer runs between frames are split (Wireshark
/// refuses packets over 256 KiB), each piece timestamped at its own first byte.
pub const MAX_CHUNK: usize = 1 << 16;

const SHB: u32 = 0x0A0D_0D0A;
const IDB: u32 = 1;
const PB: u32 = 2;
const SPB: u32 = 3;
const NRB: u32 = 4;
const ISB: u32 = 5;
const EPB: u32 = 6;
const BYTE_ORDER_MAGIC: u32 = 0x1A2B_3C4D;

const OPT_END: u16 = 0;
const OPT_COMMENT: u16 = 1;
const SHB_OS: u16 = 3;
const SHB_USERAPPL: u16 = 4;
const IF_NAME: u16 = 2;
const IF_DESCRIPTION: u16 = 3;
const IF_SPEED: u16 = 8;
const IF_TSRESOL: u16 = 9;
const IF_TSOFFSET: u16 = 14;

/// Longest block the reader accepts (a sanity bound on a length field that may be damaged).
const MAX_BLOCK: usize = 16 << 20;
/// Longest block accepted while searching for the next valid block after damage.
const MAX_RESYNC_BLOCK: usize = MAX_CHUNK + 4096;
/// Bytes asked of the source per read.
const READ_SIZE: usize = 1 << 16;

/// Writes a pcapng recording: the section header on creation, then interfaces, frames and notes.
///
/// Each block is handed to `W` in a single `write_all`. The bytes of a frame still arriving
/// (fewer than 77 per port) are held by the writer until the frame completes, until
/// [`Writer::settle`] finds its port silent, or until [`Writer::flush`] or [`Writer::into_inner`];
/// every other byte is handed to `W` by the [`Writer::write`] that brought it. With an unbuffered
/// `W` a block is in the file when the call returns, with a buffered one after a flush.
pub struct Writer<W: Write> {
    inner: W,
    /// Baud rate and cutter of each interface, by id.
    ports: Vec<(u32, Cutter)>,
    block: Vec<u8>,
    written: u64,
}

/// Bytes of file an EPB without options takes for `len` bytes of packet.
fn epb_size(len: usize) -> u64 {
    32 + len.next_multiple_of(4) as u64
}

/// The pieces of a cutter written as packets of one interface.
struct Packets<'a, W: Write> {
    writer: &'a mut Writer<W>,
    iface: u32,
}

impl<W: Write> Emit for Packets<'_, W> {
    type Error = io::Error;
    fn piece(&mut self, t_ns: u64, bytes: &[u8]) -> io::Result<()> {
        self.writer.chunk(self.iface, t_ns, bytes)
    }
}

/// The pieces of a cutter counted as file bytes.
struct Cost(u64);

impl Emit for Cost {
    type Error = std::convert::Infallible;
    fn piece(&mut self, _: u64, bytes: &[u8]) -> Result<(), Self::Error> {
        let whole = (bytes.len() / MAX_CHUNK) as u64 * epb_size(MAX_CHUNK);
        let rest = bytes.len() % MAX_CHUNK;
        self.0 += whole + if rest > 0 { epb_size(rest) } else { 0 };
        Ok(())
    }
}

impl<W: Write> Writer<W> {
    /// Starts a recording: writes the section header block (little-endian, naming `hwfoc` and
    /// its version as the writing application).
    pub fn new(w: W) -> io::Result<Self> {
        let mut writer = Writer {
            inner: w,
            ports: Vec::new(),
            block: Vec::with_capacity(256),
            written: 0,
        };
        writer.begin(SHB);
        writer.put_u32(BYTE_ORDER_MAGIC);
        writer.put_u16(1);
        writer.put_u16(0);
        writer.put_u64(u64::MAX); // section length: not known in advance
        writer.option(SHB_OS, std::env::consts::OS.as_bytes());
        writer.option(
            SHB_USERAPPL,
            concat!("hwfoc ", env!("CARGO_PKG_VERSION")).as_bytes(),
        );
        writer.end_options();
        writer.finish()?;
        Ok(writer)
    }

    /// Declares a port: writes its interface description block and returns its interface id
    /// (0, 1, 2, … in the order of the calls). `baud` must not be zero.
    pub fn add_interface(&mut self, port: &str, baud: u32) -> io::Result<u32> {
        if baud == 0 {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "a baud rate of 0 is not valid",
            ));
        }
        let id = u32::try_from(self.ports.len())
            .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "too many interfaces"))?;
        self.begin(IDB);
        self.put_u16(LINKTYPE as u16);
        self.put_u16(0); // reserved
        self.put_u32(0); // snap length: no limit
        self.option(IF_NAME, port.as_bytes());
        self.option(
            IF_DESCRIPTION,
            format!("HW-FOC telemetry, {baud} baud 8N1").as_bytes(),
        );
        self.option(IF_SPEED, &u64::from(baud).to_le_bytes());
        self.option(IF_TSRESOL, &[9]);
        self.end_options();
        self.finish()?;
        self.ports
            .push((baud, Cutter::new(hwfoc::wire::byte_ns(baud))));
        Ok(id)
    }

    /// Writes bytes received on interface `iface`, `t_ns` the Unix time in nanoseconds of the
    /// first of them (the bytes of one read of a port, back to back): each frame they complete
    /// becomes a packet, timestamped with its first byte's time, and the bytes between frames
    /// packets of their own (see the module documentation). The bytes of a frame still arriving
    /// are held for the next call. An empty `data` writes nothing.
    pub fn write(&mut self, iface: u32, t_ns: u64, data: &[u8]) -> io::Result<()> {
        self.baud(iface)?;
        let mut cutter = self.take_cutter(iface);
        let result = cutter.feed(
            t_ns,
            data,
            &mut Packets {
                writer: self,
                iface,
            },
        );
        self.ports[iface as usize].1 = cutter;
        result
    }

    /// Writes `data` as it is, as one packet on interface `iface` (several if longer than
    /// [`MAX_CHUNK`], each timestamped at its own first byte), after the bytes held for that
    /// interface. For bytes that are not a port's stream; [`Writer::write`] is for those.
    pub fn write_packet(&mut self, iface: u32, t_ns: u64, data: &[u8]) -> io::Result<()> {
        self.settle_port(iface)?;
        self.chunk(iface, t_ns, data)
    }

    /// Writes out the bytes held for every port whose last byte was received `quiet_ns` or more
    /// before `now_ns`: a frame that has not completed in that time never will (an ESC sends a
    /// frame's bytes back to back, 77 bytes at most), and its bytes are written as bytes between
    /// frames. Call it now and then (the recorder does every 50 ms with a 200 ms silence).
    pub fn settle(&mut self, now_ns: u64, quiet_ns: u64) -> io::Result<()> {
        for iface in 0..self.ports.len() as u32 {
            let cutter = &self.ports[iface as usize].1;
            if cutter.holds() && now_ns.saturating_sub(cutter.last_ns()) >= quiet_ns {
                self.settle_port(iface)?;
            }
        }
        Ok(())
    }

    /// How many bytes the file would grow by if `data` were written on `iface` at this moment
    /// and the recording then ended (every held byte written): a bound for rotating by size.
    pub fn cost(&self, iface: u32, data: &[u8]) -> io::Result<u64> {
        self.baud(iface)?;
        let mut cost = Cost(0);
        for (i, (_, cutter)) in self.ports.iter().enumerate() {
            if i != iface as usize && !cutter.holds() {
                continue;
            }
            let mut cutter = cutter.clone();
            if i == iface as usize {
                let Ok(()) = cutter.feed(0, data, &mut cost);
            }
            let Ok(()) = cutter.settle(&mut cost);
        }
        Ok(cost.0)
    }

    /// Writes a note about interface `iface` at Unix time `t_ns` (for example a gap while the
    /// port was unplugged): a packet with no bytes and the text as its comment, after the bytes
    /// held for that interface.
    pub fn comment(&mut self, iface: u32, t_ns: u64, text: &str) -> io::Result<()> {
        self.settle_port(iface)?;
        self.packet(iface, t_ns, &[], Some(text))
    }

    /// Writes out every held byte (a frame still arriving is written as bytes between frames)
    /// and flushes `W`: everything given to the writer is then in `W`.
    pub fn flush(&mut self) -> io::Result<()> {
        for iface in 0..self.ports.len() as u32 {
            self.settle_port(iface)?;
        }
        self.inner.flush()
    }

    /// Flushes `W` with every block written so far, holding back the bytes of frames still
    /// arriving (the periodic flush of a recording, which must not cut frames in two).
    pub fn flush_written(&mut self) -> io::Result<()> {
        self.inner.flush()
    }

    /// Writes out every held byte, flushes `W` and returns it.
    pub fn into_inner(mut self) -> io::Result<W> {
        self.flush()?;
        Ok(self.inner)
    }

    /// The underlying writer (for example to `sync_data` the file under a `BufWriter`).
    pub fn get_ref(&self) -> &W {
        &self.inner
    }

    /// Bytes handed to `W` so far, section header included.
    pub fn bytes_written(&self) -> u64 {
        self.written
    }

    fn baud(&self, iface: u32) -> io::Result<u32> {
        self.ports.get(iface as usize).map(|p| p.0).ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("interface {iface} was never added to the recording"),
            )
        })
    }

    /// The cutter of `iface` (which exists), leaving a fresh one in its place for the moment.
    fn take_cutter(&mut self, iface: u32) -> Cutter {
        let (baud, cutter) = &mut self.ports[iface as usize];
        std::mem::replace(cutter, Cutter::new(hwfoc::wire::byte_ns(*baud)))
    }

    /// Writes out the bytes held for `iface`.
    fn settle_port(&mut self, iface: u32) -> io::Result<()> {
        self.baud(iface)?;
        if !self.ports[iface as usize].1.holds() {
            return Ok(());
        }
        let mut cutter = self.take_cutter(iface);
        let result = cutter.settle(&mut Packets {
            writer: self,
            iface,
        });
        self.ports[iface as usize].1 = cutter;
        result
    }

    /// Writes `data` as packets of at most [`MAX_CHUNK`] bytes, each timestamped at its first
    /// byte.
    fn chunk(&mut self, iface: u32, t_ns: u64, data: &[u8]) -> io::Result<()> {
        let baud = self.baud(iface)?;
        let per_byte = hwfoc::wire::byte_ns(baud);
        for (k, piece) in data.chunks(MAX_CHUNK).enumerate() {
            let offset = (k * MAX_CHUNK) as f64 * per_byte;
            self.packet(
                iface,
                t_ns.saturating_add(offset.round() as u64),
                piece,
                None,
            )?;
        }
        Ok(())
    }

    fn packet(
        &mut self,
        iface: u32,
        t_ns: u64,
        data: &[u8],
        comment: Option<&str>,
    ) -> io::Result<()> {
        self.begin(EPB);
        self.put_u32(iface);
        self.put_u32((t_ns >> 32) as u32);
        self.put_u32(t_ns as u32);
        self.put_u32(data.len() as u32); // at most MAX_CHUNK
        self.put_u32(data.len() as u32);
        self.block.extend_from_slice(data);
        self.pad();
        if let Some(text) = comment {
            self.option(
                OPT_COMMENT,
                truncate_utf8(text, usize::from(u16::MAX) - 3).as_bytes(),
            );
            self.end_options();
        }
        self.finish()
    }

    fn begin(&mut self, block_type: u32) {
        self.block.clear();
        self.put_u32(block_type);
        self.put_u32(0); // total length, set by `finish`
    }

    fn option(&mut self, code: u16, value: &[u8]) {
        let value = &value[..value.len().min(usize::from(u16::MAX))];
        self.put_u16(code);
        self.put_u16(value.len() as u16);
        self.block.extend_from_slice(value);
        self.pad();
    }

    fn end_options(&mut self) {
        self.put_u16(OPT_END);
        self.put_u16(0);
    }

    fn pad(&mut self) {
        let padded = self.block.len().next_multiple_of(4);
        self.block.resize(padded, 0);
    }

    fn finish(&mut self) -> io::Result<()> {
        let total = (self.block.len() + 4) as u32;
        self.block[4..8].copy_from_slice(&total.to_le_bytes());
        self.put_u32(total);
        self.inner.write_all(&self.block)?;
        self.written += u64::from(total);
        Ok(())
    }

    fn put_u16(&mut self, v: u16) {
        self.block.extend_from_slice(&v.to_le_bytes());
    }

    fn put_u32(&mut self, v: u32) {
        self.block.extend_from_slice(&v.to_le_bytes());
    }

    fn put_u64(&mut self, v: u64) {
        self.block.extend_from_slice(&v.to_le_bytes());
    }
}

/// The longest prefix of `text` of at most `max` bytes that ends on a character boundary.
fn truncate_utf8(text: &str, max: usize) -> &str {
    if text.len() <= max {
        return text;
    }
    let mut end = max;
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    &text[..end]
}

/// One port (capture interface) of a recording.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Interface {
    /// The port's name (`if_name`), or `interface N` when the file gives none.
    pub name: String,
    /// The free-text description (`if_description`), empty when absent.
    pub description: String,
    /// The baud rate: `if_speed`, or "N baud" in the description; `None` when neither says.
    pub baud: Option<u32>,
    /// The link type; [`LINKTYPE`] for HW-FOC telemetry.
    pub link_type: u16,
}

impl Interface {
    /// Nanoseconds per byte on this interface (at [`crate::serial::DEFAULT_BAUD`], the HW-FOC rate, when the baud is unknown).
    pub fn byte_ns(&self) -> f64 {
        hwfoc::wire::byte_ns(self.baud.unwrap_or(crate::serial::DEFAULT_BAUD))
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
struct TsUnit {
    num: u128,
    den: u128,
    offset_ns: i128,
}

impl TsUnit {
    /// From `if_tsresol` (default 6: microseconds) and `if_tsoffset` (seconds).
    fn new(tsresol: u8, tsoffset: i64) -> TsUnit {
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

    fn to_ns(self, raw: u64) -> u64 {
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
fn baud_in(description: &str) -> Option<u32> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A packet read back, owned.
    #[derive(Debug, Clone, PartialEq, Eq)]
    struct Owned {
        iface: u32,
        t_ns: u64,
        data: Vec<u8>,
        comment: Option<String>,
    }

    fn read_all(file: &[u8]) -> (Vec<Owned>, Vec<Interface>, Vec<Damage>) {
        let mut reader = Reader::new(file);
        let mut packets = Vec::new();
        while let Some(p) = reader.next_packet().unwrap() {
            packets.push(Owned {
                iface: p.iface,
                t_ns: p.t_ns,
                data: p.data.to_vec(),
                comment: p.comment.map(str::to_string),
            });
        }
        (packets, reader.interfaces().to_vec(), reader.take_damage())
    }

    /// A recording of two ports, with chunks of every length modulo 4 and a note.
    fn sample() -> (Vec<u8>, Vec<Owned>) {
        let mut w = Writer::new(Vec::new()).unwrap();
        assert_eq!(w.add_interface("/dev/ttyUSB0", 19200).unwrap(), 0);
        assert_eq!(w.add_interface("COM7", 115_200).unwrap(), 1);
        let mut expected = Vec::new();
        let t0 = 1_754_000_000_123_456_789u64;
        for k in 0..9u8 {
            let iface = u32::from(k % 2);
            let data: Vec<u8> = (0..k * 3 + 1).map(|i| i.wrapping_mul(37) ^ k).collect();
            let t_ns = t0 + u64::from(k) * 50_000_001;
            w.write_packet(iface, t_ns, &data).unwrap();
            expected.push(Owned {
                iface,
                t_ns,
                data,
                comment: None,
            });
        }
        w.comment(1, t0 + 999, "gap: COM7 disconnected").unwrap();
        expected.push(Owned {
            iface: 1,
            t_ns: t0 + 999,
            data: Vec::new(),
            comment: Some("gap: COM7 disconnected".into()),
        });
        let file = w.into_inner().unwrap();
        (file, expected)
    }

    #[test]
    fn round_trip_is_exact() {
        let (file, expected) = sample();
        assert_eq!(&file[..4], &MAGIC);
        let (packets, interfaces, damage) = read_all(&file);
        assert_eq!(packets, expected);
        assert!(damage.is_empty(), "{damage:?}");
        assert_eq!(
            interfaces,
            vec![
                Interface {
                    name: "/dev/ttyUSB0".into(),
                    description: "HW-FOC telemetry, 19200 baud 8N1".into(),
                    baud: Some(19200),
                    link_type: 147,
                },
                Interface {
                    name: "COM7".into(),
                    description: "HW-FOC telemetry, 115200 baud 8N1".into(),
                    baud: Some(115_200),
                    link_type: 147,
                },
            ]
        );
    }

    /// A port's stream: frames (data, information, one failing its checksum), noise and a frame
    /// cut by the end, read in chunks of 7 bytes 3 ms apart.
    fn port_stream() -> (Vec<u8>, Vec<(u64, Vec<u8>)>) {
        use hwfoc::{DataFrame, InfoFrame};
        let mut wire = Vec::new();
        for packet in 0..20u16 {
            wire.extend_from_slice(
                &DataFrame {
                    packet,
                    voltage_raw: 240 + packet,
                    ..Default::default()
                }
                .encode(),
            );
            if packet % 5 == 0 {
                let info = InfoFrame::new("XR_FOC_ESC", "HW577_KZ1_V1.1", "XR-01.0.00", "1");
                wire.extend_from_slice(&info.unwrap().encode());
            }
            if packet % 7 == 3 {
                wire.extend_from_slice(&[0x9B, 0x16, 0x55, 0x00, 0x9B]);
            }
        }
        wire[100] ^= 0x01; // a frame fails its checksum
        wire.extend_from_slice(&DataFrame::default().encode()[..11]);
        let reads = wire
            .chunks(7)
            .enumerate()
            .map(|(k, c)| (1_754_000_000_000_000_000 + k as u64 * 3_000_000, c.to_vec()))
            .collect();
        (wire, reads)
    }

    #[test]
    fn writes_a_packet_per_frame_and_every_byte_with_its_time() {
        let (wire, reads) = port_stream();
        let mut w = Writer::new(Vec::new()).unwrap();
        w.add_interface("p", 19200).unwrap();
        let mut predicted = w.bytes_written();
        for (t, bytes) in &reads {
            // The cost of a write, were the recording to end after it, is exact.
            predicted = w.bytes_written() + w.cost(0, bytes).unwrap();
            w.write(0, *t, bytes).unwrap();
        }
        let file = w.into_inner().unwrap();
        assert_eq!(file.len() as u64, predicted);
        let (packets, _, damage) = read_all(&file);
        assert!(damage.is_empty());
        let joined: Vec<u8> = packets.iter().flat_map(|p| p.data.clone()).collect();
        assert_eq!(joined, wire);
        // Every frame the decoder finds is one packet, at its first byte's time in the reads.
        let per_byte = hwfoc::wire::byte_ns(19200);
        let time_of = |offset: usize| {
            let (t, _) = reads[offset / 7];
            t + ((offset % 7) as f64 * per_byte).round() as u64
        };
        let mut starts = Vec::new();
        let mut at = 0;
        for p in &packets {
            starts.push(at);
            at += p.data.len();
        }
        let mut found = 0;
        hwfoc::Decoder::new().decode_all(&wire, |d| {
            let offset = d.offset as usize;
            let k = starts
                .iter()
                .position(|&s| s == offset)
                .expect("a frame starts a packet");
            assert_eq!(packets[k].data.len(), d.frame.wire_len());
            assert_eq!(packets[k].t_ns, time_of(offset));
            found += 1;
        });
        assert_eq!(found, 23); // 20 data and 4 information frames, one failing its checksum
        // The bytes between frames keep their times too.
        for (k, p) in packets.iter().enumerate() {
            assert_eq!(p.t_ns, time_of(starts[k]), "packet {k}");
        }
    }

    #[test]
    fn held_bytes_are_written_by_settle_comment_and_flush() {
        let frame = hwfoc::DataFrame::default().encode();
        let mut w = Writer::new(Vec::new()).unwrap();
        w.add_interface("a", 19200).unwrap();
        w.add_interface("b", 19200).unwrap();
        let headers = w.bytes_written();
        w.write(0, 1_000, &frame[..5]).unwrap();
        w.write(1, 2_000, &frame[..9]).unwrap();
        w.flush_written().unwrap();
        assert_eq!(w.bytes_written(), headers, "a frame still arriving is held");
        // Port a's last byte came at 1000 + 4 byte times (~2.1 ms): settled 200 ms later.
        w.settle(100_000_000, 200_000_000).unwrap();
        assert_eq!(w.bytes_written(), headers);
        w.settle(202_084_333, 200_000_000).unwrap();
        assert_eq!(w.bytes_written(), headers + epb_size(5));
        w.comment(1, 3_000, "gap").unwrap();
        assert_eq!(w.bytes_written(), headers + epb_size(5) + epb_size(9) + 44);
        w.write(0, 5_000, &frame[..3]).unwrap();
        w.flush().unwrap();
        let (packets, _, _) = read_all(&w.into_inner().unwrap());
        let got: Vec<(u32, u64, usize)> = packets
            .iter()
            .map(|p| (p.iface, p.t_ns, p.data.len()))
            .collect();
        assert_eq!(
            got,
            [(0, 1_000, 5), (1, 2_000, 9), (1, 3_000, 0), (0, 5_000, 3)]
        );
    }

    #[test]
    fn long_chunks_are_split_with_their_own_timestamps() {
        let mut w = Writer::new(Vec::new()).unwrap();
        w.add_interface("p", 19200).unwrap();
        let data: Vec<u8> = (0..MAX_CHUNK * 2 + 5).map(|i| i as u8).collect();
        w.write(0, 1000, &data).unwrap();
        let (packets, _, damage) = read_all(&w.into_inner().unwrap());
        assert!(damage.is_empty(), "{damage:?}");
        let lens: Vec<usize> = packets.iter().map(|p| p.data.len()).collect();
        assert_eq!(lens, [MAX_CHUNK, MAX_CHUNK, 5]);
        let joined: Vec<u8> = packets.iter().flat_map(|p| p.data.clone()).collect();
        assert_eq!(joined, data);
        // 65536 bytes at 19200 baud = 34133333333.33 ns.
        assert_eq!(packets[1].t_ns, 1000 + 34_133_333_333);
        assert_eq!(packets[2].t_ns, 1000 + 68_266_666_667);
    }

    #[test]
    fn bad_arguments_are_errors_not_panics() {
        let mut w = Writer::new(Vec::new()).unwrap();
        assert!(w.write(0, 0, b"x").is_err());
        assert!(w.comment(3, 0, "x").is_err());
        assert!(w.add_interface("p", 0).is_err());
        w.add_interface("p", 9600).unwrap();
        w.write(0, 0, b"").unwrap();
        let long = "é".repeat(40_000);
        w.comment(0, 5, &long).unwrap();
        let (packets, _, damage) = read_all(&w.into_inner().unwrap());
        assert!(damage.is_empty());
        let comment = packets[0].comment.as_deref().unwrap();
        assert!(comment.len() <= 65532 && long.starts_with(comment));
    }

    #[test]
    fn every_cut_reads_the_blocks_before_it() {
        let (file, expected) = sample();
        // Block boundaries: walk the lengths.
        let mut ends = Vec::new();
        let mut at = 0;
        while at < file.len() {
            at += u32::from_le_bytes(file[at + 4..at + 8].try_into().unwrap()) as usize;
            ends.push(at);
        }
        let headers = 3; // SHB + two IDBs
        for cut in 0..=file.len() {
            let (packets, _, damage) = read_all(&file[..cut]);
            let complete = ends.iter().filter(|&&e| e <= cut).count();
            let n = complete.saturating_sub(headers);
            assert_eq!(packets, expected[..n], "cut at {cut}");
            if ends.contains(&cut) || cut == 0 {
                assert!(damage.is_empty(), "cut at {cut}: {damage:?}");
            } else {
                let start = ends.iter().rev().find(|&&e| e < cut).copied().unwrap_or(0);
                assert_eq!(damage.len(), 1, "cut at {cut}");
                assert_eq!(damage[0].offset, start as u64, "cut at {cut}");
                assert_eq!(damage[0].resumed_at, None);
            }
        }
    }

    #[test]
    fn damage_in_the_middle_is_skipped() {
        let (mut file, expected) = sample();
        // Find the third packet block and break its length field.
        let mut at = 0;
        let mut starts = Vec::new();
        while at < file.len() {
            starts.push(at);
            at += u32::from_le_bytes(file[at + 4..at + 8].try_into().unwrap()) as usize;
        }
        let bad = starts[3 + 2];
        file[bad + 4] ^= 0x40;
        let (packets, _, damage) = read_all(&file);
        let mut want = expected.clone();
        want.remove(2);
        assert_eq!(packets, want);
        assert_eq!(damage.len(), 1);
        assert_eq!(damage[0].offset, bad as u64);
        assert_eq!(damage[0].resumed_at, Some(starts[3 + 3] as u64));
        assert!(
            damage[0]
                .to_string()
                .starts_with(&format!("damaged at byte {bad} ("))
        );

        // Garbage in the middle of a file.
        let (file, expected) = sample();
        let cut = starts[3 + 4];
        let mut spliced = file[..cut].to_vec();
        spliced.extend_from_slice(&[0xAB; 37]);
        spliced.extend_from_slice(&[0; 3]);
        spliced.extend_from_slice(&file[cut..]);
        let (packets, _, damage) = read_all(&spliced);
        assert_eq!(packets, expected);
        assert_eq!(damage.len(), 1);
        assert_eq!(damage[0].resumed_at, Some(cut as u64 + 40));
    }

    #[test]
    fn not_a_recording_is_damage_not_a_panic() {
        for junk in [
            &b"hello world, this is not pcapng"[..],
            &[0x0A, 0x0D, 0x0D, 0x0A, 1, 2][..],
        ] {
            let (packets, _, damage) = read_all(junk);
            assert!(packets.is_empty());
            assert_eq!(damage.len(), 1);
            assert_eq!(damage[0].offset, 0);
        }
    }

    /// A big-endian file at the default microsecond resolution with an offset, written by hand.
    #[test]
    fn reads_other_writers_files() {
        fn block(t: u32, body: &[u8]) -> Vec<u8> {
            let len = (body.len() + 12) as u32;
            let mut b = t.to_be_bytes().to_vec();
            b.extend_from_slice(&len.to_be_bytes());
            b.extend_from_slice(body);
            b.extend_from_slice(&len.to_be_bytes());
            b
        }
        let mut shb = BYTE_ORDER_MAGIC.to_be_bytes().to_vec();
        shb.extend_from_slice(&[0, 1, 0, 0]);
        shb.extend_from_slice(&u64::MAX.to_be_bytes());
        let mut idb = vec![0, 147, 0, 0, 0, 0, 0, 0];
        idb.extend_from_slice(&[0, 3, 0, 23]); // if_description
        idb.extend_from_slice(b"UART sniffer, 9600 baud\0");
        idb.extend_from_slice(&[0, 14, 0, 8]); // if_tsoffset = 10 s
        idb.extend_from_slice(&10i64.to_be_bytes());
        idb.extend_from_slice(&[0, 0, 0, 0]);
        let mut epb = 0u32.to_be_bytes().to_vec();
        epb.extend_from_slice(&1u32.to_be_bytes()); // high
        epb.extend_from_slice(&5u32.to_be_bytes()); // low
        epb.extend_from_slice(&3u32.to_be_bytes());
        epb.extend_from_slice(&3u32.to_be_bytes());
        epb.extend_from_slice(&[0x9B, 0x16, 0x01, 0]);
        let mut file = block(SHB, &shb);
        file.extend(block(IDB, &idb));
        file.extend(block(0x0000_0BAD, &[1, 2, 3, 4])); // a custom block: skipped
        file.extend(block(EPB, &epb));
        let (packets, interfaces, damage) = read_all(&file);
        assert!(damage.is_empty(), "{damage:?}");
        assert_eq!(interfaces[0].name, "interface 0");
        assert_eq!(interfaces[0].baud, Some(9600));
        assert_eq!(packets.len(), 1);
        assert_eq!(packets[0].data, [0x9B, 0x16, 0x01]);
        assert_eq!(packets[0].t_ns, ((1u64 << 32) + 5) * 1000 + 10_000_000_000);
    }

    #[test]
    fn concatenated_recordings_continue_their_streams() {
        let (a, expected) = sample();
        let mut both = a.clone();
        both.extend_from_slice(&a);
        let (packets, interfaces, damage) = read_all(&both);
        assert!(damage.is_empty());
        assert_eq!(interfaces.len(), 2);
        assert_eq!(packets.len(), 2 * expected.len());
        assert_eq!(packets[expected.len()..], expected[..]);
    }

    #[test]
    fn timestamp_resolutions() {
        assert_eq!(TsUnit::new(9, 0).to_ns(123), 123);
        assert_eq!(TsUnit::new(6, 0).to_ns(123), 123_000);
        assert_eq!(TsUnit::new(12, 0).to_ns(123_456), 123);
        assert_eq!(TsUnit::new(0x80 | 10, 0).to_ns(1024), 1_000_000_000);
        assert_eq!(TsUnit::new(127, 0).to_ns(u64::MAX), 0);
        assert_eq!(TsUnit::new(9, -5).to_ns(1), 0);
        assert_eq!(baud_in("HW-FOC telemetry, 19200 baud 8N1"), Some(19200));
        assert_eq!(baud_in("no rate"), None);
    }
}
