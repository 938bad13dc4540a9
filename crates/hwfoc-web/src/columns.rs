//! The records decoded so far, held column by column as the page reads them: one typed array
//! per column of the record schema (`docs/RECORD-SCHEMA.md`), a null float as NaN.

use hwfoc::telemetry::Data;
use hwfoc::{Protocol, Quantity, Settings};
use hwfoc_records::Record;
use js_sys::{Array, Float32Array, Float64Array, Object, Reflect, Uint8Array};
use wasm_bindgen::JsValue;

/// The columns given as Float64Array: unsigned integers that may be null (NaN).
const NULLABLE_INTEGERS: [&str; 6] = [
    "packet",
    "erpm",
    "status",
    "node",
    "msg2_age_ms",
    "msg3_age_ms",
];

/// Records column by column, emptied by [`Columns::take`].
#[derive(Default)]
pub struct Columns {
    t_s: Vec<f64>,
    esc: Vec<u8>,
    protocol: Vec<u8>,
    /// `NULLABLE_INTEGERS`' columns, in that order.
    integers: [Vec<f64>; 6],
    /// Every float quantity of [`Quantity::ALL`] but `erpm`, in that order.
    floats: Vec<Vec<f32>>,
}

/// The float32 quantities: every quantity but eRPM, which is an integer.
fn float_quantities() -> impl Iterator<Item = Quantity> {
    Quantity::ALL.into_iter().filter(|q| *q != Quantity::Erpm)
}

/// The code of `protocol` in the `protocol` column: its place in [`Protocol::ALL`].
fn protocol_code(protocol: Protocol) -> u8 {
    protocol.index() as u8
}

impl Columns {
    /// The number of records held.
    pub fn len(&self) -> usize {
        self.esc.len()
    }

    /// Whether no record is held.
    pub fn is_empty(&self) -> bool {
        self.esc.is_empty()
    }

    /// Adds a record as the command makes it (`hwfoc_records::Record`).
    pub fn push_record(&mut self, r: &Record) {
        if self.floats.is_empty() {
            self.floats = float_quantities().map(|_| Vec::new()).collect();
        }
        let nan = f64::NAN;
        self.t_s.push(r.t_s.unwrap_or(nan));
        self.esc.push(r.esc);
        self.protocol.push(protocol_code(r.protocol));
        let integers = [
            r.packet.map(f64::from),
            r.erpm.map(f64::from),
            r.status.map(|s| f64::from(s.0)),
            r.node.map(f64::from),
            r.msg2_age_ms.map(f64::from),
            r.msg3_age_ms.map(f64::from),
        ];
        for (column, value) in self.integers.iter_mut().zip(integers) {
            column.push(value.unwrap_or(nan));
        }
        // In the order of `float_quantities`: Quantity::ALL but eRPM.
        let floats = [
            r.throttle_in_pct,
            r.throttle_out_pct,
            r.rpm,
            r.voltage_v,
            r.current_a,
            r.phase_current_a,
            r.mos_temp_c,
            r.cap_temp_c,
            r.motor_temp_c,
            r.bec_temp_c,
            r.bec_voltage_v,
            r.bec_current_a,
        ];
        for (column, value) in self.floats.iter_mut().zip(floats) {
            column.push(value.unwrap_or(f32::NAN));
        }
    }

    /// Adds the record of `data` from ESC `esc` received at `t_s` (seconds, or None), converted
    /// as the command converts it ([`Record::new`]).
    pub fn push(&mut self, t_s: Option<f64>, esc: u8, data: &Data, settings: &Settings) {
        self.push_record(&Record::new(t_s, esc, data, settings));
    }

    /// The records held as `{count, columns: {name: TypedArray}, protocols}`, emptying the
    /// columns, in the record schema's order. `protocol` is a Uint8Array of places in
    /// `protocols` (the names `--protocol` takes); every other column is the schema's, a null as
    /// NaN (`faults` is left out: it is `status` named by `protocol`).
    pub fn take(&mut self) -> Result<Object, JsValue> {
        let taken = core::mem::take(self);
        let columns = Object::new();
        let set = |name: &str, value: JsValue| Reflect::set(&columns, &name.into(), &value);
        let integer = |name: &str| {
            let at = NULLABLE_INTEGERS.iter().position(|n| *n == name);
            JsValue::from(Float64Array::from(&taken.integers[at.unwrap_or(0)][..]))
        };
        set("t_s", Float64Array::from(&taken.t_s[..]).into())?;
        set("esc", Uint8Array::from(&taken.esc[..]).into())?;
        set("protocol", Uint8Array::from(&taken.protocol[..]).into())?;
        set("packet", integer("packet"))?;
        let mut floats = float_quantities().zip(&taken.floats);
        for quantity in Quantity::ALL {
            if quantity == Quantity::Erpm {
                set("erpm", integer("erpm"))?;
            } else if let Some((q, column)) = floats.next() {
                set(q.name(), Float32Array::from(&column[..]).into())?;
            }
        }
        for name in &NULLABLE_INTEGERS[2..] {
            set(name, integer(name))?;
        }
        let protocols: Array = Protocol::ALL
            .iter()
            .map(|p| JsValue::from_str(p.name()))
            .collect();
        let out = Object::new();
        Reflect::set(&out, &"count".into(), &(taken.len() as u32).into())?;
        Reflect::set(&out, &"columns".into(), &columns)?;
        Reflect::set(&out, &"protocols".into(), &protocols)?;
        Ok(out)
    }
}
