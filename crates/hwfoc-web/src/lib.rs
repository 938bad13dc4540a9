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

use js_sys::{Array, Object, Reflect};
use wasm_bindgen::prelude::*;

/// A session as JavaScript holds it (`web/src/hwfoc.js`'s `Session` wraps it).
#[wasm_bindgen(js_name = WasmSession)]
pub struct WasmSession {
    inner: session::Session,
}

#[wasm_bindgen(js_class = WasmSession)]
impl WasmSession {
    /// A session reading every serial format, or only `protocol` (a name `--protocol` takes).
    #[wasm_bindgen(constructor)]
    pub fn new(protocol: Option<String>) -> Result<WasmSession, JsError> {
        let inner =
            session::Session::new(protocol.as_deref()).map_err(|e| JsError::new(&e.to_string()))?;
        Ok(WasmSession { inner })
    }

    /// Decodes `bytes`, the chunk whose last byte came at `t_micros` (Unix microseconds), or
    /// without a time (a file).
    pub fn feed(&mut self, bytes: &[u8], t_micros: Option<f64>) {
        self.inner.feed(bytes, t_micros.map(|t| t / 1e6));
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

    /// Per ESC: `{esc, frames, info_frames, info}`.
    pub fn summary(&self) -> Result<Object, JsValue> {
        let escs = Array::new();
        for (esc, frames, info_frames, info) in self.inner.escs() {
            let o = Object::new();
            Reflect::set(&o, &"esc".into(), &(esc as u32).into())?;
            Reflect::set(&o, &"frames".into(), &(frames as f64).into())?;
            Reflect::set(&o, &"info_frames".into(), &(info_frames as f64).into())?;
            let infos = Array::new();
            if let Some(text) = info {
                let i = Object::new();
                Reflect::set(&i, &"text".into(), &text.into())?;
                infos.push(&i);
            }
            Reflect::set(&o, &"info".into(), &infos)?;
            escs.push(&o);
        }
        let out = Object::new();
        Reflect::set(&out, &"escs".into(), &escs)?;
        Ok(out)
    }
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
        // The time of the chunk's first byte: the last's less the wire time of the others.
        let per_byte = hwfoc::wire::byte_ns(self.baud);
        let last_ns = (t_micros.max(0.0) * 1000.0) as u64;
        let before = (bytes.len().saturating_sub(1) as f64 * per_byte) as u64;
        writer
            .write(0, last_ns.saturating_sub(before), bytes)
            .map_err(err)
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
