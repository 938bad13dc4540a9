//! The codes of the Hobbywing set-up services' fields (`docs/HW5-AND-CAN.md`, "Hobbywing DroneCAN
//! ESCs"): what each number in a `SetDirection`, `SetThrottleSource`, `SetLED`,
//! `SetReportingFrequency` or `GetMaintenanceInformation` request means. The field layouts are
//! `types.rs`'; the bit rates and reporting rates by code are beside them
//! ([`SetBaudRequest::BITRATES`](super::SetBaudRequest::BITRATES),
//! [`SetReportingFrequencyRequest::RATES_HZ`](super::SetReportingFrequencyRequest::RATES_HZ)).

use super::{
    GetMaintenanceInformationRequest, SetDirectionRequest, SetLedRequest,
    SetReportingFrequencyRequest, SetThrottleSourceRequest,
};

impl SetDirectionRequest {
    /// [`direction`](SetDirectionRequest::direction): clockwise.
    pub const CW: u8 = 0;
    /// [`direction`](SetDirectionRequest::direction): counter-clockwise.
    pub const CCW: u8 = 1;
    /// [`direction`](SetDirectionRequest::direction) that asks without changing anything: the
    /// answer says the direction.
    pub const QUERY: u8 = 255;
}

impl SetThrottleSourceRequest {
    /// [`source`](SetThrottleSourceRequest::source): DroneCAN's `RawCommand`.
    pub const CAN: u8 = 0;
    /// [`source`](SetThrottleSourceRequest::source): the PWM input.
    pub const PWM: u8 = 1;
}

impl SetLedRequest {
    /// [`option`](SetLedRequest::option): the ESC keeps the setting.
    pub const SAVE: u8 = 1;
    /// The [`blink`](SetLedRequest::blink) codes: 0 steady, else the rate in Hz.
    pub const BLINKS: [u8; 4] = [0, 1, 2, 5];
}

impl SetReportingFrequencyRequest {
    /// [`option`](SetReportingFrequencyRequest::option): read the rate.
    pub const READ: u8 = 0;
    /// [`option`](SetReportingFrequencyRequest::option): set the rate.
    pub const WRITE: u8 = 1;
}

impl GetMaintenanceInformationRequest {
    /// [`option`](GetMaintenanceInformationRequest::option): read, never clear.
    pub const READ: u8 = 0;
    /// [`option`](GetMaintenanceInformationRequest::option): clear the counters.
    pub const CLEAR: u8 = 1;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dronecan::{MAX_PAYLOAD_LEN, Message};

    fn payload(m: impl Into<Message>) -> ([u8; MAX_PAYLOAD_LEN], usize) {
        let mut buf = [0u8; MAX_PAYLOAD_LEN];
        let n = m.into().encode_into(&mut buf);
        (buf, n)
    }

    /// Each code is the byte the encoder puts where the field is.
    #[test]
    fn the_codes_are_the_bytes_on_the_wire() {
        let (b, n) = payload(SetDirectionRequest {
            direction: SetDirectionRequest::QUERY,
        });
        assert_eq!(&b[..n], [255]);
        let (b, n) = payload(SetDirectionRequest {
            direction: SetDirectionRequest::CCW,
        });
        assert_eq!(&b[..n], [1]);
        let (b, n) = payload(SetThrottleSourceRequest {
            source: SetThrottleSourceRequest::PWM,
        });
        assert_eq!(&b[..n], [1]);
        let (b, n) = payload(SetLedRequest {
            option: SetLedRequest::SAVE,
            color: 4,
            blink: SetLedRequest::BLINKS[3],
        });
        assert_eq!(&b[..n], [1, 4, 5]);
        let (b, n) = payload(SetReportingFrequencyRequest {
            option: SetReportingFrequencyRequest::WRITE,
            msg_id: 20050,
            rate: 5,
        });
        assert_eq!(&b[..n], [1, 0x52, 0x4E, 5]);
        let (b, n) = payload(GetMaintenanceInformationRequest {
            option: GetMaintenanceInformationRequest::READ,
        });
        assert_eq!(&b[..n], [0]);
    }
}
