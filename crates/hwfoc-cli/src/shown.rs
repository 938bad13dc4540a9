//! The quantities the plot and the monitor show: one list, from which the plot's panels and
//! lines, the dashboard's charts and its history of each ESC are made.
//!
//! The list is the codec's quantities ([`hwfoc::Quantity::ALL`], which give the names and
//! units) but the electrical RPM (the plot and the monitor show the motor's), then the one no
//! frame carries: the input power. What a
//! quantity measures ([`Measure`]: one plot panel, one dashboard chart) follows from its unit,
//! so that a quantity the codec gains is listed, and drawn beside those of its unit, with one
//! edit here: its value in a record ([`Shown::of`], a `match` the compiler points at). Its
//! legend is its column name until [`Shown::legend`] gives it a word; a unit no measure has
//! fails this module's test.

use hwfoc::Quantity;
use hwfoc_io::energy;
use hwfoc_io::record::Record;

/// What a group of quantities measures: one plot panel, one dashboard chart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measure {
    /// Throttles, %.
    Throttle,
    /// Motor (or output shaft) speed.
    Speed,
    /// Currents, A.
    Current,
    /// Power, W.
    Power,
    /// Voltages, V.
    Voltage,
    /// Temperatures, degC.
    Temperature,
}

impl Measure {
    /// Every measure, in the order of the plot's panels.
    pub const ALL: [Measure; 6] = [
        Measure::Throttle,
        Measure::Speed,
        Measure::Current,
        Measure::Power,
        Measure::Voltage,
        Measure::Temperature,
    ];

    /// Its caption: `Throttle`, `Speed`, ...
    pub fn title(self) -> &'static str {
        match self {
            Measure::Throttle => "Throttle",
            Measure::Speed => "Speed",
            Measure::Current => "Current",
            Measure::Power => "Power",
            Measure::Voltage => "Voltage",
            Measure::Temperature => "Temperature",
        }
    }

    /// The unit as shown to people: `%`, `rpm`, `A`, `W`, `V`, `°C`.
    pub fn unit(self) -> &'static str {
        match self {
            Measure::Throttle => "%",
            Measure::Speed => "rpm",
            Measure::Current => "A",
            Measure::Power => "W",
            Measure::Voltage => "V",
            Measure::Temperature => "°C",
        }
    }

    /// What a codec quantity of unit `unit` ([`Quantity::unit`]) measures.
    fn of_unit(unit: &str) -> Option<Measure> {
        match unit {
            "%" => Some(Measure::Throttle),
            "rev/min" => Some(Measure::Speed),
            "A" => Some(Measure::Current),
            "W" => Some(Measure::Power),
            "V" => Some(Measure::Voltage),
            "degC" | "°C" => Some(Measure::Temperature),
            _ => None,
        }
    }

    /// The quantities shown of this measure, in list order.
    pub fn shown(self) -> impl Iterator<Item = Shown> {
        Shown::ALL
            .into_iter()
            .filter(move |s| s.measure() == Some(self))
    }
}

/// A quantity the plot and the monitor show.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shown {
    /// One a frame carries: name and unit are the codec's.
    Carried(Quantity),
    /// Electrical input power, W: voltage times input current.
    Power,
}

/// The codec's quantities not charted: the electrical RPM (the motor's is). Which of the rest
/// an ESC has follows from its format ([`Shown::carried_by`]): the plot and the dashboard draw
/// those only (HW5's motor and BEC readings for an HW5 ESC).
const HIDDEN: [Quantity; 1] = [Quantity::Erpm];

/// How many quantities are shown.
pub const COUNT: usize = Quantity::ALL.len() - HIDDEN.len() + 1;

/// Whether the codec's quantity `q` is shown.
const fn is_shown(q: Quantity) -> bool {
    let mut i = 0;
    while i < HIDDEN.len() {
        if HIDDEN[i] as u8 == q as u8 {
            return false;
        }
        i += 1;
    }
    true
}

impl Shown {
    /// Every quantity shown: the codec's in their order, then power. A
    /// quantity's place in this list is its index in [`Values`].
    pub const ALL: [Shown; COUNT] = {
        let mut all = [Shown::Power; COUNT];
        let (mut i, mut n) = (0, 0);
        while i < Quantity::ALL.len() {
            if is_shown(Quantity::ALL[i]) {
                all[n] = Shown::Carried(Quantity::ALL[i]);
                n += 1;
            }
            i += 1;
        }
        all[n] = Shown::Power;
        all
    };

    /// Its place in [`Shown::ALL`] (and in [`Values`]).
    pub fn index(self) -> usize {
        Shown::ALL
            .iter()
            .position(|&s| s == self)
            .expect("every quantity shown is in the list")
    }

    /// What it measures (which panel or chart it is drawn in); `None` for a codec quantity
    /// of a unit no measure has (a test checks that there is none).
    pub fn measure(self) -> Option<Measure> {
        match self {
            Shown::Carried(q) => Measure::of_unit(q.unit()),
            Shown::Power => Some(Measure::Power),
        }
    }

    /// Its legend among the quantities of its measure: `input`, `output`, `phase`, `MOSFET`.
    pub fn legend(self) -> &'static str {
        match self {
            Shown::Carried(Quantity::ThrottleIn | Quantity::Voltage | Quantity::Current) => "input",
            Shown::Carried(Quantity::ThrottleOut) => "output",
            Shown::Carried(Quantity::PhaseCurrent) => "phase",
            Shown::Carried(Quantity::MosTemp) => "MOSFET",
            Shown::Carried(Quantity::CapTemp) => "capacitor",
            Shown::Carried(Quantity::MotorTemp) => "motor",
            Shown::Carried(Quantity::BecTemp | Quantity::BecVoltage | Quantity::BecCurrent) => {
                "BEC"
            }
            Shown::Carried(q) => q.name(),
            Shown::Power => "input",
        }
    }

    /// Its legend where room is short (the dashboard): `MOS`, `CAP`, else [`Shown::legend`].
    pub fn short(self) -> &'static str {
        match self {
            Shown::Carried(Quantity::MosTemp) => "MOS",
            Shown::Carried(Quantity::CapTemp) => "CAP",
            other => other.legend(),
        }
    }

    /// Whether a frame of `protocol` carries it (power: where voltage and current are both
    /// carried).
    pub fn carried_by(self, protocol: hwfoc::Protocol) -> bool {
        match self {
            Shown::Carried(q) => protocol.carries(q),
            Shown::Power => {
                protocol.carries(Quantity::Voltage) && protocol.carries(Quantity::Current)
            }
        }
    }

    /// Its value in a record; NaN where the record has none (a quantity the ESC's protocol
    /// does not carry, a temperature out of the table's range).
    #[inline]
    pub fn of(self, r: &Record) -> f32 {
        let value = match self {
            Shown::Carried(q) => match q {
                Quantity::ThrottleIn => r.throttle_in_pct,
                Quantity::ThrottleOut => r.throttle_out_pct,
                Quantity::Erpm => r.erpm.map(|e| e as f32),
                Quantity::Rpm => r.rpm,
                Quantity::Voltage => r.voltage_v,
                Quantity::Current => r.current_a,
                Quantity::PhaseCurrent => r.phase_current_a,
                Quantity::MosTemp => r.mos_temp_c,
                Quantity::CapTemp => r.cap_temp_c,
                Quantity::MotorTemp => r.motor_temp_c,
                Quantity::BecTemp => r.bec_temp_c,
                Quantity::BecVoltage => r.bec_voltage_v,
                Quantity::BecCurrent => r.bec_current_a,
            },
            Shown::Power => r
                .voltage_v
                .zip(r.current_a)
                .map(|(v, a)| energy::power_w(f64::from(v), f64::from(a)) as f32),
        };
        value.unwrap_or(f32::NAN)
    }
}

/// The values of one record, by [`Shown::index`] (NaN: no value).
pub type Values = [f32; COUNT];

/// The values of a record.
#[inline]
pub fn values(r: &Record) -> Values {
    Shown::ALL.map(|s| s.of(r))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_list_and_what_each_measures() {
        use Quantity::*;
        assert_eq!(
            Shown::ALL,
            [
                Shown::Carried(ThrottleIn),
                Shown::Carried(ThrottleOut),
                Shown::Carried(Rpm),
                Shown::Carried(Voltage),
                Shown::Carried(Current),
                Shown::Carried(PhaseCurrent),
                Shown::Carried(MosTemp),
                Shown::Carried(CapTemp),
                Shown::Carried(MotorTemp),
                Shown::Carried(BecTemp),
                Shown::Carried(BecVoltage),
                Shown::Carried(BecCurrent),
                Shown::Power,
            ]
        );
        let of = |m: Measure| -> Vec<&str> { m.shown().map(Shown::legend).collect() };
        assert_eq!(of(Measure::Throttle), ["input", "output"]);
        assert_eq!(of(Measure::Speed), ["rpm"]);
        assert_eq!(of(Measure::Current), ["input", "phase", "BEC"]);
        assert_eq!(of(Measure::Power), ["input"]);
        assert_eq!(of(Measure::Voltage), ["input", "BEC"]);
        assert_eq!(
            of(Measure::Temperature),
            ["MOSFET", "capacitor", "motor", "BEC"]
        );
        for (i, s) in Shown::ALL.iter().enumerate() {
            assert_eq!(s.index(), i);
            assert!(s.measure().is_some(), "{s:?} is in no panel");
        }
        // Per format: V3 has throttles and RPM only; HW5 no phase current, capacitor or
        // output throttle; every extra is HW5's.
        let of = |p: hwfoc::Protocol| -> Vec<Shown> {
            Shown::ALL.into_iter().filter(|s| s.carried_by(p)).collect()
        };
        assert_eq!(
            of(hwfoc::Protocol::HwV3),
            [
                Shown::Carried(ThrottleIn),
                Shown::Carried(ThrottleOut),
                Shown::Carried(Rpm)
            ]
        );
        assert!(!of(hwfoc::Protocol::Hw5).contains(&Shown::Carried(PhaseCurrent)));
        assert!(of(hwfoc::Protocol::Hw5).contains(&Shown::Power));
        let extras = [MotorTemp, BecTemp, BecVoltage, BecCurrent].map(Shown::Carried);
        let hwfoc: Vec<Shown> = Shown::ALL
            .into_iter()
            .filter(|s| !extras.contains(s))
            .collect();
        assert_eq!(of(hwfoc::Protocol::HwFoc), hwfoc);
        for s in extras {
            assert!(s.carried_by(hwfoc::Protocol::Hw5), "{s:?}");
            assert!(!s.carried_by(hwfoc::Protocol::HwFoc), "{s:?}");
        }
    }
}
