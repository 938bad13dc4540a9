//! What the analysers read: one ESC's samples ([`EscSeries`]), in physical units, with its link
//! figures.

use hwfoc::{Protocol, Status};
use serde::{Deserialize, Serialize};

use super::EscId;
use crate::LinkStats;
use crate::record::Record;

/// One data frame of an ESC, as the analysers read it (a record's columns they use).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Sample {
    /// Receive time, s; for an input without times, the frame's index times the protocol's
    /// nominal frame period (see [`EscSeries::timed`]).
    pub t: f64,
    /// Its packet number, where its protocol sends one.
    pub packet: Option<u32>,
    /// Throttle in, %.
    pub throttle_pct: Option<f32>,
    /// Mechanical rpm.
    pub rpm: Option<f32>,
    /// Battery voltage, V.
    pub voltage_v: Option<f32>,
    /// Battery current, A.
    pub current_a: Option<f32>,
    /// MOSFET temperature, °C.
    pub mos_temp_c: Option<f32>,
    /// Capacitor temperature, °C.
    pub cap_temp_c: Option<f32>,
    /// Motor temperature, °C.
    pub motor_temp_c: Option<f32>,
    /// Its fault word, where its protocol has fault bits.
    pub status: Option<Status>,
}

impl Sample {
    /// The sample of `record`, the `index`th data frame of its ESC.
    pub fn of(record: &Record, index: usize) -> Sample {
        let t = record
            .t_s
            .unwrap_or_else(|| index as f64 * super::period_s(record.protocol));
        Sample {
            t,
            packet: record.packet,
            throttle_pct: record.throttle_in_pct,
            rpm: record.rpm,
            voltage_v: record.voltage_v,
            current_a: record.current_a,
            mos_temp_c: record.mos_temp_c,
            cap_temp_c: record.cap_temp_c,
            motor_temp_c: record.motor_temp_c,
            status: record.fault_word(),
        }
    }
}

/// The link figures the link analyser judges (the summary's).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct LinkTotals {
    /// Data and information frames decoded.
    pub frames: u64,
    /// Whether its protocol numbers its packets (else no loss is counted).
    pub counts_packets: bool,
    /// Packets lost, from the packet counter.
    pub lost_packets: u64,
    /// Whether its protocol has a checksum.
    pub has_checksum: bool,
    /// Frames whose checksum failed.
    pub checksum_failures: u64,
}

impl LinkTotals {
    /// The figures of `link`.
    pub fn of(link: &LinkStats) -> LinkTotals {
        LinkTotals {
            frames: u64::from(link.frames()),
            counts_packets: link.counts_packets(),
            lost_packets: u64::from(link.lost_packets()),
            has_checksum: link.has_checksum(),
            checksum_failures: u64::from(link.checksum_failures()),
        }
    }
}

/// One ESC's samples in one recording, in time order, and what it is.
#[derive(Debug, Clone, PartialEq)]
pub struct EscSeries {
    /// Which ESC.
    pub esc: EscId,
    /// Its recording (a vehicle's flight): ESCs of one recording are siblings.
    pub recording: String,
    /// Its protocol.
    pub protocol: Protocol,
    /// Whether its times are receive times (else the nominal period times the frame index).
    pub timed: bool,
    /// Its link's figures; `None` where there are none (built from records alone).
    pub link: Option<LinkTotals>,
    /// A Hobbywing CAN ESC's own maintenance counters, minutes (total rotation time, time since
    /// maintenance), where its recording holds its answer to GetMaintenanceInformation
    /// ([`LinkStats::maintenance_min`]).
    pub maintenance_min: Option<(u32, u32)>,
    /// Its data frames.
    pub samples: Vec<Sample>,
}
