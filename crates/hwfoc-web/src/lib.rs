//! The browser app's decoding: the workspace's codec (and readers) compiled to WebAssembly.
//!
//! `web/build.sh` builds this crate for `wasm32-unknown-unknown` and runs `wasm-bindgen` on it;
//! `web/src/hwfoc.js` wraps the classes exported here into the page's one API (`Session`,
//! `openFile`, `Recorder`). Nothing here is rewritten in JavaScript: the page reads bytes as the
//! command does.

#![warn(missing_docs)]

pub mod columns;
pub mod file;
pub mod session;

use hwfoc_records::Figure;
use js_sys::{Array, Object, Reflect};
use wasm_bindgen::prelude::*;

/// A session as JavaScript holds it (`web/src/hwfoc.js`'s `Session` wraps it).
#[wasm_bindgen(js_name = WasmSession)]
pub struct WasmSession {
    inner: session::Session,
}

#[wasm_bindgen(js_class = WasmSession)]
impl WasmSession {
    /// A session reading port `name` at `baud` (HW-FOC's 19200 when not given), every
    /// format or only `protocol` (a name `--protocol` takes); a CAN bus (`slcan:` name, or a
    /// CAN protocol) is fed SocketCAN records ([`session::Session::new`]).
    #[wasm_bindgen(constructor)]
    pub fn new(
        protocol: Option<String>,
        name: Option<String>,
        baud: Option<u32>,
    ) -> Result<WasmSession, JsError> {
        let name = name.unwrap_or_else(|| "port".to_owned());
        let inner = session::Session::new(protocol.as_deref(), &name, baud)
            .map_err(|e| JsError::new(&e.to_string()))?;
        Ok(WasmSession { inner })
    }

    /// Decodes `bytes`, the chunk whose last byte came at `t_micros` (Unix microseconds), or
    /// without a time.
    pub fn feed(&mut self, bytes: &[u8], t_micros: Option<f64>) {
        self.inner.feed(bytes, t_micros);
    }

    /// Ends the stream.
    pub fn finish(&mut self) {
        self.inner.finish();
    }

    /// The records decoded since the last call: `{count, columns, protocols}`
    /// ([`columns::Columns::take`]).
    #[wasm_bindgen(js_name = takeRecords)]
    pub fn take_records(&mut self) -> Result<Object, JsValue> {
        self.inner.columns().take()
    }

    /// The notices so far, as the command's stderr lines.
    pub fn notices(&self) -> Array {
        self.inner
            .notices()
            .iter()
            .map(|n| JsValue::from_str(n))
            .collect()
    }

    /// Per ESC, the figures of `hwfoc summary --json`'s object that a live port gives:
    /// `{esc, frames, info_frames, info, link, energy}` (`link`: checksum failures, lost and
    /// duplicate packets, restarts, bytes skipped, delivery ratio, null where the protocol
    /// has none; `energy`: charge, energy, peak and mean power, seconds, or null).
    pub fn summary(&self) -> Result<Object, JsValue> {
        let escs = Array::new();
        for (esc, figures, link) in self.inner.escs() {
            let o = Object::new();
            set(&o, "esc", esc as f64)?;
            set(&o, "frames", figures.frames as f64)?;
            set(&o, "info_frames", figures.info_frames as f64)?;
            let infos = Array::new();
            if let Some(text) = &figures.info {
                let i = Object::new();
                Reflect::set(&i, &"text".into(), &text.into())?;
                infos.push(&i);
            }
            Reflect::set(&o, &"info".into(), &infos)?;
            let l = Object::new();
            for (name, value) in link.figures() {
                set(&l, name, value.map(Figure::as_f64))?;
            }
            Reflect::set(&o, &"link".into(), &l)?;
            let energy = if figures.powered {
                let e = &figures.energy;
                let j = Object::new();
                set(&j, "charge_mah", e.charge_mah())?;
                set(&j, "energy_wh", e.energy_wh())?;
                set(&j, "peak_power_w", e.peak_w())?;
                set(&j, "mean_power_w", e.mean_w())?;
                set(&j, "seconds", e.seconds())?;
                JsValue::from(j)
            } else {
                JsValue::NULL
            };
            Reflect::set(&o, &"energy".into(), &energy)?;
            escs.push(&o);
        }
        let out = Object::new();
        Reflect::set(&out, &"escs".into(), &escs)?;
        Ok(out)
    }
}

/// Sets `key` of `o` to a number (null for `None`).
fn set(o: &Object, key: &str, value: impl Into<Option<f64>>) -> Result<(), JsValue> {
    let value = value.into().map_or(JsValue::NULL, JsValue::from);
    Reflect::set(o, &key.into(), &value).map(|_| ())
}

/// The names of the set fault bits of `status` in bit order, by `protocol` (a name
/// `--protocol` takes), as a record's `faults` gives them; empty for an unknown protocol.
#[wasm_bindgen(js_name = faultNames)]
pub fn fault_names(protocol: &str, status: u16) -> Array {
    hwfoc::Protocol::from_name(protocol)
        .into_iter()
        .flat_map(|p| p.fault_names(hwfoc::Status(status)))
        .map(JsValue::from_str)
        .collect()
}

/// A recording's records, summary and notices (`file::open`): `{records, summary, notices}`,
/// `records` as [`WasmSession::take_records`] gives them, `summary` the object of
/// `hwfoc summary --json` (null when the file could not be read).
#[wasm_bindgen(js_name = openFile)]
pub fn open_file(name: &str, bytes: Vec<u8>) -> Result<Object, JsValue> {
    let mut opened = file::open(name, bytes);
    let out = Object::new();
    Reflect::set(&out, &"records".into(), &opened.columns.take()?.into())?;
    Reflect::set(
        &out,
        &"summary".into(),
        &js_sys::JSON::parse(&opened.summary)?,
    )?;
    let notices: Array = opened
        .notices
        .iter()
        .map(|n| JsValue::from_str(n))
        .collect();
    Reflect::set(&out, &"notices".into(), &notices)?;
    Ok(out)
}

/// A recording of one port's bytes with their receive times, written as `hwfoc record` writes
/// it (`hwfoc_records::pcapng::Writer`): the port is declared at its first bytes.
#[wasm_bindgen(js_name = WasmRecorder)]
pub struct WasmRecorder {
    writer: Option<hwfoc_records::pcapng::Writer<Vec<u8>>>,
    port: String,
    baud: u32,
    declared: bool,
}

#[wasm_bindgen(js_class = WasmRecorder)]
impl WasmRecorder {
    /// A recording of the port named `port`, read at `baud` (8N1).
    #[wasm_bindgen(constructor)]
    pub fn new(port: String, baud: u32) -> Result<WasmRecorder, JsError> {
        let writer = hwfoc_records::pcapng::Writer::new(Vec::new())
            .map_err(|e| JsError::new(&format!("{port}: {e}")))?;
        Ok(WasmRecorder {
            writer: Some(writer),
            port,
            baud,
            declared: false,
        })
    }

    /// Adds a chunk as the port gave it, its last byte received at `t_micros` (Unix
    /// microseconds).
    pub fn add(&mut self, bytes: &[u8], t_micros: f64) -> Result<(), JsError> {
        let port = self.port.clone();
        let err = |e: std::io::Error| JsError::new(&format!("{port}: {e}"));
        let Some(writer) = self.writer.as_mut() else {
            return Err(JsError::new(&format!("{port}: the recording is finished")));
        };
        if !self.declared {
            writer.add_interface(&self.port, self.baud).map_err(err)?;
            self.declared = true;
        }
        let first_ns = session::first_byte_ns(t_micros, bytes.len(), self.baud);
        writer.write(0, first_ns, bytes).map_err(err)
    }

    /// The pcapng file.
    pub fn finish(&mut self) -> Result<Vec<u8>, JsError> {
        let port = self.port.clone();
        let writer = self
            .writer
            .take()
            .ok_or_else(|| JsError::new(&format!("{port}: the recording is finished")))?;
        writer
            .into_inner()
            .map_err(|e| JsError::new(&format!("{port}: {e}")))
    }
}
