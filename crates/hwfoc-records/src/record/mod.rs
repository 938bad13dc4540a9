//! The telemetry record of `docs/RECORD-SCHEMA.md`: one row per data frame, in physical units, the
//! same columns in every output.
//!
//! The columns are declared once, in the table of [`columns`] (name, unit, value type, how the
//! value is computed from a frame under the settings); everything else is derived from it by
//! name, at compile time:
//!
//! - [`Record`], [`Record::new`], [`COLUMNS`] and [`UNITS`];
//! - a zero-sized type per column implementing [`Column`], and [`columns::visit`], which calls
//!   a [`Visitor`] with each column's type in schema order: writers are generic over the
//!   column, monomorphised and inlined, with no dispatch per row;
//! - the text encodings (JSON Lines and CSV, [`TextEncoder`]), the Arrow schema and record
//!   batches (`hwfoc-io`'s `write::arrow`), the Parquet columns (the `parquet` feature): each
//!   format stores a column as its [`Value`] type says.
//!
//! How to add a column: see [`columns`].

#[macro_use]
mod column;
pub mod columns;
mod frames;
mod text;

pub use column::{Column, Cons, FaultList, Nil, UtcTime, Value, Visitor};
pub use columns::{COLUMNS, Record, TEXT_COLUMNS, UNITS};
pub use frames::{DataFrames, FrameSlice};
pub use text::TextEncoder;

impl Record {
    /// The record's fault word: its `status` where its protocol has fault bits (see
    /// [`hwfoc::telemetry::Data::fault_word`]: a Hobbywing CAN ESC's `status` is no fault word).
    pub fn fault_word(&self) -> Option<hwfoc::Status> {
        self.status.filter(|_| self.protocol.has_faults())
    }

    /// Appends the record as one JSON object and a newline.
    ///
    /// For many records, [`TextEncoder`] is faster: it remembers the text of recent numbers.
    pub fn write_json(&self, out: &mut Vec<u8>) {
        TextEncoder::new().json(self, out);
    }

    /// Appends the CSV header row: the names of the columns text formats write
    /// ([`TEXT_COLUMNS`]), joined by commas.
    pub fn write_csv_header(out: &mut Vec<u8>) {
        out.extend_from_slice(TEXT_COLUMNS.join(",").as_bytes());
        out.push(b'\n');
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hwfoc::foc::DataFrame;
    use hwfoc::{Settings, Status};

    /// Reading a column from the record gives what computing it from the frame gives.
    #[test]
    fn record_fields_are_the_columns_of_the_frame() {
        struct Check<'a> {
            t: Option<f64>,
            esc: u8,
            frame: &'a DataFrame,
            settings: &'a Settings,
            record: Record,
        }
        impl Visitor for Check<'_> {
            fn column<C: Column>(&mut self) {
                let from_frame = C::from_frame(
                    self.t,
                    self.esc,
                    &hwfoc::telemetry::Data::from(*self.frame),
                    self.settings,
                );
                // NaN never occurs in a record: equality is the right test.
                assert_eq!(C::from_record(&self.record), from_frame, "{}", C::NAME);
            }
        }
        let settings = Settings::new(100.0, 14, 2.5).unwrap();
        for (i, status) in [0u16, 0x0041, 0xFFFF].into_iter().enumerate() {
            let frame = DataFrame {
                packet: 7 + i as u16,
                throttle_in_raw: 512,
                throttle_out_raw: 300,
                erpm_raw: 12_345,
                voltage_raw: 247,
                current_raw: -5,
                phase_current_raw: 1000,
                mos_adc: [206, 250, 20][i],
                cap_adc: 210,
                status: Status(status),
            };
            let t = [Some(1.5), None, Some(1.7e9)][i];
            let record = Record::new(t, i as u8, &hwfoc::telemetry::Data::from(frame), &settings);
            columns::visit(&mut Check {
                t,
                esc: i as u8,
                frame: &frame,
                settings: &settings,
                record,
            });
        }
    }

    /// Only `esc` and `protocol` are never null (schema version 2): every measurement,
    /// `packet`, `status` and `faults` may be null, and a quantity's column is null exactly
    /// where the frame's protocol does not carry it (never 0). One sample of each protocol; a
    /// new protocol is a new arm of `Data`: the `match` below does not compile until it has a
    /// sample here.
    #[test]
    fn a_column_is_null_exactly_where_the_protocol_does_not_carry_it() {
        use hwfoc::telemetry::{Data, Telemetry};
        use hwfoc::{Protocol, Quantity};

        struct NonNull(Vec<&'static str>);
        impl Visitor for NonNull {
            fn column<C: Column>(&mut self) {
                if !C::NULLABLE {
                    self.0.push(C::NAME);
                }
            }
        }
        let mut non_null = NonNull(Vec::new());
        columns::visit(&mut non_null);
        // Written out: the schema's table (docs/RECORD-SCHEMA.md) as it stands.
        assert_eq!(non_null.0, ["esc", "protocol"]);
        let frame = DataFrame {
            packet: 3,
            voltage_raw: 247,
            mos_adc: 206,
            cap_adc: 206,
            ..DataFrame::default()
        };
        let info = hwfoc::v4::InfoFrame {
            full_scale: 1000,
            v1: 8,
            v2: 91,
            i1: 1,
            i2: 2,
            i3: 0,
            t1: 0x21,
            t2: 0x21,
        };
        let v4 = hwfoc::v4::DataFrame {
            counter: 3,
            throttle_in_raw: 500,
            voltage_adc: 1365,
            current_adc: 40,
            temp_adc: 3244,
            temp2_adc: 3244,
            ..Default::default()
        };
        let v3 = hwfoc::v3::V3Frame {
            counter: 3,
            throttle_in_raw: 51,
            pwm_out_raw: 51,
            period_us: 1500,
        };
        let hw5 = hwfoc::hw5::TelemetryFrame {
            throttle: 42,
            fault: hwfoc::hw5::FaultCode(0b1000_1000),
            voltage_raw: 504,
            ..Default::default()
        };
        let samples = [
            Data::from(frame),
            Data::DataLink(frame),
            Data::from(hwfoc::v4::Data {
                frame: v4,
                info: Some(info),
            }),
            Data::from(v3),
            Data::from(hw5),
            Data::from(hwfoc::dronecan::HwCanEsc {
                node: 7,
                throttle_channel: Some(2),
                transfer_id: 3,
                rpm: 1200,
                pwm: 300,
                status: 1 << 14,
                power: Some(hwfoc::dronecan::Power {
                    input_voltage: 252,
                    current: 11,
                    temperature: 35,
                }),
                msg2_age_ms: Some(12),
                temperatures: Some(hwfoc::dronecan::Temperatures {
                    mos: 36,
                    cap: 30,
                    motor: 41,
                }),
                msg3_age_ms: Some(80),
            }),
            Data::from(hwfoc::dronecan::DroneCanEsc {
                node: 9,
                transfer_id: 3,
                esc_index: 1,
                error_count: 0,
                voltage_f16: hwfoc::dronecan::f16_from_f32(24.5),
                current_f16: hwfoc::dronecan::f16_from_f32(3.0),
                temperature_f16: hwfoc::dronecan::f16_from_f32(300.0),
                rpm: 900,
                power_rating_pct: 10,
                extended: Some(hwfoc::dronecan::Extended {
                    input_pct: 20,
                    output_pct: 19,
                    motor_temperature_deg_c: 30,
                    status_flags: 0,
                }),
                ext_age_ms: Some(5),
            }),
        ];
        let s = Settings::default();
        for sample in samples {
            let protocol = match sample {
                Data::HwFoc(_) => Protocol::HwFoc,
                Data::DataLink(_) => Protocol::DataLink,
                Data::HwV4(_) => Protocol::HwV4,
                Data::HwV3(_) => Protocol::HwV3,
                Data::Hw5(_) => Protocol::Hw5,
                Data::HwCan(_) => Protocol::HwCan,
                Data::DroneCan(_) => Protocol::DroneCan,
            };
            assert_eq!(sample.protocol(), protocol);
            let mut json = Vec::new();
            Record::new(None, 0, &sample, &s).write_json(&mut json);
            let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
            assert_eq!(v["protocol"], protocol.name());
            for q in Quantity::ALL {
                // Each sample has a value for every quantity its protocol carries.
                let carried = protocol.carries(q);
                assert_eq!(sample.reading(q, &s).is_some(), carried, "{sample:?} {q:?}");
                assert_eq!(!v[q.name()].is_null(), carried, "{sample:?} {q:?}");
            }
            // HW-FOC and DataLink carry every quantity of schema version 1, and none of the
            // four added in version 2.
            let added = [
                Quantity::MotorTemp,
                Quantity::BecTemp,
                Quantity::BecVoltage,
                Quantity::BecCurrent,
            ];
            if matches!(protocol, Protocol::HwFoc | Protocol::DataLink) {
                for q in Quantity::ALL {
                    assert_eq!(sample.reading(q, &s).is_none(), added.contains(&q), "{q:?}");
                }
            }
            match protocol {
                Protocol::Hw5 => {
                    assert!(v["packet"].is_null());
                    assert_eq!(v["status"], 0x88);
                    assert_eq!(
                        v["faults"],
                        serde_json::json!(["throttle_signal_lost", "motor_connection_error"])
                    );
                }
                Protocol::HwV4 | Protocol::HwV3 => {
                    assert_eq!(v["packet"], 3);
                    assert!(v["status"].is_null() && v["faults"].is_null());
                }
                Protocol::HwCan => {
                    // The raw word kept (bit 14: counter-clockwise), no fault names.
                    assert!(v["packet"].is_null() && v["faults"].is_null());
                    assert_eq!(v["status"], 0x4000);
                    assert_eq!(
                        (&v["node"], &v["esc"]),
                        (&serde_json::json!(7), &serde_json::json!(0))
                    );
                    assert_eq!(
                        (&v["msg2_age_ms"], &v["msg3_age_ms"]),
                        (&serde_json::json!(12), &serde_json::json!(80))
                    );
                    assert_eq!(v["throttle_out_pct"], 30.0);
                    assert_eq!(v["rpm"], 1200.0);
                }
                Protocol::DroneCan => {
                    assert!(v["packet"].is_null() && v["status"].is_null());
                    assert_eq!(v["msg2_age_ms"], 5);
                    assert!(v["msg3_age_ms"].is_null());
                    assert_eq!(v["voltage_v"], 24.5);
                }
                Protocol::HwFoc | Protocol::DataLink => {
                    assert_eq!(v["packet"], 3);
                    assert_eq!(v["status"], 0);
                    assert_eq!(v["faults"], serde_json::json!([]));
                }
            }
        }
        // Where a format has no value: a V4 temperature of 0, a V4 current before an info
        // frame, a V3 start-up placeholder.
        let idle = Data::from(hwfoc::v4::Data {
            frame: hwfoc::v4::DataFrame { temp2_adc: 0, ..v4 },
            info: None,
        });
        let mut json = Vec::new();
        Record::new(None, 0, &idle, &s).write_json(&mut json);
        let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
        assert!(v["cap_temp_c"].is_null() && v["current_a"].is_null());
        assert_eq!(
            v["voltage_v"].as_f64().map(|x| (x * 100.0).round()),
            Some(1200.0)
        );
        let placeholder = Data::from(hwfoc::v3::V3Frame {
            period_us: hwfoc::v3::PLACEHOLDER_PERIOD_US,
            ..v3
        });
        let mut json = Vec::new();
        Record::new(None, 0, &placeholder, &s).write_json(&mut json);
        let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
        assert!(v["erpm"].is_null() && v["rpm"].is_null());
        assert!(v["throttle_in_pct"].is_number());
    }
}
