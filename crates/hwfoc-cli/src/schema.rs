//! The telemetry record of `RECORD-SCHEMA.md` and its text encodings (JSON Lines and CSV).
//!
//! Numbers are written with `itoa`/`ryu` (the shortest text that reads back to the same value,
//! as `serde_json` writes them), straight into the output buffer: no allocation per record.

use hwfoc::{DataFrame, Settings, Status};

/// Column names in schema order.
pub const COLUMNS: [&str; 14] = [
    "t_s",
    "esc",
    "packet",
    "throttle_in_pct",
    "throttle_out_pct",
    "erpm",
    "rpm",
    "voltage_v",
    "current_a",
    "phase_current_a",
    "mos_temp_c",
    "cap_temp_c",
    "status",
    "faults",
];

/// One decoded data frame in physical units, as every output presents it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Record {
    /// Receive time of the frame's first byte, in seconds, if the source has timing.
    pub t_s: Option<f64>,
    /// Index of the input the frame came from.
    pub esc: u8,
    /// Packet number.
    pub packet: u16,
    /// Input throttle, %.
    pub throttle_in_pct: f32,
    /// Output throttle, %.
    pub throttle_out_pct: f32,
    /// Electrical RPM.
    pub erpm: u32,
    /// Mechanical RPM under the settings.
    pub rpm: f32,
    /// Input voltage, V.
    pub voltage_v: f32,
    /// Input current, A.
    pub current_a: f32,
    /// Phase current, A.
    pub phase_current_a: f32,
    /// MOSFET temperature, degC, if in the table's range.
    pub mos_temp_c: Option<f32>,
    /// Capacitor temperature, degC, if in the table's range.
    pub cap_temp_c: Option<f32>,
    /// Raw status word (the `faults` column is derived from it).
    pub status: Status,
}

impl Record {
    /// Converts a frame under `settings`.
    pub fn new(t_s: Option<f64>, esc: u8, f: &DataFrame, settings: &Settings) -> Record {
        Record {
            t_s,
            esc,
            packet: f.packet,
            throttle_in_pct: f.throttle_in_pct(),
            throttle_out_pct: f.throttle_out_pct(),
            erpm: f.erpm(),
            rpm: f.rpm(settings),
            voltage_v: f.voltage_v(),
            current_a: f.current_a(settings),
            phase_current_a: f.phase_current_a(settings),
            mos_temp_c: f.mos_temp().celsius(),
            cap_temp_c: f.cap_temp().celsius(),
            status: f.status,
        }
    }

    /// Appends the record as one JSON object and a newline.
    pub fn write_json(&self, out: &mut Vec<u8>) {
        let mut num = Numbers::default();
        out.extend_from_slice(b"{\"t_s\":");
        match self.t_s {
            Some(t) => num.f64(out, t),
            None => out.extend_from_slice(b"null"),
        }
        out.extend_from_slice(b",\"esc\":");
        num.int(out, self.esc);
        out.extend_from_slice(b",\"packet\":");
        num.int(out, self.packet);
        out.extend_from_slice(b",\"throttle_in_pct\":");
        num.f32(out, self.throttle_in_pct);
        out.extend_from_slice(b",\"throttle_out_pct\":");
        num.f32(out, self.throttle_out_pct);
        out.extend_from_slice(b",\"erpm\":");
        num.int(out, self.erpm);
        out.extend_from_slice(b",\"rpm\":");
        num.f32(out, self.rpm);
        out.extend_from_slice(b",\"voltage_v\":");
        num.f32(out, self.voltage_v);
        out.extend_from_slice(b",\"current_a\":");
        num.f32(out, self.current_a);
        out.extend_from_slice(b",\"phase_current_a\":");
        num.f32(out, self.phase_current_a);
        out.extend_from_slice(b",\"mos_temp_c\":");
        num.opt_f32(out, self.mos_temp_c, b"null");
        out.extend_from_slice(b",\"cap_temp_c\":");
        num.opt_f32(out, self.cap_temp_c, b"null");
        out.extend_from_slice(b",\"status\":");
        num.int(out, self.status.0);
        out.extend_from_slice(b",\"faults\":[");
        for (i, fault) in self.status.faults().enumerate() {
            if i > 0 {
                out.push(b',');
            }
            // Fault names are plain ASCII identifiers: nothing to escape.
            out.push(b'"');
            out.extend_from_slice(fault.name().as_bytes());
            out.push(b'"');
        }
        out.extend_from_slice(b"]}\n");
    }

    /// Appends the CSV header row.
    pub fn write_csv_header(out: &mut Vec<u8>) {
        out.extend_from_slice(COLUMNS.join(",").as_bytes());
        out.push(b'\n');
    }

    /// Appends the record as one CSV row: empty fields for nulls, faults joined by `|`.
    pub fn write_csv(&self, out: &mut Vec<u8>) {
        let mut num = Numbers::default();
        if let Some(t) = self.t_s {
            num.f64(out, t);
        }
        out.push(b',');
        num.int(out, self.esc);
        out.push(b',');
        num.int(out, self.packet);
        out.push(b',');
        num.f32(out, self.throttle_in_pct);
        out.push(b',');
        num.f32(out, self.throttle_out_pct);
        out.push(b',');
        num.int(out, self.erpm);
        out.push(b',');
        num.f32(out, self.rpm);
        out.push(b',');
        num.f32(out, self.voltage_v);
        out.push(b',');
        num.f32(out, self.current_a);
        out.push(b',');
        num.f32(out, self.phase_current_a);
        out.push(b',');
        num.opt_f32(out, self.mos_temp_c, b"");
        out.push(b',');
        num.opt_f32(out, self.cap_temp_c, b"");
        out.push(b',');
        num.int(out, self.status.0);
        out.push(b',');
        for (i, fault) in self.status.faults().enumerate() {
            if i > 0 {
                out.push(b'|');
            }
            out.extend_from_slice(fault.name().as_bytes());
        }
        out.push(b'\n');
    }
}

/// Formatting buffers for numbers.
#[derive(Default)]
struct Numbers {
    int: itoa::Buffer,
    float: ryu::Buffer,
}

impl Numbers {
    fn int(&mut self, out: &mut Vec<u8>, v: impl itoa::Integer) {
        out.extend_from_slice(self.int.format(v).as_bytes());
    }

    /// Finite values only: every value written is computed from integers by a finite factor.
    fn f32(&mut self, out: &mut Vec<u8>, v: f32) {
        out.extend_from_slice(self.float.format_finite(v).as_bytes());
    }

    fn f64(&mut self, out: &mut Vec<u8>, v: f64) {
        out.extend_from_slice(self.float.format_finite(v).as_bytes());
    }

    fn opt_f32(&mut self, out: &mut Vec<u8>, v: Option<f32>, null: &[u8]) {
        match v {
            Some(v) => self.f32(out, v),
            None => out.extend_from_slice(null),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first frame of the XRotor capture and the JSON line RECORD-SCHEMA.md gives for it.
    #[test]
    fn schema_example_line() {
        let bytes = [
            0x9B, 0x16, 0x01, 0x02, 0x05, 0xC2, 0, 0, 0, 0, 0, 0, 0x00, 0xF7, 0xFF, 0xFF, 0xFF,
            0xFF, 0xCE, 0xD1, 0x00, 0x00, 0x0D, 0x08,
        ];
        let frame = DataFrame::parse(&bytes).unwrap();
        let record = Record::new(Some(0.22798), 0, &frame, &Settings::default());
        let mut out = Vec::new();
        record.write_json(&mut out);
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "{\"t_s\":0.22798,\"esc\":0,\"packet\":1474,\"throttle_in_pct\":0.0,\"throttle_out_pct\":0.0,\"erpm\":0,\"rpm\":0.0,\"voltage_v\":24.7,\"current_a\":-0.015625,\"phase_current_a\":-0.015625,\"mos_temp_c\":28.0,\"cap_temp_c\":26.0,\"status\":0,\"faults\":[]}\n"
        );
    }

    #[test]
    fn nulls_faults_and_csv() {
        let frame = DataFrame {
            packet: 3,
            mos_adc: 250,
            cap_adc: 10,
            erpm_raw: 700,
            status: Status(0x0041),
            ..Default::default()
        };
        let record = Record::new(None, 2, &frame, &Settings::default());
        let mut json = Vec::new();
        record.write_json(&mut json);
        let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
        assert_eq!(v["t_s"], serde_json::Value::Null);
        assert_eq!(v["mos_temp_c"], serde_json::Value::Null);
        assert_eq!(v["rpm"], 1000.0);
        assert_eq!(
            v["faults"],
            serde_json::json!(["input_voltage_high", "mos_overheat"])
        );
        // serde_json keeps the order of the keys (feature preserve_order): the schema's order.
        let keys: Vec<&str> = v.as_object().unwrap().keys().map(|k| k.as_str()).collect();
        assert_eq!(keys, COLUMNS);

        let mut csv = Vec::new();
        Record::write_csv_header(&mut csv);
        record.write_csv(&mut csv);
        assert_eq!(
            String::from_utf8(csv).unwrap(),
            "t_s,esc,packet,throttle_in_pct,throttle_out_pct,erpm,rpm,voltage_v,current_a,phase_current_a,mos_temp_c,cap_temp_c,status,faults\n\
             ,2,3,0.0,0.0,7000,1000.0,0.0,0.0,0.0,,,65,input_voltage_high|mos_overheat\n"
        );
    }
}
