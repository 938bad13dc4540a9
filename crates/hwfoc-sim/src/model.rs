//! The physical model behind a virtual ESC: motor and propeller, battery, power stage heating.
//!
//! - The ESC arms when it first sees zero throttle (until then it reports `throttle_not_zeroed`
//!   and keeps the motor stopped, as a real one does). Output throttle follows the input at a
//!   limited rate on the way up.
//! - RPM follows `kv * bus voltage * output throttle * 0.85` (the propeller's load) with a
//!   first-order lag (0.2 s up, 0.15 s down; FOC brakes actively).
//! - Mechanical power is the propeller's load, `k * rpm^3`, plus the rotor's change of kinetic
//!   energy, `J * rpm * d(rpm)/dt`: when the throttle drops fast the second term wins, power flows
//!   back to the battery and the input current goes negative (regenerative braking). `k` is set
//!   so that full throttle on a full battery draws `full_current_a`; `J` so that a chop from
//!   full throttle regenerates about a fifth of that.
//! - The battery is an open-circuit voltage falling with the charge drawn, an internal
//!   resistance (instant sag) and a polarisation element (half as much again, 4 s time constant:
//!   the voltage keeps sagging under a long load and recovers slowly after it).
//! - The MOSFETs heat with conduction (`I_phase^2`) and switching losses and cool to ambient
//!   (first order, 20 s); the capacitors heat with ripple (`I_in^2`) and from the MOSFETs (45 s).
//!   Above 110 degC the ESC raises `mos_overheat` and limits output to 50 % until below 100 degC;
//!   `cap_overheat` at 100/90 degC; `input_voltage_low` below 3.3 V per cell (clears above
//!   3.45 V), `input_voltage_high` above 4.35 V per cell (clears below 4.3 V).
//!
//! Each ESC gets slightly different parameters (a few percent on KV, load, battery resistance,
//! cooling; its own sensor offsets), drawn from its own random stream.

use hwfoc::foc::DataFrame;
use hwfoc::units::ADC_TABLE;
use hwfoc::{Fault, Status};

use crate::degrade::ModelDegradations;
use crate::rng::Rng;

/// Loaded RPM at full throttle as a fraction of `kv * volts` (the propeller's load).
const LOADED: f64 = 0.85;
/// RPM time constants, seconds.
const TAU_UP_S: f64 = 0.20;
const TAU_DOWN_S: f64 = 0.15;
/// Output throttle slew limit on the way up, percent per second.
const SLEW_PCT_S: f64 = 250.0;
/// Efficiency motoring and regenerating.
const ETA: f64 = 0.88;
const ETA_REGEN: f64 = 0.75;
/// Rotor energy released by a chop from full throttle, relative to full power (see module doc).
const BRAKE: f64 = 1.25;
/// Current drawn by the ESC and the motor's iron losses while spinning, A.
const SPIN_A: f64 = 0.3;
/// Below this RPM with zero output the motor is stopped.
const STOP_RPM: f64 = 20.0;
/// Open-circuit cell voltage: `CELL_EMPTY_V + CELL_SPAN_V * state of charge`.
const CELL_EMPTY_V: f64 = 3.5;
const CELL_SPAN_V: f64 = 0.7;
/// Nominal cell voltage under load, for calibrating the propeller load.
const CELL_NOMINAL_V: f64 = 3.95;
/// Polarisation resistance relative to the internal resistance, and its time constant.
const POLARISATION: f64 = 0.5;
const TAU_POLARISATION_S: f64 = 4.0;
/// MOSFET on-resistance (ohm), switching loss per watt switched, quiescent loss (W),
/// thermal resistance to ambient (K/W) and time constant (s).
const R_ON: f64 = 0.002;
const K_SWITCH: f64 = 0.0028;
const P_QUIESCENT_W: f64 = 0.15;
const R_TH_MOS: f64 = 3.0;
const TAU_MOS_S: f64 = 20.0;
/// Capacitor ripple loss per A^2 of input current, thermal resistance, share of the MOSFETs'
/// temperature rise it takes, time constant.
const K_CAP: f64 = 0.0008;
const R_TH_CAP: f64 = 4.0;
const CAP_COUPLING: f64 = 0.5;
const TAU_CAP_S: f64 = 45.0;
/// Protection thresholds (set, clear).
const MOS_OVERHEAT_C: (f64, f64) = (110.0, 100.0);
const CAP_OVERHEAT_C: (f64, f64) = (100.0, 90.0);
const CELL_LOW_V: (f64, f64) = (3.3, 3.45);
const CELL_HIGH_V: (f64, f64) = (4.35, 4.3);
/// Output limit while the MOSFETs are overheated, percent.
const DERATED_PCT: f64 = 50.0;

/// The user's settings for the motor, battery and ESC.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelConfig {
    /// Motor KV, RPM per volt.
    pub kv: f64,
    /// Motor pole pairs (for eRPM).
    pub pole_pairs: u16,
    /// Input current at full throttle on a full battery, A (sets the propeller's load).
    pub full_current_a: f64,
    /// Battery cells in series (LiPo).
    pub cells: u8,
    /// Battery internal resistance, ohm.
    pub battery_r_ohm: f64,
    /// Battery capacity, mAh.
    pub capacity_mah: f64,
    /// Ambient temperature, degC.
    pub ambient_c: f64,
    /// Raw current units per ampere the ESC sends.
    pub current_scale: f32,
}

impl ModelConfig {
    /// The model of `hwfoc simulate`'s defaults: 500 KV, 7 pole pairs, 60 A at full throttle,
    /// 6 cells of 5000 mAh at 0.02 ohm, 25 degC, 64 raw units per ampere (for tests and
    /// examples that want a typical model).
    pub const SIMULATE: ModelConfig = ModelConfig {
        kv: 500.0,
        pole_pairs: 7,
        full_current_a: 60.0,
        cells: 6,
        battery_r_ohm: 0.02,
        capacity_mah: 5000.0,
        ambient_c: 25.0,
        current_scale: 64.0,
    };
}

/// One ESC's parameters: the configuration with this unit's tolerances applied.
#[derive(Debug, Clone, Copy)]
struct Params {
    kv: f64,
    pole_pairs: u16,
    full_current_a: f64,
    cells: f64,
    r0: f64,
    r1: f64,
    capacity_ah: f64,
    ambient_c: f64,
    current_scale: f64,
    /// Propeller load: watts per rpm^3.
    prop_k: f64,
    /// Rotor inertia: watts per (rpm * rpm/s).
    inertia: f64,
    r_th_mos: f64,
    /// Gain on the throttle command (flight controllers drive motors differently).
    throttle_gain: f64,
    /// Current sensor offsets, raw units (a real idle ESC sends FF FF: -1).
    current_offset: i16,
    phase_offset: i16,
}

/// The state of one ESC, its motor and its battery.
#[derive(Debug, Clone)]
pub struct Model {
    p: Params,
    armed: bool,
    /// Input throttle as the ESC sees it, percent.
    throttle_in: f64,
    /// Output throttle, percent.
    throttle_out: f64,
    rpm: f64,
    i_in: f64,
    i_phase: f64,
    soc: f64,
    v_polarisation: f64,
    v_bus: f64,
    t_mos: f64,
    t_cap: f64,
    faults: Status,
    /// Degradations acting on the motor, propeller, battery or power stage.
    degradations: ModelDegradations,
}

impl Model {
    /// The model of ESC `index` of a run with `seed`: `config` with its full current scaled by
    /// `load`, its tolerances drawn from the ESC's parameter stream, which is returned for the
    /// ESC's other parameters (what every kind of virtual ESC starts from).
    pub fn for_esc(config: ModelConfig, load: f64, seed: u64, index: usize) -> (Model, Rng) {
        let mut params = Rng::for_esc(seed, index, crate::rng::Purpose::Params);
        let mut config = config;
        config.full_current_a *= load;
        (Model::new(&config, &mut params), params)
    }

    /// A model at rest (disarmed, motor stopped, at ambient temperature), with this ESC's
    /// tolerances drawn from `rng`.
    pub fn new(config: &ModelConfig, rng: &mut Rng) -> Model {
        let vary = |rng: &mut Rng, spread: f64| 1.0 + spread * rng.signed();
        let kv = config.kv * vary(rng, 0.02);
        let full_current_a = config.full_current_a * vary(rng, 0.03);
        let r = config.battery_r_ohm * vary(rng, 0.1);
        let cells = f64::from(config.cells);
        let ambient_c = config.ambient_c + 0.8 * rng.signed();
        let soc = 0.95 + 0.02 * rng.signed();
        let v_nominal = cells * CELL_NOMINAL_V;
        let rpm_full = kv * v_nominal * LOADED;
        let p_full = full_current_a * v_nominal * ETA;
        let p = Params {
            kv,
            pole_pairs: config.pole_pairs,
            full_current_a,
            cells,
            r0: r,
            r1: r * POLARISATION,
            capacity_ah: config.capacity_mah / 1000.0,
            ambient_c,
            current_scale: f64::from(config.current_scale),
            prop_k: p_full / rpm_full.powi(3),
            inertia: BRAKE * p_full * TAU_DOWN_S / (rpm_full * rpm_full),
            r_th_mos: R_TH_MOS * vary(rng, 0.05),
            throttle_gain: vary(rng, 0.02),
            current_offset: -(rng.below(2) as i16),
            phase_offset: -(rng.below(2) as i16),
        };
        let v_bus = cells * (CELL_EMPTY_V + CELL_SPAN_V * soc);
        Model {
            p,
            armed: false,
            throttle_in: 0.0,
            throttle_out: 0.0,
            rpm: 0.0,
            i_in: 0.0,
            i_phase: 0.0,
            soc,
            v_polarisation: 0.0,
            v_bus,
            t_mos: ambient_c + 1.5 * rng.unit(),
            t_cap: ambient_c + 1.0 * rng.unit(),
            faults: Status::OK,
            degradations: ModelDegradations::default(),
        }
    }

    /// The model with `degradations` acting on it from their start times on.
    pub fn degraded(self, degradations: ModelDegradations) -> Model {
        Model {
            degradations,
            ..self
        }
    }

    /// Advances by `dt` seconds (a few milliseconds) with throttle command `command_pct`;
    /// `signal_lost` makes the ESC see no throttle at all.
    pub fn step(&mut self, dt: f64, command_pct: f64, signal_lost: bool) {
        let p = self.p;
        self.throttle_in = if signal_lost {
            0.0
        } else {
            (command_pct * p.throttle_gain).clamp(0.0, 100.0)
        };
        if !self.armed && self.throttle_in == 0.0 {
            self.armed = true;
        }
        let limit = if self.faults.contains(Fault::MosOverheat) {
            DERATED_PCT
        } else {
            100.0
        };
        let target_out = if self.armed {
            self.throttle_in.min(limit)
        } else {
            0.0
        };
        self.throttle_out = if target_out > self.throttle_out {
            target_out.min(self.throttle_out + SLEW_PCT_S * dt)
        } else {
            target_out
        };

        // Motor and propeller.
        let d = &mut self.degradations;
        d.advance(dt, self.rpm);
        let rpm_target = p.kv * self.v_bus * LOADED * self.throttle_out / 100.0 * d.rpm_factor();
        let tau = if rpm_target > self.rpm {
            TAU_UP_S
        } else {
            TAU_DOWN_S
        };
        let mut rpm = rpm_target + (self.rpm - rpm_target) * (-dt / tau).exp();
        if self.throttle_out == 0.0 && rpm < STOP_RPM {
            rpm = 0.0;
        }
        let rpm_dot = (rpm - self.rpm) / dt;
        let rpm_mid = (rpm + self.rpm) / 2.0;
        self.rpm = rpm;
        let spinning = self.spinning();
        let p_mech = p.prop_k * rpm_mid.powi(3) + p.inertia * rpm_mid * rpm_dot;
        let p_in = if p_mech >= 0.0 {
            p_mech / ETA
        } else {
            p_mech * ETA_REGEN
        };
        self.i_in = if spinning {
            let i = p_in / self.v_bus + SPIN_A;
            let i = if i > 0.0 {
                i * self.degradations.current_factor()
            } else {
                i
            };
            i.max(-0.5 * p.full_current_a)
        } else {
            0.0
        };
        let duty = (rpm / (p.kv * self.v_bus)).clamp(0.1, 1.0);
        self.i_phase = if spinning {
            (self.i_in / duty).clamp(-3.0 * p.full_current_a, 3.0 * p.full_current_a)
        } else {
            0.0
        };

        // Battery.
        self.soc = (self.soc - self.i_in * dt / 3600.0 / p.capacity_ah).clamp(0.0, 1.0);
        let weak = self.degradations.resistance_factor();
        self.v_polarisation += (self.i_in * p.r1 * weak - self.v_polarisation)
            * (1.0 - (-dt / TAU_POLARISATION_S).exp());
        let v_open = p.cells * (CELL_EMPTY_V + CELL_SPAN_V * self.soc);
        self.v_bus = (v_open - self.i_in * p.r0 * weak - self.v_polarisation).max(0.5);

        // Power stage temperatures.
        let p_mos = self.i_phase * self.i_phase * R_ON
            + K_SWITCH * self.i_in.abs() * self.v_bus
            + P_QUIESCENT_W;
        let mos_eq = p.ambient_c + p_mos * p.r_th_mos + self.degradations.extra_heat_k();
        self.t_mos += (mos_eq - self.t_mos) * (1.0 - (-dt / TAU_MOS_S).exp());
        let cap_eq = p.ambient_c
            + CAP_COUPLING * (self.t_mos - p.ambient_c)
            + K_CAP * self.i_in * self.i_in * R_TH_CAP;
        self.t_cap += (cap_eq - self.t_cap) * (1.0 - (-dt / TAU_CAP_S).exp());

        // Protections, with hysteresis.
        let per_cell = self.v_bus / p.cells;
        self.latch(
            Fault::MosOverheat,
            self.t_mos > MOS_OVERHEAT_C.0,
            self.t_mos < MOS_OVERHEAT_C.1,
        );
        self.latch(
            Fault::CapOverheat,
            self.t_cap > CAP_OVERHEAT_C.0,
            self.t_cap < CAP_OVERHEAT_C.1,
        );
        self.latch(
            Fault::InputVoltageLow,
            per_cell < CELL_LOW_V.0,
            per_cell > CELL_LOW_V.1,
        );
        self.latch(
            Fault::InputVoltageHigh,
            per_cell > CELL_HIGH_V.0,
            per_cell < CELL_HIGH_V.1,
        );
    }

    fn latch(&mut self, fault: Fault, set: bool, clear: bool) {
        if set {
            self.faults = self.faults.with(fault);
        } else if clear {
            self.faults = Status(self.faults.0 & !fault.mask());
        }
    }

    /// Whether the motor is running: the ESC then sends a frame every 50 ms, else every 364 ms.
    pub fn spinning(&self) -> bool {
        self.throttle_out > 0.0 || self.rpm > 0.0
    }

    /// Status bits the ESC raises itself.
    pub fn status(&self) -> Status {
        if !self.armed && self.throttle_in > 0.0 {
            self.faults.with(Fault::ThrottleNotZeroed)
        } else {
            self.faults
        }
    }

    /// The data frame the ESC sends now: measured values (with a little sensor noise from
    /// `noise`) in the wire's raw units, the model's status bits plus `injected`.
    pub fn frame(&self, packet: u16, injected: Status, noise: &mut Rng) -> DataFrame {
        let p = &self.p;
        let raw_throttle = |pct: f64| (pct * 1024.0 / 100.0).round() as u16;
        let spinning = self.spinning();
        let erpm = if self.rpm > 0.0 {
            self.rpm * (1.0 + noise.noise(0.002)) * f64::from(p.pole_pairs)
        } else {
            0.0
        };
        let amps = |a: f64, offset: i16, noise: &mut Rng| {
            let raw = if spinning {
                (a + noise.noise(0.05) + a.abs() * noise.noise(0.01)) * p.current_scale
            } else {
                0.0
            };
            (raw.round() + f64::from(offset)).clamp(-32768.0, 32767.0) as i16
        };
        let current_raw = amps(self.i_in, p.current_offset, noise);
        let phase_current_raw = amps(self.i_phase, p.phase_offset, noise);
        DataFrame {
            packet,
            throttle_in_raw: raw_throttle(self.throttle_in),
            throttle_out_raw: raw_throttle(self.throttle_out),
            erpm_raw: (erpm / 10.0).round().clamp(0.0, 65535.0) as u16,
            voltage_raw: ((self.v_bus + noise.noise(0.03)) * 10.0)
                .round()
                .clamp(0.0, 65535.0) as u16,
            current_raw,
            phase_current_raw,
            mos_adc: adc_code(
                overheated(self.t_mos, injected, Fault::MosOverheat, MOS_OVERHEAT_C)
                    + noise.noise(0.15),
            ),
            cap_adc: adc_code(
                overheated(self.t_cap, injected, Fault::CapOverheat, CAP_OVERHEAT_C)
                    + noise.noise(0.15),
            ),
            status: Status(self.status().0 | injected.0),
        }
    }
}

/// What an ESC measures at one moment, in physical units, with a little sensor noise: what the
/// frames of the protocols other than HW-FOC are made from ([`Model::measure`]; HW-FOC's frame
/// is [`Model::frame`], unchanged).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Input throttle, percent.
    pub throttle_in_pct: f64,
    /// Output throttle (PWM), percent.
    pub throttle_out_pct: f64,
    /// Electrical RPM (0 when stopped).
    pub erpm: f64,
    /// Bus voltage, V.
    pub voltage_v: f64,
    /// Input current, A (negative while braking regeneratively; 0 when stopped).
    pub current_a: f64,
    /// MOSFET temperature, degC (at least the threshold's while an overheat is injected).
    pub mos_c: f64,
    /// Capacitor temperature, degC (likewise).
    pub cap_c: f64,
    /// The ambient temperature, degC.
    pub ambient_c: f64,
    /// The model's status bits plus the injected ones.
    pub status: Status,
    /// Whether the motor turns (or is driven).
    pub spinning: bool,
}

impl Model {
    /// The measurements the ESC sends now, with `injected` status bits (see [`Measured`]).
    pub fn measure(&self, injected: Status, noise: &mut Rng) -> Measured {
        let p = &self.p;
        let spinning = self.spinning();
        let erpm = if self.rpm > 0.0 {
            self.rpm * (1.0 + noise.noise(0.002)) * f64::from(p.pole_pairs)
        } else {
            0.0
        };
        let current_a = if spinning {
            self.i_in + noise.noise(0.05) + self.i_in.abs() * noise.noise(0.01)
        } else {
            0.0
        };
        Measured {
            throttle_in_pct: self.throttle_in,
            throttle_out_pct: self.throttle_out,
            erpm,
            voltage_v: self.v_bus + noise.noise(0.03),
            current_a,
            mos_c: overheated(self.t_mos, injected, Fault::MosOverheat, MOS_OVERHEAT_C)
                + noise.noise(0.15),
            cap_c: overheated(self.t_cap, injected, Fault::CapOverheat, CAP_OVERHEAT_C)
                + noise.noise(0.15),
            ambient_c: p.ambient_c,
            status: Status(self.status().0 | injected.0),
            spinning,
        }
    }
}

/// The temperature an ESC reports with an injected overheat: an overheat bit comes with the
/// temperature that raises it, so the sensor reads at least 2 degC above the threshold (`set`)
/// while `fault` is injected; otherwise the model's `t_c`.
fn overheated(t_c: f64, injected: Status, fault: Fault, (set, _clear): (f64, f64)) -> f64 {
    if injected.contains(fault) {
        t_c.max(set + 2.0)
    } else {
        t_c
    }
}

/// Readings of the true state, for tests.
#[cfg(test)]
impl Model {
    /// Mechanical RPM.
    pub fn rpm(&self) -> f64 {
        self.rpm
    }

    /// Input current, A (negative while braking regeneratively).
    pub fn current_a(&self) -> f64 {
        self.i_in
    }

    /// Bus voltage at the ESC, V.
    pub fn voltage_v(&self) -> f64 {
        self.v_bus
    }

    /// MOSFET temperature, degC.
    pub fn mos_temp_c(&self) -> f64 {
        self.t_mos
    }

    /// Capacitor temperature, degC.
    pub fn cap_temp_c(&self) -> f64 {
        self.t_cap
    }
}

/// The ADC code a temperature reads as: the vendor table (`hwfoc::units::ADC_TABLE`) at the
/// nearest whole degree from 0 to 129 degC. Outside it the sensor keeps going as the table's
/// ends do, so the code leaves the table's range as a real ESC's would (the decoder then reports
/// the temperature as out of range): about one code per degree above 241 below 0 degC, and 0.8
/// of a code per degree below 33 above 129 degC, clamped to 0..=255.
pub fn adc_code(celsius: f64) -> u8 {
    if celsius.is_nan() {
        return ADC_TABLE[25];
    }
    let degree = celsius.round();
    if degree < 0.0 {
        (f64::from(ADC_TABLE[0]) - degree).min(255.0) as u8
    } else if degree > 129.0 {
        (f64::from(ADC_TABLE[129]) - (celsius - 129.0) * 0.8)
            .round()
            .max(0.0) as u8
    } else {
        ADC_TABLE[degree as usize]
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::rng::Purpose;
    use hwfoc::{Settings, Temperature};

    /// The command line's defaults.
    pub(crate) fn config() -> ModelConfig {
        ModelConfig::SIMULATE
    }

    fn model() -> Model {
        Model::new(&config(), &mut Rng::for_esc(1, 0, Purpose::Params))
    }

    const DT: f64 = 0.005;

    /// Runs `seconds` at `throttle`, returning the states after each step.
    fn run(m: &mut Model, seconds: f64, throttle: f64) -> Vec<Model> {
        (0..(seconds / DT).round() as usize)
            .map(|_| {
                m.step(DT, throttle, false);
                m.clone()
            })
            .collect()
    }

    #[test]
    fn rpm_follows_throttle_with_a_lag() {
        let mut m = model();
        run(&mut m, 0.5, 0.0);
        assert!(m.armed && !m.spinning());
        let states = run(&mut m, 3.0, 60.0);
        let last = states.last().unwrap().rpm();
        // Loaded RPM at 60 %: kv * V * 0.85 * 0.6, about 6300 at 24.7 V (tolerances aside).
        assert!((5900.0..6700.0).contains(&last), "{last}");
        // Not there at once: the output slews, then first order.
        let at = |s: f64| states[(s / DT) as usize - 1].rpm();
        assert!(at(0.1) < 0.25 * last, "{}", at(0.1));
        assert!(at(0.5) > 0.6 * last && at(0.5) < 0.95 * last, "{}", at(0.5));
        assert!(at(1.5) > 0.99 * last);
        // RPM never decreases while spinning up.
        assert!(states.windows(2).all(|w| w[1].rpm() >= w[0].rpm() - 1.0));
    }

    #[test]
    fn disarmed_until_throttle_seen_at_zero() {
        let mut m = model();
        run(&mut m, 1.0, 40.0);
        assert_eq!(m.rpm(), 0.0);
        assert!(m.status().contains(Fault::ThrottleNotZeroed));
        run(&mut m, 0.1, 0.0);
        assert!(m.status().is_ok());
        run(&mut m, 1.0, 40.0);
        assert!(m.rpm() > 1000.0);
    }

    #[test]
    fn voltage_sags_under_load_and_recovers() {
        let mut m = model();
        run(&mut m, 1.0, 0.0);
        let rest = m.voltage_v();
        assert!((24.5..25.6).contains(&rest), "{rest}");
        run(&mut m, 2.0, 100.0);
        let amps = m.current_a();
        assert!((50.0..75.0).contains(&amps), "{amps}");
        let loaded = m.voltage_v();
        // Instant sag I*R0 plus polarisation building up.
        assert!(rest - loaded > amps * 0.02 * 0.9, "{rest} -> {loaded}");
        run(&mut m, 10.0, 100.0);
        assert!(
            m.voltage_v() < loaded - 0.1,
            "keeps sagging: {}",
            m.voltage_v()
        );
        run(&mut m, 2.0, 0.0);
        let after = m.voltage_v();
        run(&mut m, 20.0, 0.0);
        assert!(
            m.voltage_v() > after + 0.1,
            "recovers: {after} -> {}",
            m.voltage_v()
        );
        // Charge was drawn: not quite back to rest.
        assert!(m.voltage_v() < rest);
    }

    #[test]
    fn regenerative_braking_gives_negative_current() {
        let mut m = model();
        run(&mut m, 0.5, 0.0);
        run(&mut m, 2.0, 100.0);
        assert!(m.current_a() > 40.0);
        let states = run(&mut m, 1.5, 0.0);
        let min = states.iter().map(Model::current_a).fold(f64::MAX, f64::min);
        assert!((-25.0..-5.0).contains(&min), "{min}");
        // The voltage rises above rest while current flows back.
        let braking = states.iter().find(|s| s.current_a() < -5.0).unwrap();
        assert!(braking.i_phase < 0.0);
        // Then the motor stops and the current is zero.
        assert_eq!(m.rpm(), 0.0);
        assert_eq!(m.current_a(), 0.0);
        // A slow ramp down never regenerates: the propeller absorbs the rotor's energy.
        let mut m = model();
        run(&mut m, 0.5, 0.0);
        run(&mut m, 2.0, 100.0);
        for k in 0..200 {
            let states = run(&mut m, 0.05, 100.0 - k as f64 * 0.5);
            assert!(states.iter().all(|s| s.current_a() > 0.0));
        }
    }

    #[test]
    fn power_stage_heats_with_current_and_cools() {
        let mut m = model();
        run(&mut m, 0.5, 0.0);
        let (mos0, cap0) = (m.mos_temp_c(), m.cap_temp_c());
        assert!((23.0..28.0).contains(&mos0));
        run(&mut m, 10.0, 40.0);
        let mos_light = m.mos_temp_c();
        let mut hot = m.clone();
        run(&mut hot, 10.0, 100.0);
        run(&mut m, 10.0, 40.0);
        assert!(hot.mos_temp_c() > m.mos_temp_c() + 5.0);
        assert!(m.mos_temp_c() > mos_light && mos_light > mos0);
        run(&mut hot, 120.0, 100.0);
        let peak = hot.mos_temp_c();
        assert!((55.0..85.0).contains(&peak), "steady at full: {peak}");
        assert!(hot.cap_temp_c() > cap0 + 10.0 && hot.cap_temp_c() < peak);
        run(&mut hot, 60.0, 0.0);
        assert!(
            hot.mos_temp_c() < peak - 20.0,
            "cools: {}",
            hot.mos_temp_c()
        );
        assert!(!hot.status().contains(Fault::MosOverheat));
    }

    #[test]
    fn overheat_is_raised_and_derates() {
        let mut m = Model::new(
            &ModelConfig {
                ambient_c: 60.0,
                full_current_a: 110.0,
                ..config()
            },
            &mut Rng::for_esc(1, 0, Purpose::Params),
        );
        run(&mut m, 0.5, 0.0);
        let states = run(&mut m, 200.0, 100.0);
        let first = states
            .iter()
            .position(|s| s.status().contains(Fault::MosOverheat))
            .expect("overheats");
        assert!(states[first].mos_temp_c() > 110.0);
        assert!(states[first + 400].throttle_out <= DERATED_PCT);
    }

    #[test]
    fn frames_carry_the_model_in_raw_units() {
        let mut m = model();
        let mut noise = Rng::for_esc(1, 0, Purpose::Noise);
        run(&mut m, 0.5, 0.0);
        let idle = m.frame(65535, Status::OK, &mut noise);
        assert_eq!(idle.packet, 65535);
        assert_eq!((idle.throttle_in_raw, idle.erpm_raw), (0, 0));
        // At rest only the sensor offset: 0 or -1 raw, like a real idle ESC's FF FF.
        assert!((-1..=0).contains(&idle.current_raw));
        run(&mut m, 3.0, 50.0);
        let f = m.frame(1, Status::OK.with(Fault::OverCurrent), &mut noise);
        let s = Settings::default();
        assert_eq!(
            f.throttle_in_raw,
            (50.0 * m.p.throttle_gain * 10.24).round() as u16
        );
        assert!((f64::from(f.rpm(&s)) - m.rpm()).abs() < m.rpm() * 0.005 + 2.0);
        assert!((f64::from(f.voltage_v()) - m.voltage_v()).abs() < 0.1);
        assert!((f64::from(f.current_a(&s)) - m.current_a()).abs() < 0.3);
        assert!(f.phase_current_a(&s) > f.current_a(&s));
        let mos = f.mos_temp().celsius().unwrap();
        assert!((f64::from(mos) - m.mos_temp_c()).abs() <= 1.0);
        assert!(f.status.contains(Fault::OverCurrent));
    }

    #[test]
    fn an_injected_overheat_comes_with_its_temperature() {
        let mut m = model();
        let mut noise = Rng::for_esc(1, 0, Purpose::Noise);
        run(&mut m, 0.5, 0.0);
        let temps = |f: DataFrame| {
            (
                f.mos_temp().celsius().unwrap(),
                f.cap_temp().celsius().unwrap(),
            )
        };
        let (mos, cap) = temps(m.frame(1, Status::OK, &mut noise));
        assert!(mos < 30.0 && cap < 30.0, "{mos} {cap}");
        let f = m.frame(2, Status::OK.with(Fault::MosOverheat), &mut noise);
        let (mos, cap) = temps(f);
        assert!(mos > MOS_OVERHEAT_C.0 as f32 && cap < 30.0, "{mos} {cap}");
        assert!(f.status.contains(Fault::MosOverheat));
        let (mos, cap) = temps(m.frame(3, Status::OK.with(Fault::CapOverheat), &mut noise));
        assert!(cap > CAP_OVERHEAT_C.0 as f32 && mos < 30.0, "{mos} {cap}");
    }

    #[test]
    fn adc_encoding() {
        assert_eq!(adc_code(28.0), 206);
        assert_eq!(adc_code(28.4), 206);
        assert_eq!(adc_code(0.0), 241);
        assert_eq!(adc_code(-0.4), 241);
        assert_eq!(adc_code(129.0), 33);
        for t in 0..=129 {
            let code = adc_code(f64::from(t));
            let back = Temperature::from_adc(code).celsius().unwrap();
            // Codes repeat in the table: the decoder gives the middle of a run.
            assert!((back - t as f32).abs() <= 1.0, "{t} -> {code} -> {back}");
        }
        assert_eq!(
            Temperature::from_adc(adc_code(-3.0)),
            Temperature::BelowRange
        );
        assert_eq!(adc_code(-100.0), 255);
        assert_eq!(
            Temperature::from_adc(adc_code(131.0)),
            Temperature::AboveRange
        );
        assert_eq!(adc_code(500.0), 0);
        // Monotonic: hotter never reads as a higher code.
        let mut last = 255;
        for tenth in -200..2000 {
            let code = adc_code(f64::from(tenth) / 10.0);
            assert!(code <= last);
            last = code;
        }
    }
}
