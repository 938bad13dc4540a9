//! The browser app's decoding: the workspace's codec (and readers) compiled to WebAssembly.
//!
//! `web/build.sh` builds this crate for `wasm32-unknown-unknown` and runs `wasm-bindgen` on it;
//! `web/src/hwfoc.js` wraps the classes exported here into the page's one API (`Session`,
//! `openFile`, `Recorder`). Nothing here is rewritten in JavaScript: the page reads bytes as the
//! command does.

#![warn(missing_docs)]

pub mod columns;
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
