//! The pcapng writer: the section header, interfaces, frames cut from each port's bytes, notes.

use std::io::{self, Write};

use hwfoc::dronecan::SOCKETCAN_RECORD_LEN;

use super::cut::{Cutter, PieceSink};
use super::{
    BYTE_ORDER_MAGIC, EPB, IDB, IF_DESCRIPTION, IF_NAME, IF_SPEED, IF_TSRESOL, LINKTYPE,
    LINKTYPE_CAN_SOCKETCAN, MAX_CHUNK, OPT_COMMENT, OPT_END, RecordingId, SHB, SHB_OS,
    SHB_USERAPPL,
};

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
    /// Whether each interface is a CAN bus ([`Writer::add_can_interface`]).
    can: Vec<bool>,
    block: Vec<u8>,
    written: u64,
    /// The recording the file is part of, named in its section header.
    recording: RecordingId,
}

/// Bytes of file an EPB without options takes for `len` bytes of packet.
pub(super) fn epb_size(len: usize) -> u64 {
    32 + len.next_multiple_of(4) as u64
}

/// The pieces of a cutter written as packets of one interface.
struct Packets<'a, W: Write> {
    writer: &'a mut Writer<W>,
    iface: u32,
}

impl<W: Write> PieceSink for Packets<'_, W> {
    type Error = io::Error;
    fn piece(&mut self, t_ns: u64, bytes: &[u8]) -> io::Result<()> {
        self.writer.chunk(self.iface, t_ns, bytes)
    }
}

/// The pieces of a cutter counted as file bytes.
struct Cost(u64);

impl PieceSink for Cost {
    type Error = std::convert::Infallible;
    fn piece(&mut self, _: u64, bytes: &[u8]) -> Result<(), Self::Error> {
        let whole = (bytes.len() / MAX_CHUNK) as u64 * epb_size(MAX_CHUNK);
        let rest = bytes.len() % MAX_CHUNK;
        self.0 += whole + if rest > 0 { epb_size(rest) } else { 0 };
        Ok(())
    }
}

impl<W: Write> Writer<W> {
    /// Starts a new recording: writes the section header block (little-endian, naming `hwfoc`
    /// and its version as the writing application, and a new [`RecordingId`]).
    pub fn new(w: W) -> io::Result<Self> {
        Writer::continuing(w, RecordingId::new())
    }

    /// Starts a file of recording `recording` (the next file of a rotated recording: the same
    /// id in every file tells readers the files are one recording).
    pub fn continuing(w: W, recording: RecordingId) -> io::Result<Self> {
        let mut writer = Writer {
            inner: w,
            ports: Vec::new(),
            can: Vec::new(),
            block: Vec::with_capacity(256),
            written: 0,
            recording,
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
        writer.option(OPT_COMMENT, recording.comment().as_bytes());
        writer.end_options();
        writer.finish()?;
        Ok(writer)
    }

    /// Declares a port: writes its interface description block and returns its interface id
    /// (0, 1, 2, … in the order of the calls). `baud` must not be zero. Its description says
    /// hwfoc recorded ESC telemetry; [`Writer::add_port`] names the format too.
    pub fn add_interface(&mut self, port: &str, baud: u32) -> io::Result<u32> {
        self.add_port(port, baud, None)
    }

    /// [`Writer::add_interface`] for a port known to carry `protocol`: its description names
    /// the format (`HW5 telemetry (hwfoc), 115200 baud 8N1`), for Wireshark and other readers
    /// (hwfoc reads the bytes, whatever the description says).
    pub fn add_port(
        &mut self,
        port: &str,
        baud: u32,
        protocol: Option<hwfoc::Protocol>,
    ) -> io::Result<u32> {
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
        self.option(IF_DESCRIPTION, port_description(protocol, baud).as_bytes());
        self.option(IF_SPEED, &u64::from(baud).to_le_bytes());
        self.option(IF_TSRESOL, &[9]);
        self.end_options();
        self.finish()?;
        self.ports
            .push((baud, Cutter::new(hwfoc::wire::byte_ns(baud))));
        self.can.push(false);
        Ok(id)
    }

    /// Declares a CAN bus: writes an interface description block of link type
    /// [`LINKTYPE_CAN_SOCKETCAN`] (`if_name` = `bus`, `if_speed` = `bitrate` where known, the
    /// description "CAN bus (DroneCAN), 500000 bit/s") and returns its interface id. Its frames
    /// are written with [`Writer::write_can`] (or [`Writer::write`], which takes them as
    /// records back to back).
    pub fn add_can_interface(&mut self, bus: &str, bitrate: Option<u32>) -> io::Result<u32> {
        let id = u32::try_from(self.ports.len())
            .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "too many interfaces"))?;
        self.begin(IDB);
        self.put_u16(LINKTYPE_CAN_SOCKETCAN as u16);
        self.put_u16(0); // reserved
        self.put_u32(0); // snap length: no limit
        self.option(IF_NAME, bus.as_bytes());
        let description = match bitrate {
            Some(b) => format!("CAN bus (DroneCAN), {b} bit/s"),
            None => "CAN bus (DroneCAN)".to_string(),
        };
        self.option(IF_DESCRIPTION, description.as_bytes());
        if let Some(b) = bitrate.filter(|&b| b > 0) {
            self.option(IF_SPEED, &u64::from(b).to_le_bytes());
        }
        self.option(IF_TSRESOL, &[9]);
        self.end_options();
        self.finish()?;
        // The baud rate is not used for a CAN interface (its packets are never cut).
        let baud = crate::serial::DEFAULT_BAUD;
        self.ports
            .push((baud, Cutter::new(hwfoc::wire::byte_ns(baud))));
        self.can.push(true);
        Ok(id)
    }

    /// Writes one CAN frame received on the CAN interface `iface` at `t_ns` (Unix ns): one
    /// packet holding its record ([`hwfoc::dronecan::CanFrame::to_socketcan_record`]).
    pub fn write_can(
        &mut self,
        iface: u32,
        t_ns: u64,
        record: &[u8; SOCKETCAN_RECORD_LEN],
    ) -> io::Result<()> {
        if !self.is_can(iface)? {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("interface {iface} is not a CAN interface"),
            ));
        }
        self.packet(iface, t_ns, record, None)
    }

    /// Whether interface `iface` is a CAN bus; an error if it was never added.
    fn is_can(&self, iface: u32) -> io::Result<bool> {
        self.baud(iface)?;
        Ok(self.can[iface as usize])
    }

    /// Writes bytes received on interface `iface`, `t_ns` the Unix time in nanoseconds of the
    /// first of them (the bytes of one read of a port, back to back): each frame they complete
    /// becomes a packet, timestamped with its first byte's time, and the bytes between frames
    /// packets of their own (see the module documentation). The bytes of a frame still arriving
    /// are held for the next call. An empty `data` writes nothing.
    ///
    /// On a CAN interface, `data` is frame records back to back (a CAN stream's bytes), each
    /// written as a packet at `t_ns`; a length that is not a multiple of 16 is an error.
    pub fn write(&mut self, iface: u32, t_ns: u64, data: &[u8]) -> io::Result<()> {
        if self.is_can(iface)? {
            let (records, rest) = data.as_chunks::<SOCKETCAN_RECORD_LEN>();
            if !rest.is_empty() {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!("{} bytes are not whole CAN frame records", data.len()),
                ));
            }
            for record in records {
                self.packet(iface, t_ns, record, None)?;
            }
            return Ok(());
        }
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
        let mut cost = Cost(0);
        if self.is_can(iface)? {
            cost.0 = (data.len() / SOCKETCAN_RECORD_LEN) as u64 * epb_size(SOCKETCAN_RECORD_LEN);
        }
        for (i, (_, cutter)) in self.ports.iter().enumerate() {
            if i != iface as usize && !cutter.holds() {
                continue;
            }
            let mut cutter = cutter.clone();
            if i == iface as usize && !self.can[i] {
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

    /// The recording this file is part of (see [`Writer::continuing`]).
    pub fn recording_id(&self) -> RecordingId {
        self.recording
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

/// What the interface of a serial port says it holds: `HW5 telemetry (hwfoc), 115200 baud 8N1`,
/// or for a port whose format is not known when it is declared `ESC telemetry (hwfoc), 19200
/// baud 8N1`. The Wireshark dissector takes interfaces whose description holds
/// `telemetry (hwfoc)` (and, as recordings before these words said, `HW-FOC telemetry`).
fn port_description(protocol: Option<hwfoc::Protocol>, baud: u32) -> String {
    let title = protocol.map_or("ESC", hwfoc::Protocol::title);
    format!("{title} telemetry (hwfoc), {baud} baud 8N1")
}
