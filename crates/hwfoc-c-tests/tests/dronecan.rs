//! The header's DroneCAN payload codec (`hwfoc_can_pack`, `hwfoc_can_unpack`) against the Rust
//! codec's `dronecan` types: every payload of every fixed-layout type, random and extreme,
//! decodes and re-encodes to the same bytes; typed fields unpack to the Rust values; values
//! beyond a field's range saturate alike; a payload of another length is refused by both.

use hwfoc::dronecan::{
    DataType, EscStatus, EscStatusExtended, GetMaintenanceInformationRequest,
    GetMaintenanceInformationResponse, GetMajorConfigRequest, GetMajorConfigResponse,
    MAX_PAYLOAD_LEN, NodeStatus, SelfTestRequest, SelfTestResponse, SetAngleRequest,
    SetBaudRequest, SetBaudResponse, SetDirectionRequest, SetDirectionResponse, SetIdRequest,
    SetIdResponse, SetLedRequest, SetLedResponse, SetReportingFrequencyRequest,
    SetReportingFrequencyResponse, SetThrottleSourceRequest, SetThrottleSourceResponse, StatusMsg1,
    StatusMsg2, StatusMsg3, f16_from_f32,
};
use hwfoc_c_tests::ffi::{can_pack, can_unpack};
use hwfoc_c_tests::ops::Rng;

/// Payload `p` decoded and re-encoded by the Rust type `T`, and unpacked and re-packed by the
/// header as its type number `kind`, give the same bytes; other lengths are refused by both.
fn same_round_trip<T: DataType>(kind: i32, p: &[u8]) {
    let rust = T::decode(p).ok().map(|t| {
        let mut out = [0u8; MAX_PAYLOAD_LEN];
        let n = t.encode_into(&mut out);
        out[..n].to_vec()
    });
    let c = can_unpack(kind, p).map(|fields| can_pack(kind, &fields));
    assert_eq!(c, rust, "type {kind}, payload {p:02X?}");
}

fn every_type(p: &[u8]) {
    same_round_trip::<StatusMsg1>(0, p);
    same_round_trip::<StatusMsg2>(1, p);
    same_round_trip::<StatusMsg3>(2, p);
    same_round_trip::<NodeStatus>(3, p);
    same_round_trip::<EscStatus>(4, p);
    same_round_trip::<EscStatusExtended>(5, p);
    same_round_trip::<SetIdRequest>(6, p);
    same_round_trip::<SetIdResponse>(7, p);
    same_round_trip::<SetBaudRequest>(8, p);
    same_round_trip::<SetBaudResponse>(9, p);
    same_round_trip::<SetLedRequest>(10, p);
    same_round_trip::<SetLedResponse>(11, p);
    same_round_trip::<SetDirectionRequest>(12, p);
    same_round_trip::<SetDirectionResponse>(13, p);
    same_round_trip::<SetReportingFrequencyRequest>(14, p);
    same_round_trip::<SetReportingFrequencyResponse>(15, p);
    same_round_trip::<SetThrottleSourceRequest>(16, p);
    same_round_trip::<SetThrottleSourceResponse>(17, p);
    same_round_trip::<SelfTestRequest>(18, p);
    same_round_trip::<SelfTestResponse>(19, p);
    same_round_trip::<SetAngleRequest>(20, p);
    same_round_trip::<GetMaintenanceInformationRequest>(21, p);
    same_round_trip::<GetMaintenanceInformationResponse>(22, p);
    same_round_trip::<GetMajorConfigRequest>(23, p);
    same_round_trip::<GetMajorConfigResponse>(24, p);
}

#[test]
fn every_payload_round_trips_alike() {
    let mut rng = Rng::new(7);
    for len in 0..=MAX_PAYLOAD_LEN {
        for fill in [0x00, 0xFF, 0x80, 0x7F, 0x55] {
            every_type(&vec![fill; len]);
        }
        for _ in 0..300 {
            let p: Vec<u8> = (0..len).map(|_| rng.bits() as u8).collect();
            every_type(&p);
        }
    }
}

#[test]
fn typed_fields_unpack_to_the_rust_values() {
    let mut rng = Rng::new(11);
    for _ in 0..2000 {
        let m1 = StatusMsg1 {
            rpm: rng.bits() as u16,
            pwm: rng.bits() as u16,
            status: rng.bits() as u16,
        };
        let m2 = StatusMsg2 {
            input_voltage: rng.bits() as i16,
            current: rng.bits() as i16,
            temperature: rng.bits() as u8,
        };
        let (rpm, volts) = (rng.bits() as i32 >> 14, (rng.below(600) as f32) / 10.0);
        let status = EscStatus {
            error_count: rng.bits() as u32,
            voltage: volts,
            current: -volts,
            temperature: 300.0,
            rpm,
            power_rating_pct: rng.below(128) as u8,
            esc_index: rng.below(32) as u8,
        };
        let encode = |t: &dyn Fn(&mut [u8; MAX_PAYLOAD_LEN]) -> usize| {
            let mut out = [0u8; MAX_PAYLOAD_LEN];
            let n = t(&mut out);
            out[..n].to_vec()
        };
        let p1 = encode(&|o| m1.encode_into(o));
        let want1 = [m1.rpm, m1.pwm, m1.status].map(i32::from);
        assert_eq!(can_unpack(0, &p1), Some(want1.to_vec()));
        let p2 = encode(&|o| m2.encode_into(o));
        let want2 = [
            m2.input_voltage.into(),
            m2.current.into(),
            m2.temperature.into(),
        ];
        assert_eq!(can_unpack(1, &p2), Some(want2.to_vec()));
        let p4 = encode(&|o| status.encode_into(o));
        let half = |v: f32| i32::from(f16_from_f32(v));
        let want4 = [
            status.error_count as i32,
            half(volts),
            half(-volts),
            half(300.0),
            rpm.clamp(-(1 << 17), (1 << 17) - 1),
            status.power_rating_pct.into(),
            status.esc_index.into(),
        ];
        assert_eq!(can_unpack(4, &p4), Some(want4.to_vec()), "{status:?}");
        assert_eq!(can_pack(4, &want4), p4);
    }
}

#[test]
fn values_beyond_a_field_saturate_alike() {
    let ext = EscStatusExtended {
        input_pct: 200,
        output_pct: 255,
        motor_temperature_deg_c: -1000,
        motor_angle: 0xFFFF,
        status_flags: u32::MAX,
        esc_index: 40,
    };
    let mut out = [0u8; MAX_PAYLOAD_LEN];
    let n = ext.encode_into(&mut out);
    let fields = [200, 255, -1000, 0xFFFF, -1, 40];
    assert_eq!(can_pack(5, &fields), out[..n].to_vec());
    let status = EscStatus {
        rpm: 1 << 20,
        power_rating_pct: 250,
        ..Default::default()
    };
    let n = status.encode_into(&mut out);
    assert_eq!(
        can_pack(4, &[0, 0, 0, 0, 1 << 20, 250, 0]),
        out[..n].to_vec()
    );
}
