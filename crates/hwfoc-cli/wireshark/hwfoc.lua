-- hwfoc.lua: a Wireshark dissector for Hobbywing ESC telemetry recorded by hwfoc: HW-FOC frames,
-- and the older formats hwfoc reads (Platinum V4 data and info frames, Platinum V3 frames, HW5
-- telemetry frames; docs/OLDER-PROTOCOLS.md, docs/HW5-AND-CAN.md); and DroneCAN on CAN captures
-- (Hobbywing's CAN ESCs, below).
--
-- `hwfoc record` (and `hwfoc simulate -o FILE.pcapng`, and the monitor's recording) write pcapng
-- files with link type USER0 (147): each packet holds the raw bytes of one serial port (one
-- interface per port, described as "HW5 telemetry (hwfoc), 115200 baud 8N1", naming the format
-- when it is known, "ESC telemetry (hwfoc), ..." when not; before hwfoc named formats, "HW-FOC
-- telemetry, 19200 baud 8N1"). Recordings written since
-- hwfoc 0.1 (compact layout) hold one frame per packet, or the bytes between two frames; older
-- ones hold each read of the port as a packet, cut anywhere in the frames.
--
-- This dissector shows each frame's fields in physical units, the status word with every fault
-- bit named, the device-information frame's text, and the checksum (good or bad, with the value
-- computed). Bytes that are no frame are shown as line noise. In an old recording a frame cut
-- across packets is shown as a partial frame at the end of the first packet and reassembled in
-- the packet that completes it (the bytes of one port are a stream, as hwfoc decodes them).
-- The valid frames shown are exactly those `hwfoc decode` finds, on noisy lines too: a candidate
-- frame is given up as soon as a byte shows it is none (the frames after it are shown in their
-- own packets), and a silence of over a second ends a frame still arriving.
--
-- USER0 is a link type for private use: other tools write other things with it. The dissector
-- only takes packets of interfaces hwfoc described ("telemetry (hwfoc)", or in older recordings
-- "HW-FOC telemetry", in the interface description); other USER0 packets go to the dissector that had USER0 before (the "User DLTs"
-- table of the preferences, or raw data), unless the preference "Dissect every USER0 packet" is
-- set (for HW-FOC bytes recorded by another tool).
--
-- The other formats are recognised by their bytes, in the simplest sound way for a dissector:
-- HW5 by its header `FE 01 00 03 30 5C 17` and its CRC-16/MODBUS (checked, good or bad, as
-- HW-FOC's checksum); V4 and V3, which have no checksum, by their lead byte `9B` and length: a
-- frame is taken where the last V4 or V3 frame ended (a V4 data frame plausible: its four ADC
-- fields below 4096; a V3 frame's throttle and PWM high bytes 0), or, starting a chain, when the
-- next frame's lead byte follows it with the next packet counter (a V4 info frame, `9B 9B .. 01
-- .. B9`, when a `9B` follows it). A V4 data frame's trailing `B9` (idle mode) is part of it.
-- The tree says that these formats carry no checksum. V4 voltages use the preference "V4 volts
-- per step" (8/910, as hwfoc's --v4-volts-per-step) and throttle a full scale of 1000; hwfoc
-- adopts an info frame's constants once two identical copies came, which this dissector does
-- not follow (it shows each info frame's constants), nor does it give a V4 current.
--
-- DroneCAN (protocol `dronecan`; docs/HW5-AND-CAN.md, "Hobbywing DroneCAN ESCs"): CAN captures
-- (link type LINKTYPE_CAN_SOCKETCAN, 227: what Wireshark captures on a SocketCAN interface) are
-- read by Wireshark's own `can` dissector; this adds DroneCAN as a heuristic sub-dissector of it,
-- taking every extended data frame whose tail byte can be DroneCAN's (a transfer's first frame has
-- its toggle bit clear, a service names both nodes; standard, remote and error frames are left
-- alone; turn it off in Analyze > Enabled Protocols on a bus with another protocol in extended
-- frames). Each frame shows the CAN id's fields (priority, data type id and name, message,
-- anonymous message or service request/response, source and destination node) and its tail byte
-- (start, end, toggle, transfer id). A single-frame transfer's payload is decoded field by field
-- (DSDL bit packing: fields one after the other, a field's bytes little-endian, each byte most
-- significant bit first): com.hobbywing.esc.StatusMsg1/2/3 (status bit 14 shown as the direction,
-- CCW or CW; input voltage and current, sent in 0.1 V and 0.1 A, shown in V and A), GetEscID
-- (`[0]` a request for ids, `[node, throttle channel]` an answer), uavcan.protocol.NodeStatus,
-- uavcan.equipment.esc.StatusExtended, and Hobbywing's setup services (210-217, 241, 242),
-- request and response. A multi-frame transfer (uavcan.equipment.esc.Status: 14 bytes, the
-- transfer CRC first, over 3 frames) is reassembled by source, data type, transfer kind,
-- destination and transfer id, its toggle bits followed; on its last frame the CRC
-- (CRC-16/CCITT-FALSE over the data type signature's 8 bytes, little-endian, then the payload) is
-- shown ok or bad and, when ok, the fields decoded. A data type not listed here is shown with its
-- id and its payload's bytes. Field names: dronecan.<type>.<DSDL field in lower case>, <type>
-- hobbywing.<name> for com.hobbywing.esc.<Name>, esc.<name> for uavcan.equipment.esc.<Name>,
-- nodestatus.
--
-- Install: `hwfoc wireshark install` (copies this file into Wireshark's personal Lua plugin
-- folder), or run `tshark -X lua_script:hwfoc.lua -r FILE`.
--
-- Conversions (as hwfoc's own outputs, with the same defaults): throttle % = raw * 100 / 1024;
-- eRPM = raw * 10; RPM = eRPM / (pole pairs * gear ratio); voltage = raw / 10 V; currents are
-- int16 / current scale A (default 64); temperatures by the protocol's ADC table, codes between
-- two entries interpolated, codes above 241 (below 0 degC) and below 33 (above 129 degC) shown
-- as out of range, with no value. Pole pairs, gear ratio and current scale are preferences
-- (Edit > Preferences > Protocols > HWFOC, or `-o hwfoc.pole_pairs:14` on tshark's command line).

local hwfoc = Proto("hwfoc", "Hobbywing HW-FOC ESC telemetry")

local SYNC = 0x9B
local DATA_LEN, INFO_LEN = 24, 77
-- A silence of the line longer than this (seconds, between two bytes) ends a frame still
-- arriving (hwfoc's SILENCE_S).
local SILENCE_S = 1.0
-- Frame kinds by length byte.
local KINDS = {
    [0x16] = { len = DATA_LEN, command = 0x02, name = "Data frame", proto = "hw-foc", kind = "data" },
    [0x4C] = { len = INFO_LEN, command = 0x01, name = "Device-information frame", proto = "hw-foc",
        kind = "info" },
}
-- The other formats' frames (lengths with what ends them: a V4 data frame's trailer).
local B9 = 0xB9
local V4_DATA = { len = 19, name = "Platinum V4 data frame", proto = "hw-v4", kind = "data" }
local V4_DATA_SLOW = { len = 20, name = "Platinum V4 data frame", proto = "hw-v4", kind = "data" }
local V4_INFO = { len = 13, name = "Platinum V4 info frame", proto = "hw-v4", kind = "info" }
local V4_TRAILER = { len = 1, name = "Platinum V4 data frame trailer", proto = "hw-v4",
    kind = "trailer" }
local V3_DATA = { len = 10, name = "Platinum V3 frame", proto = "hw-v3", kind = "data" }
local HW5_TELEMETRY = { len = 32, name = "HW5 telemetry frame", proto = "hw5", kind = "data" }
local HW5_HEADER = { 0xFE, 0x01, 0x00, 0x03, 0x30, 0x5C, 0x17 }
-- The physical ranges the codec allows (a frame whose checksum matches with a value past them is
-- rejected, as a bad checksum is: the codec's hwfoc::foc::THROTTLE_MAX_RAW,
-- hwfoc::hw5::THROTTLE_MAX_PCT and hwfoc::hw5::VOLTAGE_MAX_RAW; tests/dissector_tables.rs keeps
-- them equal).
local FOC_THROTTLE_MAX_RAW = 1024
local HW5_THROTTLE_MAX_PCT = 100
local HW5_VOLTAGE_MAX_RAW = 1000
local TITLES = { ["hw-foc"] = "HW-FOC", ["hw-v4"] = "HW-V4", ["hw-v3"] = "HW-V3", hw5 = "HW5" }

-- Status bits, bit 0 = least significant bit of the low byte (docs/PROTOCOL-NOTES.md).
local FAULTS = {
    { "input_voltage_high", "Input voltage too high" },
    { "input_voltage_low", "Input voltage too low" },
    { "over_current", "Over current" },
    { "reserved_3", "Reserved (bit 3)" },
    { "throttle_signal_lost", "Throttle signal lost" },
    { "throttle_not_zeroed", "Throttle not returned to zero" },
    { "mos_overheat", "MOSFET overheat" },
    { "cap_overheat", "Capacitor overheat" },
    { "motor_blocked", "Motor blocked" },
    { "upper_bridge_open", "Open circuit of upper bridge (MOSFET)" },
    { "mos_short", "MOSFET short circuit" },
    { "lower_bridge_open", "Open circuit of lower bridge (MOSFET)" },
    { "opamp_phase_c", "Operational amplifier abnormal, phase C" },
    { "opamp_phase_b", "Operational amplifier abnormal, phase B" },
    { "opamp_phase_a", "Operational amplifier abnormal, phase A" },
    { "reserved_15", "Reserved (bit 15)" },
}

-- ADC code for each temperature 0..129 degC (the protocol document's "ADC vs Temp" table).
local ADC_TABLE = {
    241, 240, 239, 238, 237, 236, 235, 234, 233, 232, 231, 230, 229, 228, 227, 226, 224, 223, 222,
    220, 219, 217, 216, 214, 213, 211, 209, 208, 206, 204, 202, 201, 199, 197, 195, 193, 191, 189,
    187, 185, 183, 181, 179, 177, 174, 172, 170, 168, 166, 164, 161, 159, 157, 154, 152, 150, 148,
    146, 143, 141, 139, 136, 134, 132, 130, 128, 125, 123, 121, 119, 117, 115, 113, 111, 109, 106,
    105, 103, 101, 99, 97, 95, 93, 91, 90, 88, 85, 84, 82, 81, 79, 77, 76, 74, 73, 72, 69, 68, 66,
    65, 64, 62, 62, 61, 59, 58, 56, 54, 54, 53, 51, 51, 50, 48, 48, 46, 46, 44, 43, 43, 41, 41, 39,
    39, 39, 37, 37, 35, 35, 33,
}
local ADC_MAX, ADC_MIN = 241, 33

-- degC for every code ADC_MIN..ADC_MAX: a code in the table takes the mean of its temperatures
-- (where it repeats); a code between two entries, the value linearly between theirs.
local CELSIUS = {}
do
    local exact = {}
    local t = 1
    while t <= #ADC_TABLE do
        local code, last = ADC_TABLE[t], t
        while last + 1 <= #ADC_TABLE and ADC_TABLE[last + 1] == code do
            last = last + 1
        end
        exact[code] = ((t - 1) + (last - 1)) / 2
        t = last + 1
    end
    for code = ADC_MIN, ADC_MAX do
        if exact[code] then
            CELSIUS[code] = exact[code]
        else
            local lo, hi = code, code
            while not exact[lo] do lo = lo - 1 end
            while not exact[hi] do hi = hi + 1 end
            CELSIUS[code] = exact[lo] + (exact[hi] - exact[lo]) * ((code - lo) / (hi - lo))
        end
    end
end

local CHECKSUM_STATUS = { [0] = "Bad", [1] = "Good" }
local COMMANDS = { [0x01] = "Device information", [0x02] = "Real-time data" }

local f = {
    kind = ProtoField.string("hwfoc.kind", "Kind"),
    motor_temp = ProtoField.double("hwfoc.motor_temp_c", "Motor temperature"),
    bec_temp = ProtoField.double("hwfoc.bec_temp_c", "BEC temperature"),
    bec_voltage = ProtoField.double("hwfoc.bec_voltage_v", "BEC voltage"),
    bec_current = ProtoField.double("hwfoc.bec_current_a", "BEC current"),
    no_checksum = ProtoField.string("hwfoc.no_checksum", "Checksum"),
    v4_voltage_adc = ProtoField.uint16("hwfoc.v4.voltage_adc", "Voltage (ADC)"),
    v4_current_adc = ProtoField.uint16("hwfoc.v4.current_adc", "Current (ADC)"),
    v4_temp_adc = ProtoField.uint16("hwfoc.v4.temp_adc", "MOSFET temperature (ADC)"),
    v4_temp2_adc = ProtoField.uint16("hwfoc.v4.temp2_adc", "Second temperature (ADC)"),
    v4_trailer = ProtoField.uint8("hwfoc.v4.trailer", "Trailer (idle mode)", base.HEX),
    v4_full_scale = ProtoField.uint16("hwfoc.v4.full_scale", "Full scale of throttle and PWM"),
    v4_volts_per_step = ProtoField.string("hwfoc.v4.volts_per_step", "Volts per voltage step"),
    v4_current_scale = ProtoField.string("hwfoc.v4.current_scale", "Current"),
    v4_t1 = ProtoField.uint8("hwfoc.v4.t1", "T1 (meaning unknown)", base.HEX),
    v4_t2 = ProtoField.uint8("hwfoc.v4.t2", "T2 (meaning unknown)", base.HEX),
    v3_period = ProtoField.uint16("hwfoc.v3.period_us", "Electrical revolution period (us)"),

    sync = ProtoField.uint8("hwfoc.sync", "Sync", base.HEX),
    length = ProtoField.uint8("hwfoc.length", "Length (bytes before the checksum)", base.DEC),
    version = ProtoField.uint8("hwfoc.version", "Protocol version", base.DEC),
    command = ProtoField.uint8("hwfoc.command", "Command", base.HEX, COMMANDS),
    time = ProtoField.absolute_time("hwfoc.time", "First byte received", base.UTC),
    time_epoch = ProtoField.relative_time("hwfoc.time_epoch",
        "First byte received (seconds since 1970, as hwfoc's t_s)"),
    -- uint32 as the record's `packet` (record schema 2: the older formats count in 24 bits);
    -- an HW-FOC frame's counter is its 2 bytes.
    packet = ProtoField.uint32("hwfoc.packet", "Packet number", base.DEC),
    -- The record's `protocol`: the format of the frame, as `--protocol` names it.
    protocol = ProtoField.string("hwfoc.protocol", "Protocol (record's protocol column)"),
    throttle_in_raw = ProtoField.uint16("hwfoc.throttle_in_raw", "Input throttle (raw, of 1024)"),
    throttle_in = ProtoField.double("hwfoc.throttle_in_pct", "Input throttle"),
    throttle_out_raw = ProtoField.uint16("hwfoc.throttle_out_raw", "Output throttle (raw, of 1024)"),
    throttle_out = ProtoField.double("hwfoc.throttle_out_pct", "Output throttle"),
    erpm_raw = ProtoField.uint16("hwfoc.erpm_raw", "eRPM (raw, x10)"),
    erpm = ProtoField.uint32("hwfoc.erpm", "Electrical RPM", base.DEC),
    rpm = ProtoField.double("hwfoc.rpm", "RPM"),
    voltage_raw = ProtoField.uint16("hwfoc.voltage_raw", "Voltage (raw, x0.1 V)"),
    voltage = ProtoField.double("hwfoc.voltage_v", "Input voltage"),
    current_raw = ProtoField.int16("hwfoc.current_raw", "Input current (raw int16)"),
    current = ProtoField.double("hwfoc.current_a", "Input current"),
    phase_current_raw = ProtoField.int16("hwfoc.phase_current_raw", "Phase current (raw int16)"),
    phase_current = ProtoField.double("hwfoc.phase_current_a", "Phase current"),
    mos_adc = ProtoField.uint8("hwfoc.mos_adc", "MOSFET temperature (ADC code)"),
    mos_temp = ProtoField.double("hwfoc.mos_temp_c", "MOSFET temperature"),
    cap_adc = ProtoField.uint8("hwfoc.cap_adc", "Capacitor temperature (ADC code)"),
    cap_temp = ProtoField.double("hwfoc.cap_temp_c", "Capacitor temperature"),
    status = ProtoField.uint16("hwfoc.status", "Status", base.HEX),
    faults = ProtoField.string("hwfoc.faults", "Faults (status bits set, by name, or none)"),
    info_text = ProtoField.string("hwfoc.info.text", "Text"),
    info_product = ProtoField.string("hwfoc.info.product", "Product"),
    info_hardware = ProtoField.string("hwfoc.info.hardware", "Hardware"),
    info_firmware = ProtoField.string("hwfoc.info.firmware", "Firmware"),
    info_id = ProtoField.string("hwfoc.info.id", "Id"),
    checksum = ProtoField.uint16("hwfoc.checksum", "Checksum", base.HEX),
    checksum_computed = ProtoField.uint16("hwfoc.checksum.computed", "Checksum computed", base.HEX),
    checksum_status = ProtoField.uint8("hwfoc.checksum.status", "Checksum status", base.DEC,
        CHECKSUM_STATUS),
    noise = ProtoField.bytes("hwfoc.noise", "Line noise (no frame)"),
    partial = ProtoField.bytes("hwfoc.partial", "Partial frame"),
}
-- HW5's fault byte (byte 12), as hwfoc names its bits.
local HW5_FAULTS = {
    { "motor_locked", "Motor locked" },
    { "over_temperature", "Over-temperature" },
    { "throttle_not_zero_at_start", "Throttle not at zero at start-up" },
    { "throttle_signal_lost", "Throttle signal lost" },
    { "over_current", "Over-current" },
    { "low_voltage", "Low voltage" },
    { "input_voltage_error", "Input voltage error" },
    { "motor_connection_error", "Motor connection error" },
}
local hw5_bits = {}
for bit, fault in ipairs(HW5_FAULTS) do
    local field = ProtoField.bool("hwfoc.hw5.fault." .. fault[1], fault[2], 8, nil, 2 ^ (bit - 1))
    hw5_bits[bit] = field
    f["hw5_fault_" .. fault[1]] = field
end
local status_bits = {}
for bit, fault in ipairs(FAULTS) do
    local field = ProtoField.bool("hwfoc.status." .. fault[1], fault[2], 16, nil, 2 ^ (bit - 1))
    status_bits[bit] = field
    f["status_" .. fault[1]] = field
end
local fields = {}
for _, field in pairs(f) do
    fields[#fields + 1] = field
end
hwfoc.fields = fields

local ef = {
    fault = ProtoExpert.new("hwfoc.fault.expert", "ESC fault", expert.group.RESPONSE_CODE,
        expert.severity.WARN),
    bad_checksum = ProtoExpert.new("hwfoc.checksum.bad", "Bad checksum", expert.group.CHECKSUM,
        expert.severity.ERROR),
    bad_header = ProtoExpert.new("hwfoc.header.bad", "Unexpected version or command",
        expert.group.MALFORMED, expert.severity.ERROR),
    not_ascii = ProtoExpert.new("hwfoc.info.not_ascii", "Text byte outside ASCII",
        expert.group.MALFORMED, expert.severity.ERROR),
    temp_range = ProtoExpert.new("hwfoc.temp.out_of_range", "Temperature out of the ADC table",
        expert.group.SEQUENCE, expert.severity.NOTE),
    out_of_range = ProtoExpert.new("hwfoc.value.out_of_range",
        "Value past the protocol's range: rejected by hwfoc", expert.group.MALFORMED,
        expert.severity.ERROR),
    noise = ProtoExpert.new("hwfoc.noise.expert", "Line noise", expert.group.SEQUENCE,
        expert.severity.NOTE),
    partial = ProtoExpert.new("hwfoc.partial.expert", "Frame cut by the end of the packet",
        expert.group.REASSEMBLE, expert.severity.NOTE),
    cut = ProtoExpert.new("hwfoc.cut.expert", "Frame cut short by the next frame",
        expert.group.MALFORMED, expert.severity.WARN),
    reassembled = ProtoExpert.new("hwfoc.reassembled.expert",
        "Frame begun in an earlier packet of this port", expert.group.REASSEMBLE,
        expert.severity.CHAT),
}
hwfoc.experts = { ef.fault, ef.bad_checksum, ef.bad_header, ef.not_ascii, ef.temp_range, ef.noise,
    ef.partial, ef.cut, ef.reassembled, ef.out_of_range }

hwfoc.prefs.pole_pairs = Pref.uint("Pole pairs", 7, "Motor pole pairs (magnets / 2), for RPM")
hwfoc.prefs.gear_ratio = Pref.string("Gear ratio", "1",
    "Gear ratio between motor and the shaft whose RPM is shown (1 for direct drive)")
hwfoc.prefs.current_scale = Pref.string("Current scale", "64",
    "Raw current units per ampere (the vendor document says 64; some drivers use 100)")
hwfoc.prefs.v4_volts_per_step = Pref.string("V4 volts per step", "8/910",
    "Volts per voltage ADC step of a Platinum V4 ESC (8/910 for low-voltage models, 11/650 for " ..
    "HV), as hwfoc's --v4-volts-per-step")
hwfoc.prefs.all_user0 = Pref.bool("Dissect every USER0 packet", false,
    "Also dissect USER0 packets of interfaces hwfoc did not describe (HW-FOC bytes recorded by " ..
    "another tool); otherwise they go to the USER0 dissector there was before")

local function positive_pref(text, default)
    local value = tonumber(text)
    if value and value > 0 and value < math.huge then return value end
    return default
end

local f_iface_id = Field.new("frame.interface_id")
local f_iface_desc = Field.new("frame.interface_description")
local f_epoch = Field.new("frame.time_epoch")

-- First pass over a file: per interface, the bytes of a frame still undecided at the end of the
-- last packet, and that packet's time; per packet, the bytes carried into it.
local carry_of = {}
local pending = {}

function hwfoc.init()
    carry_of = {}
    pending = {}
end

-- A value for a label: up to 7 significant digits, no trailing zeros.
local function fmt(value)
    return (string.format("%.7g", value))
end

local function sum(s, from, to) -- bytes from..to-1 (0-based)
    local total = 0
    for i = from + 1, to do total = total + s:byte(i) end
    return total
end

-- The first value of the HW-FOC data frame at `i` (whole) past its range, as "name raw max",
-- or nil: the throttles (big-endian, bytes 6 and 8) up to FOC_THROTTLE_MAX_RAW.
local function foc_out_of_range(s, i)
    for _, t in ipairs({ { 6, "input throttle" }, { 8, "output throttle" } }) do
        local raw = s:byte(i + t[1] + 1) * 256 + s:byte(i + t[1] + 2)
        if raw > FOC_THROTTLE_MAX_RAW then
            return string.format("%s %d over %d", t[2], raw, FOC_THROTTLE_MAX_RAW)
        end
    end
    return nil
end

-- The first value of the HW5 telemetry frame at `i` (whole) past its range, or nil: the
-- throttle (byte 9, percent) and the input voltage (bytes 15-16, 0.1 V), as the codec checks.
local function hw5_out_of_range(s, i)
    local throttle = s:byte(i + 10)
    if throttle > HW5_THROTTLE_MAX_PCT then
        return string.format("throttle %d over %d", throttle, HW5_THROTTLE_MAX_PCT)
    end
    local volts = s:byte(i + 16) + s:byte(i + 17) * 256
    if volts > HW5_VOLTAGE_MAX_RAW then
        return string.format("input voltage %d over %d", volts, HW5_VOLTAGE_MAX_RAW)
    end
    return nil
end

-- Whether a frame may start at `i` of `s` (n bytes): returns the kind and "good" or "bad" once
-- its bytes decide, "undecided" while the bytes there begin a frame the bytes still to come may
-- complete, or nil when no frame starts there. The rule is the hwfoc decoder's: a sync byte, a
-- known length byte, then version, command, checksum and, for the information frame, ASCII
-- text. A candidate is "bad" as soon as a byte there shows it is no frame (a version, command
-- or text byte no frame has), before all its bytes are there: the decoder waits for them before
-- it gives the candidate up, but, giving up a candidate at the cost of its first byte whenever
-- that is, finds the same frames. So a candidate carried into the next packet is always the
-- start of a frame, and holds no other frame (an information frame's text has no sync byte,
-- and a frame that begins in a data frame's first 23 bytes ends after them): a silence or the
-- end of the file that ends it hides nothing the decoder would find.
local function candidate(s, n, i)
    if s:byte(i + 1) ~= SYNC then return nil end
    if i + 1 >= n then return nil, "undecided" end
    local kind = KINDS[s:byte(i + 2)]
    if not kind then return nil end
    local have = math.min(n - i, kind.len) -- bytes of the candidate there
    if (have >= 3 and s:byte(i + 3) ~= 0x01) or (have >= 4 and s:byte(i + 4) ~= kind.command) then
        return kind, "bad"
    end
    if kind.len == INFO_LEN then
        for k = i + 5, i + math.min(have, INFO_LEN - 1) do
            if s:byte(k) >= 0x80 then return kind, "bad" end
        end
    end
    if have < kind.len then return kind, "undecided" end
    local good
    if kind.len == DATA_LEN then
        good = sum(s, i, i + 22) % 65536 == s:byte(i + 23) + s:byte(i + 24) * 256
            and foc_out_of_range(s, i) == nil
    else
        good = sum(s, i, i + 76) % 256 == s:byte(i + 77)
    end
    return kind, good and "good" or "bad"
end


-- XOR of two integers below 2^16 (arithmetic: Lua 5.2 has no operators for it, 5.3 no bit32).
local function bxor16(a, b)
    local r, bitv = 0, 1
    for _ = 1, 16 do
        local x, y = a % 2, b % 2
        if x ~= y then r = r + bitv end
        a, b, bitv = (a - x) / 2, (b - y) / 2, bitv * 2
    end
    return r
end

-- CRC-16/MODBUS of bytes from..to-1 (0-based) of `s`.
local function crc16_modbus(s, from, to)
    local crc = 0xFFFF
    for k = from + 1, to do
        crc = bxor16(crc, s:byte(k))
        for _ = 1, 8 do
            local lsb = crc % 2
            crc = (crc - lsb) / 2
            if lsb == 1 then crc = bxor16(crc, 0xA001) end
        end
    end
    return crc
end

local function be(s, i, width) -- big-endian unsigned of `width` bytes at i (0-based)
    local v = 0
    for k = i + 1, i + width do v = v * 256 + s:byte(k) end
    return v
end

-- An HW5 telemetry frame at `i`: its header so far, then the CRC of its 32 bytes.
local function hw5_candidate(s, n, i)
    for k = 1, math.min(#HW5_HEADER, n - i) do
        if s:byte(i + k) ~= HW5_HEADER[k] then return nil end
    end
    if n - i < HW5_TELEMETRY.len then return HW5_TELEMETRY, "undecided" end
    local good = crc16_modbus(s, i, i + 30) == s:byte(i + 31) + s:byte(i + 32) * 256
        and hw5_out_of_range(s, i) == nil
    return HW5_TELEMETRY, good and "good" or "bad"
end

-- Whether the frame after one ending at `j` begins a chain with it: its lead byte `9B`, and
-- the packet counter after `counter` (a V4 info frame, `9B 9B`, is not counted). "yes", "no"
-- or "undecided" (the bytes end before it tells).
local function followed(s, n, j, counter, info_ok)
    if j >= n then return "undecided" end
    if s:byte(j + 1) ~= SYNC then return "no" end
    if info_ok and j + 1 < n and s:byte(j + 2) == SYNC then return "yes" end
    if n - j < 4 then return "undecided" end
    return be(s, j + 1, 3) == (counter + 1) % 16777216 and "yes" or "no"
end

local function v4_plausible(s, i) -- the 19 bytes at i are there
    for _, k in ipairs({ 11, 13, 15, 17 }) do
        if s:byte(i + k + 1) >= 16 then return false end
    end
    return true
end

-- A V4 info frame at `i`: `9B 9B`, `01` at 4, `B9` at 12, then (out of a chain) a `9B`.
local function v4_info_candidate(s, n, i, chained)
    local fixed = { [1] = SYNC, [4] = 0x01, [12] = B9 }
    for k, b in pairs(fixed) do
        if i + k < n and s:byte(i + k + 1) ~= b then return nil end
    end
    if n - i < V4_INFO.len then return V4_INFO, "undecided" end
    if chained then return V4_INFO, "good" end
    if i + 13 >= n then return V4_INFO, "undecided" end
    return (s:byte(i + 14) == SYNC) and V4_INFO or nil, (s:byte(i + 14) == SYNC) and "good" or nil
end

-- A V4 data frame at `i` (19 bytes, 20 with its trailer `B9`).
local function v4_data_candidate(s, n, i, chained)
    if n - i < V4_DATA.len then return V4_DATA, "undecided" end
    if not v4_plausible(s, i) then return nil end
    local slow = i + 19 < n and s:byte(i + 20) == B9
    local kind = slow and V4_DATA_SLOW or V4_DATA
    if chained then return kind, "good" end
    local next_at = i + 19
    if i + 19 >= n then return V4_DATA, "undecided" end
    if slow then next_at = i + 20 end
    local after = followed(s, n, next_at, be(s, i + 1, 3), true)
    if after == "yes" then return kind, "good" end
    if after == "undecided" then return kind, "undecided" end
    return nil
end

-- A V3 frame at `i` (10 bytes): throttle and PWM high bytes 0 (their full scale is 255).
local function v3_candidate(s, n, i, chained)
    for _, k in ipairs({ 4, 6 }) do
        if i + k < n and s:byte(i + k + 1) ~= 0 then return nil end
    end
    if n - i < V3_DATA.len then return V3_DATA, "undecided" end
    if chained then return V3_DATA, "good" end
    local after = followed(s, n, i + 10, be(s, i + 1, 3), false)
    if after == "yes" then return V3_DATA, "good" end
    if after == "undecided" then return V3_DATA, "undecided" end
    return nil
end

-- A frame of the other formats at `i`: kind and state as `candidate`'s ("bad" only for HW5,
-- whose CRC can be wrong). `chain`: the format whose last frame ended at `i` ("hw-v4",
-- "hw-v3", or nil), with `trailer` when a V4 data frame's `B9` may follow.
local function other_candidate(s, n, i, chain, trailer)
    local lead = s:byte(i + 1)
    if lead == 0xFE then return hw5_candidate(s, n, i) end
    if chain == "hw-v4" and trailer and lead == B9 then return V4_TRAILER, "good" end
    if lead ~= SYNC then return nil end
    local tries
    if chain == "hw-v3" then
        tries = { { v3_candidate, true }, { v4_info_candidate }, { v4_data_candidate } }
    elseif chain == "hw-v4" then
        tries = { { v4_info_candidate, true }, { v4_data_candidate, true }, { v3_candidate } }
    else
        tries = { { v4_info_candidate }, { v4_data_candidate }, { v3_candidate } }
    end
    local waiting = nil
    for _, try in ipairs(tries) do
        local kind, state = try[1](s, n, i, try[2])
        if state == "good" then return kind, state end
        if state == "undecided" and not waiting then waiting = kind end
    end
    if waiting then return waiting, "undecided" end
    return nil
end

-- A frame of any format at `i`: a good HW-FOC frame, else a frame of the others, else what
-- is still undecided, else a bad HW-FOC or HW5 frame.
local function any_candidate(s, n, i, chain, trailer)
    local kind, state = candidate(s, n, i)
    if state == "good" then return kind, state end
    local other, other_state = other_candidate(s, n, i, chain, trailer)
    if other_state == "good" then return other, other_state end
    if state == "undecided" then return kind, state end
    if other_state == "undecided" then return other, other_state end
    if state == "bad" then return kind, state end
    return other, other_state
end

-- The frames and noise in `s`: a list of items {kind, from, to, what} (0-based, `to` exclusive),
-- `what` one of "good", "bad", "cut" (a frame cut short by the next one), "partial" (cut by the
-- end of `s`) or "noise". Valid frames are those the hwfoc decoder finds in the same bytes.
local function scan(s, chain)
    local n = #s
    local items = {}
    local noise_from = nil
    -- Where the last V4 or V3 frame ended, and its format.
    local chain_at, chain_proto, trailer = 0, chain and chain.proto, chain and chain.trailer
    local function noise_to(i)
        if noise_from then
            items[#items + 1] = { from = noise_from, to = i, what = "noise" }
            noise_from = nil
        end
    end
    local i = 0
    local function chain_here()
        if chain_at == i then return chain_proto, trailer end
        return nil, nil
    end
    while i < n do
        local kind, state = any_candidate(s, n, i, chain_here())
        if state == "undecided" then
            noise_to(i)
            items[#items + 1] = { kind = kind, from = i, to = n, what = "partial" }
            return items, (chain_at == i and chain_proto) and { proto = chain_proto, trailer = trailer,
                at = i } or nil
        elseif state == "good" then
            noise_to(i)
            items[#items + 1] = { kind = kind, from = i, to = i + kind.len, what = "good" }
            i = i + kind.len
            if kind.proto == "hw-v4" or kind.proto == "hw-v3" then
                chain_at, chain_proto = i, kind.proto
                trailer = kind == V4_DATA
            end
        elseif state == "bad" then
            -- The decoder goes on at the next byte: a valid (or still arriving) frame that starts
            -- inside this one ends it.
            local whole = n - i >= kind.len
            local cut = nil
            for j = i + 1, math.min(i + kind.len, n) - 1 do
                local _, inner = any_candidate(s, n, j)
                if inner == "good" or inner == "undecided" then
                    cut = j
                    break
                end
            end
            if cut then
                noise_to(i)
                items[#items + 1] = { kind = kind, from = i, to = cut, what = "cut" }
                i = cut
            elseif whole then
                noise_to(i)
                items[#items + 1] = { kind = kind, from = i, to = i + kind.len, what = "bad" }
                i = i + kind.len
            else
                -- Given up before its end, with no frame after it in `s`: line noise.
                noise_from = noise_from or i
                i = n
            end
        else
            noise_from = noise_from or i
            i = i + 1
        end
    end
    noise_to(n)
    return items, (chain_at == n and chain_proto) and { proto = chain_proto, trailer = trailer,
        at = n } or nil
end

-- Adds `value` as `field` with its unit in the label ("Input voltage: 24.7 V"); the field keeps
-- the full value (for filters and tshark's -T fields).
local function quantity(tree, field, range, value, name, unit)
    return tree:add(field, range, value, string.format("%s: %s %s", name, fmt(value), unit))
end

local function temperature(tree, adc_field, temp_field, range, name)
    local code = range:uint()
    local celsius = CELSIUS[code]
    if celsius then
        local item = quantity(tree, temp_field, range, celsius, name, "\194\176C")
        item:add(adc_field, range)
        return fmt(celsius)
    end
    local side = code > ADC_MAX and "below 0 \194\176C" or "above 129 \194\176C"
    local item = tree:add(adc_field, range)
    item:append_text(" (" .. name .. " out of range: " .. side .. ")")
    item:add_proto_expert_info(ef.temp_range, name .. " out of range: " .. side)
    return "out of range"
end

-- Dissects the data frame in `r` (a TvbRange of 24 bytes) into `tree`; returns a summary.
local function data_frame(r, tree)
    local current_scale = positive_pref(hwfoc.prefs.current_scale, 64)
    local gear_ratio = positive_pref(hwfoc.prefs.gear_ratio, 1)
    local pole_pairs = hwfoc.prefs.pole_pairs
    if pole_pairs < 1 then pole_pairs = 7 end

    local packet = r(4, 2):uint()
    tree:add(f.packet, r(4, 2))
    local t_in = r(6, 2):uint()
    quantity(tree, f.throttle_in, r(6, 2), t_in * 100 / 1024, "Input throttle", "%")
        :add(f.throttle_in_raw, r(6, 2))
    local t_out = r(8, 2):uint()
    quantity(tree, f.throttle_out, r(8, 2), t_out * 100 / 1024, "Output throttle", "%")
        :add(f.throttle_out_raw, r(8, 2))
    local erpm = r(10, 2):uint() * 10
    quantity(tree, f.erpm, r(10, 2), erpm, "Electrical RPM", "rev/min"):add(f.erpm_raw, r(10, 2))
    quantity(tree, f.rpm, r(10, 2), erpm / (gear_ratio * pole_pairs), "RPM", "rev/min")
        :append_text(string.format(" (%d pole pairs, gear ratio %s)", pole_pairs, fmt(gear_ratio)))
    local volts = r(12, 2):uint() / 10
    quantity(tree, f.voltage, r(12, 2), volts, "Input voltage", "V"):add(f.voltage_raw, r(12, 2))
    local amps = r(14, 2):int() / current_scale
    quantity(tree, f.current, r(14, 2), amps, "Input current", "A"):add(f.current_raw, r(14, 2))
    quantity(tree, f.phase_current, r(16, 2), r(16, 2):int() / current_scale, "Phase current", "A")
        :add(f.phase_current_raw, r(16, 2))
    local mos = temperature(tree, f.mos_adc, f.mos_temp, r(18, 1), "MOSFET temperature")
    temperature(tree, f.cap_adc, f.cap_temp, r(19, 1), "Capacitor temperature")
    local status = r(20, 2):uint()
    local status_item = tree:add(f.status, r(20, 2))
    local names = {}
    for bit, fault in ipairs(FAULTS) do
        status_item:add(status_bits[bit], r(20, 2))
        -- (arithmetic rather than bit32, which Lua 5.3 and later lack)
        if math.floor(status / 2 ^ (bit - 1)) % 2 == 1 then
            names[#names + 1] = fault[1]
        end
    end
    local faults = table.concat(names, ",")
    tree:add(f.faults, r(20, 2), #names > 0 and faults or "none")
    if #names > 0 then
        status_item:append_text(" (" .. faults .. ")")
        status_item:add_proto_expert_info(ef.fault, "ESC fault: " .. faults)
    end
    return string.format("#%d %.1f V %.2f A %s%% eRPM %d %s\194\176C%s", packet, volts, amps,
        fmt(t_in * 100 / 1024), erpm, mos,
        #names > 0 and (" FAULT " .. faults) or "")
end

local function trim(s)
    return (s:gsub("^[ %z]+", ""):gsub("[ %z]+$", ""))
end

-- Dissects the device-information frame in `r` (77 bytes); returns a summary.
local function info_frame(r, tree)
    local text = r(4, 72):string()
    tree:add(f.info_text, r(4, 72))
    local product = trim(text:sub(17, 32))
    local hardware = trim(text:sub(33, 48))
    local firmware = trim(text:sub(49, 64))
    local id = trim(text:sub(65, 72))
    tree:add(f.info_product, r(20, 16), product)
    tree:add(f.info_hardware, r(36, 16), hardware)
    tree:add(f.info_firmware, r(52, 16), firmware)
    tree:add(f.info_id, r(68, 8), id)
    for k = 4, 75 do
        if r(k, 1):uint() >= 0x80 then
            tree:add_proto_expert_info(ef.not_ascii, string.format("Text byte %d is 0x%02X", k,
                r(k, 1):uint()))
            break
        end
    end
    return string.format("%s %s %s %s", product, hardware, firmware, id)
end

-- The settings shared by the formats' conversions: pole pairs and gear ratio.
local function rpm_settings()
    local gear_ratio = positive_pref(hwfoc.prefs.gear_ratio, 1)
    local pole_pairs = hwfoc.prefs.pole_pairs
    if pole_pairs < 1 then pole_pairs = 7 end
    return pole_pairs, gear_ratio
end

-- The V4 volts per step preference: "N/D", "low" (8/910) or "hv" (11/650); 8/910 otherwise.
local function v4_volts_per_step()
    local text = tostring(hwfoc.prefs.v4_volts_per_step):gsub("^%s+", ""):gsub("%s+$", "")
    if text == "hv" then return 11, 650 end
    local num, den = text:match("^(%d+)%s*/%s*(%d+)$")
    num, den = tonumber(num), tonumber(den)
    if num and den and num > 0 and den > 0 and num < 65536 and den < 65536 then return num, den end
    return 8, 910
end

-- A V4 temperature ADC value in degC (NTC, beta 3950, 47 kOhm at 25 degC on a 10 kOhm
-- reference), or nil for 0 (no reading).
local function ntc_celsius(adc)
    if adc == 0 or adc >= 4096 then return nil end
    local ratio = adc / (4096 - adc) / 4.7
    return 1 / (math.log(ratio) / 3950 + 1 / 298.15) - 273.15
end

local function rpm_item(tree, range, erpm)
    local pole_pairs, gear_ratio = rpm_settings()
    quantity(tree, f.rpm, range, erpm / (gear_ratio * pole_pairs), "RPM", "rev/min")
        :append_text(string.format(" (%d pole pairs, gear ratio %s)", pole_pairs, fmt(gear_ratio)))
end

local function v4_temperature(tree, adc_field, temp_field, range, name)
    local adc = range:uint()
    local celsius = ntc_celsius(adc)
    if celsius then
        quantity(tree, temp_field, range, celsius, name, "\194\176C"):add(adc_field, range)
        return fmt(celsius)
    end
    tree:add(adc_field, range):append_text(" (no reading)")
    return "-"
end

-- Dissects a V4 data frame (19 bytes, or 20 with its trailer); returns a summary.
local function v4_data(r, tree)
    local packet = r(1, 3):uint()
    tree:add(f.packet, r(1, 3), packet)
    local t_in = r(4, 2):uint()
    quantity(tree, f.throttle_in, r(4, 2), t_in * 100 / 1000, "Input throttle", "%")
        :append_text(string.format(" (raw %d of full scale 1000)", t_in))
    local t_out = r(6, 2):uint()
    quantity(tree, f.throttle_out, r(6, 2), t_out * 100 / 1000, "Output throttle", "%")
        :append_text(string.format(" (raw %d of full scale 1000)", t_out))
    local erpm = r(8, 3):uint()
    quantity(tree, f.erpm, r(8, 3), erpm, "Electrical RPM", "rev/min")
    rpm_item(tree, r(8, 3), erpm)
    local num, den = v4_volts_per_step()
    local adc = r(11, 2):uint()
    local volts = adc * num / den
    quantity(tree, f.voltage, r(11, 2), volts, "Input voltage", "V")
        :append_text(string.format(" (%d/%d V per step: the preference)", num, den))
        :add(f.v4_voltage_adc, r(11, 2))
    tree:add(f.v4_current_adc, r(13, 2)):append_text(
        " (amperes need an info frame's current constants: not shown)")
    local mos = v4_temperature(tree, f.v4_temp_adc, f.mos_temp, r(15, 2), "MOSFET temperature")
    v4_temperature(tree, f.v4_temp2_adc, f.cap_temp, r(17, 2), "Second temperature")
    if r:len() == 20 then tree:add(f.v4_trailer, r(19, 1)) end
    return string.format("#%d %.2f V %s%% eRPM %d %s\194\176C", packet, volts,
        fmt(t_in * 100 / 1000), erpm, mos)
end

-- Dissects a V4 info frame (13 bytes); returns a summary.
local function v4_info(r, tree)
    tree:add(f.sync, r(0, 1))
    tree:add(f.sync, r(1, 1))
    local full = r(2, 2):uint()
    tree:add(f.v4_full_scale, r(2, 2))
    local v1, v2 = r(5, 1):uint(), r(6, 1):uint()
    local per_step = string.format("%d/%d", v1, v2 * 10)
    tree:add(f.v4_volts_per_step, r(5, 2), per_step)
    local i1, i2, i3 = r(7, 1):uint(), r(8, 1):uint(), r(9, 1):uint()
    local current = i1 == 0 and "no current sensor" or
        string.format("amps = adc * %d / %d - %d", i1, i2, i3)
    tree:add(f.v4_current_scale, r(7, 3), current)
    tree:add(f.v4_t1, r(10, 1))
    tree:add(f.v4_t2, r(11, 1))
    tree:add(f.v4_trailer, r(12, 1)):set_text("End of the info frame: 0xb9")
    return string.format("full scale %d, %s V per step, %s", full, per_step, current)
end

-- Dissects a V3 frame (10 bytes); returns a summary.
local function v3_data(r, tree)
    local packet = r(1, 3):uint()
    tree:add(f.packet, r(1, 3), packet)
    local t_in = r(4, 2):uint()
    quantity(tree, f.throttle_in, r(4, 2), t_in * 100 / 255, "Input throttle", "%")
        :append_text(string.format(" (raw %d of 255)", t_in))
    local t_out = r(6, 2):uint()
    quantity(tree, f.throttle_out, r(6, 2), t_out * 100 / 255, "Output throttle", "%")
        :append_text(string.format(" (raw %d of 255)", t_out))
    local period = r(8, 2):uint()
    local item = tree:add(f.v3_period, r(8, 2))
    local speed = "no speed"
    if period == 0 or period == 35314 then
        item:append_text(" (no speed: the ESC's placeholder before the motor turns)")
    else
        local erpm = math.floor(60000000 / period)
        quantity(tree, f.erpm, r(8, 2), erpm, "Electrical RPM", "rev/min")
            :append_text(" (60 000 000 / period)")
        rpm_item(tree, r(8, 2), erpm)
        speed = string.format("eRPM %d", erpm)
    end
    return string.format("#%d %s%% %s", packet, fmt(t_in * 100 / 255), speed)
end

-- Dissects an HW5 telemetry frame (32 bytes, fields little-endian); returns a summary.
local function hw5_data(r, tree)
    local throttle = r(9, 1):uint()
    quantity(tree, f.throttle_in, r(9, 1), throttle, "Throttle", "%")
    local fault = r(12, 1):uint()
    local status_item = tree:add(f.status, r(12, 1), fault)
    status_item:prepend_text("HW5 fault byte: ")
    local names = {}
    for bit, name in ipairs(HW5_FAULTS) do
        status_item:add(hw5_bits[bit], r(12, 1))
        if math.floor(fault / 2 ^ (bit - 1)) % 2 == 1 then names[#names + 1] = name[1] end
    end
    local faults = table.concat(names, ",")
    tree:add(f.faults, r(12, 1), #names > 0 and faults or "none")
    if #names > 0 then
        status_item:append_text(" (" .. faults .. ")")
        status_item:add_proto_expert_info(ef.fault, "ESC fault: " .. faults)
    end
    local erpm = r(13, 2):le_uint() * 10
    quantity(tree, f.erpm, r(13, 2), erpm, "Electrical RPM", "rev/min")
    rpm_item(tree, r(13, 2), erpm)
    local volts = r(15, 2):le_uint() / 10
    quantity(tree, f.voltage, r(15, 2), volts, "Input voltage", "V")
    local amps = r(17, 2):le_uint() / 10
    quantity(tree, f.current, r(17, 2), amps, "Input current", "A")
    quantity(tree, f.mos_temp, r(19, 1), r(19, 1):uint(), "ESC (MOSFET) temperature", "\194\176C")
    quantity(tree, f.bec_temp, r(20, 1), r(20, 1):uint(), "BEC temperature", "\194\176C")
    quantity(tree, f.motor_temp, r(21, 1), r(21, 1):uint(), "Motor temperature", "\194\176C")
    quantity(tree, f.bec_voltage, r(22, 1), r(22, 1):uint() / 10, "BEC voltage", "V")
    quantity(tree, f.bec_current, r(23, 1), r(23, 1):uint() / 10, "BEC current", "A")
    return string.format("%.1f V %.1f A %d%% eRPM %d %d\194\176C%s", volts, amps, throttle, erpm,
        r(19, 1):uint(), #names > 0 and (" FAULT " .. faults) or "")
end

-- Adds the time of a frame's first byte: that of the first byte of the packet it is in (or,
-- reassembled, of the packet where it began), plus a byte time per byte before it (10 bits at
-- the baud rate).
local function add_time(subtree, r, when)
    local ns = math.floor(when.k * when.byte_s * 1e9 + 0.5)
    local offset = NSTime(math.floor(ns / 1e9), ns % 1e9)
    local time = when.epoch + offset
    subtree:add(f.time, r(0, 1), time):set_generated()
    subtree:add(f.time_epoch, r(0, 1), time):set_generated()
end

-- Adds one frame of the other formats (V4, V3, HW5) found at `r`.
local function other_frame(item, r, tree, when)
    local kind = item.kind
    local subtree = tree:add(hwfoc, r, kind.name)
    subtree:add(f.kind, r, kind.kind)
    subtree:add(f.protocol, r(0, 1), kind.proto):set_generated()
    add_time(subtree, r, when)
    local summary
    if kind == V4_DATA or kind == V4_DATA_SLOW then
        summary = v4_data(r, subtree)
    elseif kind == V4_INFO then
        summary = v4_info(r, subtree)
    elseif kind == V4_TRAILER then
        subtree:add(f.v4_trailer, r(0, 1))
        summary = "trailer of the data frame before (idle mode)"
    elseif kind == V3_DATA then
        summary = v3_data(r, subtree)
    else
        summary = hw5_data(r, subtree)
    end
    local good = item.what == "good"
    if kind.proto == "hw5" then
        local check_range = r(30, 2)
        local carried = check_range:le_uint()
        local computed = crc16_modbus(r:raw(), 0, 30)
        local check = subtree:add(f.checksum, check_range, carried)
        check:prepend_text("CRC-16/MODBUS: ")
        check:add(f.checksum_computed, check_range, computed):set_generated()
        check:add(f.checksum_status, check_range, (computed == carried) and 1 or 0):set_generated()
        if computed ~= carried then
            check:append_text(string.format(" [incorrect, should be 0x%04X]", computed))
            check:add_proto_expert_info(ef.bad_checksum, string.format(
                "Bad CRC: 0x%X carried, 0x%X computed", carried, computed))
        else
            check:append_text(" [correct]")
            local range = hw5_out_of_range(r:raw(), 0)
            if range then
                subtree:add_proto_expert_info(ef.out_of_range, "Out of range: " .. range ..
                    " (rejected by hwfoc, CRC notwithstanding)")
            end
        end
    else
        subtree:add(f.no_checksum, r, "none (" .. TITLES[kind.proto] .. " frames carry none: " ..
            "recognised by their lead byte, their length and the frames around them)"):set_generated()
    end
    if good then
        subtree:append_text(": " .. summary)
    else
        subtree:append_text(" [invalid, not decoded by hwfoc]: " .. summary)
    end
    return (good and "" or "BAD ") .. TITLES[kind.proto] .. " " .. kind.kind .. " " .. summary
end

-- Adds one frame (good or bad) found at `r`.
local function frame(item, r, tree, pinfo, when)
    local kind = item.kind
    if kind.proto ~= "hw-foc" then return other_frame(item, r, tree, when) end
    local len = kind.len
    local subtree = tree:add(hwfoc, r, kind.name)
    subtree:add(f.kind, r, kind.len == DATA_LEN and "data" or "info")
    subtree:add(f.protocol, r(0, 1), "hw-foc"):set_generated()
    add_time(subtree, r, when)
    subtree:add(f.sync, r(0, 1))
    subtree:add(f.length, r(1, 1))
    subtree:add(f.version, r(2, 1))
    local command = subtree:add(f.command, r(3, 1))
    if r(2, 1):uint() ~= 0x01 or r(3, 1):uint() ~= kind.command then
        command:add_proto_expert_info(ef.bad_header, string.format(
            "Version %d, command 0x%02X: a %s has version 1, command 0x%02X", r(2, 1):uint(),
            r(3, 1):uint(), kind.name:lower(), kind.command))
    end
    local summary
    if len == DATA_LEN then
        summary = data_frame(r, subtree)
    else
        summary = info_frame(r, subtree)
    end
    local bytes = r:bytes()
    local computed, carried, check_range
    if len == DATA_LEN then
        local s = r:raw()
        computed = sum(s, 0, 22) % 65536
        check_range = r(22, 2)
        carried = check_range:le_uint()
    else
        local s = r:raw()
        computed = sum(s, 0, 76) % 256
        check_range = r(76, 1)
        carried = check_range:uint()
    end
    local good = item.what == "good"
    local check = subtree:add(f.checksum, check_range, carried)
    check:add(f.checksum_computed, check_range, computed):set_generated()
    check:add(f.checksum_status, check_range, (computed == carried) and 1 or 0):set_generated()
    if computed ~= carried then
        check:append_text(string.format(" [incorrect, should be 0x%0" ..
            (len == DATA_LEN and "4" or "2") .. "X]", computed))
        check:add_proto_expert_info(ef.bad_checksum, string.format(
            "Bad checksum: 0x%X carried, 0x%X computed", carried, computed))
    else
        check:append_text(" [correct]")
        local range = len == DATA_LEN and foc_out_of_range(r:raw(), 0)
        if range then
            subtree:add_proto_expert_info(ef.out_of_range, "Out of range: " .. range ..
                " (rejected by hwfoc, checksum notwithstanding)")
        end
    end
    if good then
        subtree:append_text(": " .. summary)
    else
        subtree:append_text(" [invalid, not decoded by hwfoc]: " .. summary)
    end
    return (good and "" or "BAD ") .. (len == DATA_LEN and "Data " or "Info ") .. summary
end

local fallback = nil

function hwfoc.dissector(tvb, pinfo, tree)
    local desc = f_iface_desc()
    local text = desc and tostring(desc.value)
    local ours = (text and (text:find("telemetry (hwfoc)", 1, true) or
        text:find("HW-FOC telemetry", 1, true))) or hwfoc.prefs.all_user0
    if not ours then
        if fallback then return fallback:call(tvb, pinfo, tree) end
        return Dissector.get("data"):call(tvb, pinfo, tree)
    end
    pinfo.cols.protocol = "HW-FOC"
    local n = tvb:len()
    if n == 0 then
        pinfo.cols.info = "(no bytes: a note)"
        return 0
    end
    local iface_field = f_iface_id()
    local iface = iface_field and iface_field.value or 0
    local number = pinfo.number
    local baud = desc and tonumber(tostring(desc.value):match("(%d+) baud")) or 19200
    local byte_s = 10 / baud
    local byte_ns = 10 * 1e9 / baud
    local epoch = f_epoch().value
    -- The receive time in seconds of byte `i` of this packet, computed as hwfoc computes it
    -- (`(t_ns + i * ns per byte) * 1e-9` in doubles), so that the silences of over a second are
    -- the ones hwfoc finds.
    local function byte_time(i)
        return ((epoch.secs * 1e9 + epoch.nsecs) + i * byte_ns) * 1e-9
    end

    -- The bytes of a frame begun in the previous packet of this port (first pass only; later
    -- passes use what the first one kept). A silence of over a second between that packet's
    -- last byte and this one's first ends such a frame, as it does in hwfoc's decoder.
    -- Carried bytes: where each packet they came from begins in them (`at`), that packet's
    -- time and how many of its bytes came before (`k`).
    local carry = { bytes = "", segs = {} }
    if not pinfo.visited then
        local p = pending[iface]
        if p and byte_time(0) - p.t_last <= SILENCE_S then carry = p end
        carry_of[number] = carry
    else
        carry = carry_of[number] or carry
    end
    local s = carry.bytes .. tvb:raw()
    local c = #carry.bytes
    local segs = {}
    for _, seg in ipairs(carry.segs) do segs[#segs + 1] = seg end
    segs[#segs + 1] = { at = c, epoch = epoch, k = 0 }
    -- The time of byte `i` of `s`, as {epoch, k}: k bytes after the first byte of a packet.
    local function when_of(i)
        local seg = segs[1]
        for _, candidate_seg in ipairs(segs) do
            if candidate_seg.at <= i then seg = candidate_seg end
        end
        return { epoch = seg.epoch, k = seg.k + i - seg.at, byte_s = byte_s }
    end
    local items, chain = scan(s, carry.chain)
    if not pinfo.visited then
        local last = items[#items]
        if last and last.what == "partial" and last.to - last.from < INFO_LEN then
            local first = when_of(last.from)
            local kept = { { at = 0, epoch = first.epoch, k = first.k } }
            for _, seg in ipairs(segs) do
                if seg.at > last.from then
                    kept[#kept + 1] = { at = seg.at - last.from, epoch = seg.epoch, k = seg.k }
                end
            end
            pending[iface] = { bytes = s:sub(last.from + 1), segs = kept, t_last = byte_time(n - 1),
                chain = chain }
        elseif chain then
            -- The last V4 or V3 frame ended the packet: the next packet's first frame may be the
            -- one after it.
            pending[iface] = { bytes = "", segs = {}, t_last = byte_time(n - 1), chain = chain }
        else
            pending[iface] = nil
        end
    end

    local root = tree:add(hwfoc, tvb(), "HW-FOC telemetry")
    local infos = {}
    local protos = {}
    local joined = nil
    for _, item in ipairs(items) do
        -- An item with bytes of this packet; or a frame wholly in earlier packets, which were
        -- left undecided there (the first V4 or V3 frame of a recording is a frame only if the
        -- next one follows it): shown here, reassembled, as decode reads it.
        if item.to > c or (item.what == "good" and item.from < c) then
            local when = when_of(item.from)
            local range
            if item.from >= c then
                range = tvb(item.from - c, item.to - item.from)
            else
                joined = joined or ByteArray.new(s, true):tvb("Reassembled HW-FOC frame")
                range = joined(item.from, item.to - item.from)
            end
            if item.what == "noise" then
                local it = root:add(f.noise, range)
                it:append_text(string.format(" (%d bytes)", item.to - item.from))
                it:add_proto_expert_info(ef.noise, string.format("%d bytes of line noise",
                    item.to - item.from))
                infos[#infos + 1] = string.format("Noise (%d bytes)", item.to - item.from)
            elseif item.what == "partial" then
                local it = root:add(f.partial, range)
                local what = item.kind and item.kind.name:lower() or "frame"
                it:append_text(string.format(
                    " (%d bytes of a %s: it continues in a later packet of this port)",
                    item.to - item.from, what))
                it:add_proto_expert_info(ef.partial, "Frame continues in a later packet")
                infos[#infos + 1] = "Partial frame"
            elseif item.what == "cut" then
                local it = root:add(f.partial, range)
                it:append_text(string.format(" (%d bytes of a %s, cut short by the next frame)",
                    item.to - item.from, item.kind.name:lower()))
                it:add_proto_expert_info(ef.cut)
                infos[#infos + 1] = "Cut frame"
            else
                protos[item.kind.proto] = true
                local info = frame(item, range, root, pinfo, when)
                if item.from < c then
                    root:add_proto_expert_info(ef.reassembled, string.format(
                        "%s begun in an earlier packet: %d of its bytes are in this one",
                        item.kind.name, item.to - c))
                end
                infos[#infos + 1] = info
            end
        end
    end
    pinfo.cols.info = table.concat(infos, "; ")
    -- The protocol column names the format of the packet's frames (HW-FOC when mixed or none).
    local only = nil
    for proto in pairs(protos) do
        only = (only == nil) and proto or false
    end
    if only then pinfo.cols.protocol = TITLES[only] end
    return n
end

local encap = DissectorTable.get("wtap_encap")
fallback = encap:get_dissector(wtap_encaps.USER0)
encap:add(wtap_encaps.USER0, hwfoc)

-- ---------------------------------------------------------------------------------------------
-- DroneCAN on CAN: Hobbywing's CAN ESCs (docs/HW5-AND-CAN.md, "Hobbywing DroneCAN ESCs"), as the
-- codec's `dronecan` module reads them (crates/hwfoc/src/dronecan/). Wireshark's own `can`
-- dissector reads the frames (LINKTYPE_CAN_SOCKETCAN captures); this is a heuristic
-- sub-dissector of it that takes every extended data frame with a tail byte that can be
-- DroneCAN's (a transfer's first frame has its toggle bit clear; a service names a source and a
-- destination node).

local dronecan = Proto("dronecan", "DroneCAN (hwfoc: Hobbywing CAN ESCs)")

local f_can_id = Field.new("can.id")
local f_can_xtd = Field.new("can.flags.xtd")
local f_can_rtr = Field.new("can.flags.rtr")
local f_can_err = Field.new("can.flags.err")

local HEALTH = { [0] = "OK", [1] = "Warning", [2] = "Error", [3] = "Critical" }
local MODE = { [0] = "Operational", [1] = "Initialization", [2] = "Maintenance",
    [3] = "Software update", [7] = "Offline" }
local BAUD = { [0] = "1 Mbit/s", [1] = "500 kbit/s", [2] = "250 kbit/s", [3] = "200 kbit/s",
    [4] = "100 kbit/s", [5] = "50 kbit/s" }
local DIRECTION = { [0] = "clockwise", [1] = "counter-clockwise", [255] = "query" }
local READ_WRITE = { [0] = "read", [1] = "write" }
local RATE = { [1] = "500 Hz", [2] = "250 Hz", [3] = "200 Hz", [4] = "100 Hz", [5] = "50 Hz",
    [6] = "20 Hz", [7] = "10 Hz", [8] = "1 Hz", [9] = "0 Hz (off)" }
local SOURCE = { [0] = "CAN", [1] = "PWM" }
local PASS_FAIL = { [0] = "pass", [1] = "fail" }

-- The data types: field lists as pydronecan 1.0.27 ships them (crates/hwfoc/src/dronecan/
-- types.rs), `prefix` the fields' filter names (dronecan.<prefix>.<DSDL field name in lower
-- case>), `sig` the data type signature (seeds a multi-frame transfer's CRC). A field is
-- { DSDL name, kind, bits, label, options }: kind "u" unsigned, "i" signed, "f16" float16,
-- "bool", "tail" (a last array of `bits`-bit unsigned elements, up to `max`, with no length on
-- the wire), "static" (an array of `n` elements). Options: vs (names of the values), div and
-- unit (shown as value / div in unit), unit, hex.
local function fld(name, kind, bits, label, opts)
    opts = opts or {}
    opts.name, opts.kind, opts.bits, opts.label = name, kind, bits, label
    return opts
end
local HW_ESC = "com.hobbywing.esc."
local MESSAGES = {
    [20050] = { name = HW_ESC .. "StatusMsg1", sig = "0813B3E2C4AD670E", fields = {
        fld("rpm", "u", 16, "RPM (as the ESC reports it)", { unit = "rev/min" }),
        fld("pwm", "u", 16, "PWM (output throttle, nominally of 1000)"),
        fld("status", "u", 16, "Status", { hex = true }),
    } },
    [20051] = { name = HW_ESC .. "StatusMsg2", sig = "1675DA01C3B91297", fields = {
        fld("input_voltage", "i", 16, "Input voltage", { div = 10, unit = "V" }),
        fld("current", "i", 16, "Current", { div = 10, unit = "A" }),
        fld("temperature", "u", 8, "Temperature", { unit = "\194\176C" }),
    } },
    [20052] = { name = HW_ESC .. "StatusMsg3", sig = "24919CD1EB34ECE9", fields = {
        fld("MOS_T", "u", 8, "MOSFET temperature", { unit = "\194\176C" }),
        fld("CAP_T", "u", 8, "Capacitor temperature", { unit = "\194\176C" }),
        fld("Motor_T", "u", 8, "Motor temperature", { unit = "\194\176C" }),
    } },
    [20013] = { name = HW_ESC .. "GetEscID", sig = "0000000000004E2D", fields = {
        fld("payload", "tail", 8, "Payload byte", { max = 3 }),
    } },
    [341] = { name = "uavcan.protocol.NodeStatus", sig = "0F0868D0C1A7C6F1", fields = {
        fld("uptime_sec", "u", 32, "Uptime", { unit = "s" }),
        fld("health", "u", 2, "Health", { vs = HEALTH }),
        fld("mode", "u", 3, "Mode", { vs = MODE }),
        fld("sub_mode", "u", 3, "Sub-mode"),
        fld("vendor_specific_status_code", "u", 16, "Vendor-specific status code", { hex = true }),
    } },
    [1034] = { name = "uavcan.equipment.esc.Status", sig = "A9AF28AEA2FBB254", fields = {
        fld("error_count", "u", 32, "Error count"),
        fld("voltage", "f16", 16, "Voltage", { unit = "V" }),
        fld("current", "f16", 16, "Current", { unit = "A" }),
        fld("temperature", "f16", 16, "Temperature", { unit = "K" }),
        fld("rpm", "i", 18, "RPM", { unit = "rev/min" }),
        fld("power_rating_pct", "u", 7, "Power rating", { unit = "%" }),
        fld("esc_index", "u", 5, "ESC index"),
    } },
    [1036] = { name = "uavcan.equipment.esc.StatusExtended", sig = "02DC203C50960EDC", fields = {
        fld("input_pct", "u", 7, "Input (throttle received)", { unit = "%" }),
        fld("output_pct", "u", 7, "Output (to the motor)", { unit = "%" }),
        fld("motor_temperature_degC", "i", 9, "Motor temperature", { unit = "\194\176C" }),
        fld("motor_angle", "u", 9, "Motor angle", { unit = "\194\176" }),
        fld("status_flags", "u", 19, "Status flags (manufacturer-specific)", { hex = true }),
        fld("esc_index", "u", 5, "ESC index"),
    } },
}
local function u8(name, label, opts) return fld(name, "u", 8, label, opts) end
local SERVICES = {
    [210] = { name = HW_ESC .. "SetID", sig = "C323CB5E9EC2B6F7",
        request = { u8("node_id", "Node id"), u8("throttle_channel", "Throttle channel") },
        response = { u8("node_id", "Node id"), u8("throttle_channel", "Throttle channel") } },
    [211] = { name = HW_ESC .. "SetBaud", sig = "ADA98653B52DE435",
        request = { u8("baud", "Bit rate", { vs = BAUD }) }, response = {} },
    [212] = { name = HW_ESC .. "SetLED", sig = "B493BD48C0853EE5",
        request = { u8("option", "Option (1 = save)"), u8("color", "Colour (R = 4, G = 2, B = 1)"),
            u8("blink", "Blink (0 = off)") },
        response = { u8("option", "Option (1 = save)"), u8("color", "Colour (R = 4, G = 2, B = 1)"),
            u8("blink", "Blink (0 = off)") } },
    [213] = { name = HW_ESC .. "SetDirection", sig = "9D793111D262BA68",
        request = { u8("direction", "Direction", { vs = DIRECTION }) },
        response = { u8("direction", "Direction", { vs = DIRECTION }) } },
    [214] = { name = HW_ESC .. "SetReportingFrequency", sig = "1FD0404420983DEB",
        request = { u8("option", "Option", { vs = READ_WRITE }),
            fld("MSG_ID", "u", 16, "Message (data type id)"), u8("rate", "Rate", { vs = RATE }) },
        response = { u8("option", "Option", { vs = READ_WRITE }),
            fld("MSG_ID", "u", 16, "Message (data type id)"), u8("rate", "Rate", { vs = RATE }) } },
    [215] = { name = HW_ESC .. "SetThrottleSource", sig = "0C248FAAEFE5E29A",
        request = { u8("source", "Throttle source", { vs = SOURCE }) },
        response = { u8("source", "Throttle source", { vs = SOURCE }) } },
    [216] = { name = HW_ESC .. "SelfTest", sig = "C48D4DE61C5295DF",
        request = {}, response = { u8("status", "Self-test", { vs = PASS_FAIL }) } },
    [217] = { name = HW_ESC .. "SetAngle", sig = "81D9B10761C28E0A",
        request = { u8("option", "Option"), fld("angle", "u", 16, "Angle") },
        response = { u8("option", "Option"), fld("angle", "tail", 16, "Angle", { max = 2 }) } },
    [241] = { name = HW_ESC .. "GetMaintenanceInformation", sig = "B81DBD4EC9A5977D",
        request = { u8("option", "Option (1 = clear)") },
        response = { fld("total_rotation_time_min", "u", 32, "Total rotation time", { unit = "min" }),
            fld("time_since_maintainence_min", "u", 24, "Time since maintenance", { unit = "min" }) } },
    [242] = { name = HW_ESC .. "GetMajorConfig", sig = "1506774DA3930BFD",
        request = { u8("option", "Option") },
        response = { fld("direction", "bool", 1, "Direction counter-clockwise"),
            fld("throttle_source", "bool", 1, "Throttle source PWM"),
            fld("throttle_channel", "u", 6, "Throttle channel"),
            fld("led_status", "u", 5, "LED status"), fld("led_color", "u", 3, "LED colour"),
            fld("MSG2_rate", "u", 4, "StatusMsg2 rate"), fld("MSG1_rate", "u", 4, "StatusMsg1 rate"),
            fld("positioning_angle", "u", 16, "Positioning angle"),
            fld("reserved", "static", 8, "Reserved", { n = 2, hex = true }) } },
}

local KIND_NAMES = { message = "Message", anonymous = "Anonymous message",
    request = "Service request", response = "Service response" }
local CRC_STATUS = { [0] = "bad", [1] = "ok" }
local df = {
    priority = ProtoField.uint8("dronecan.priority", "Priority"),
    type_id = ProtoField.uint16("dronecan.type_id", "Data type id"),
    type_name = ProtoField.string("dronecan.type_name", "Data type"),
    kind = ProtoField.string("dronecan.kind", "Transfer (message, anonymous, request, response)"),
    source = ProtoField.uint8("dronecan.source", "Source node"),
    destination = ProtoField.uint8("dronecan.destination", "Destination node"),
    discriminator = ProtoField.uint16("dronecan.discriminator", "Discriminator (anonymous)",
        base.HEX),
    tail = ProtoField.uint8("dronecan.tail", "Tail byte", base.HEX),
    tail_start = ProtoField.bool("dronecan.tail.start", "Start of transfer", 8, nil, 0x80),
    tail_end = ProtoField.bool("dronecan.tail.end", "End of transfer", 8, nil, 0x40),
    tail_toggle = ProtoField.bool("dronecan.tail.toggle", "Toggle", 8, nil, 0x20),
    tail_tid = ProtoField.uint8("dronecan.tail.transfer_id", "Transfer id", base.DEC, nil, 0x1F),
    frame_index = ProtoField.uint8("dronecan.transfer.frame_index", "Frame of the transfer"),
    first_frame = ProtoField.framenum("dronecan.transfer.first_frame",
        "First frame of the transfer", base.NONE),
    frames = ProtoField.uint8("dronecan.transfer.frames", "Frames in the transfer"),
    length = ProtoField.uint8("dronecan.transfer.length", "Payload length (bytes)"),
    crc = ProtoField.uint16("dronecan.crc", "Transfer CRC", base.HEX),
    crc_computed = ProtoField.uint16("dronecan.crc.computed", "Transfer CRC computed", base.HEX),
    crc_status = ProtoField.uint8("dronecan.crc.status", "CRC", base.DEC, CRC_STATUS),
    payload = ProtoField.bytes("dronecan.payload", "Payload"),
    direction = ProtoField.string("dronecan.hobbywing.statusmsg1.direction",
        "Direction (status bit 14: CCW)"),
    escid_what = ProtoField.string("dronecan.hobbywing.getescid.what",
        "GetEscID (request for ids, answer)"),
    escid_node = ProtoField.uint8("dronecan.hobbywing.getescid.node_id", "Node id"),
    escid_channel = ProtoField.uint8("dronecan.hobbywing.getescid.throttle_channel",
        "Throttle channel"),
}

-- A type's filter-name prefix: hobbywing.<name> for com.hobbywing.esc.<Name>, esc.<name> for
-- uavcan.equipment.esc.<Name>, <name> for uavcan.protocol.<Name>.
local function type_prefix(name)
    local rest = name:match("^com%.hobbywing%.esc%.(.*)$")
    if rest then return "hobbywing." .. rest:lower() end
    rest = name:match("^uavcan%.equipment%.esc%.(.*)$")
    if rest then return "esc." .. rest:lower() end
    return name:match("([^.]*)$"):lower()
end

-- Each DSDL field's ProtoField (a service's request and response share one per name).
local dc_field_of = {}
local function make_field(prefix, spec)
    local abbr = "dronecan." .. prefix .. "." .. spec.name:lower()
    if not dc_field_of[abbr] then
        local pf
        if spec.kind == "f16" or spec.div then
            pf = ProtoField.double(abbr, spec.label)
        elseif spec.kind == "bool" then
            pf = ProtoField.bool(abbr, spec.label)
        elseif spec.kind == "i" then
            pf = (spec.bits <= 8 and ProtoField.int8 or spec.bits <= 16 and ProtoField.int16 or
                ProtoField.int32)(abbr, spec.label, base.DEC)
        else
            pf = (spec.bits <= 8 and ProtoField.uint8 or spec.bits <= 16 and ProtoField.uint16 or
                ProtoField.uint32)(abbr, spec.label, spec.hex and base.HEX or base.DEC, spec.vs)
        end
        dc_field_of[abbr] = pf
        df["field " .. abbr] = pf
    end
    spec.pf = dc_field_of[abbr]
end
-- Bits of the fields before a tail array, and the payload's length bounds in bytes.
local function layout(fields)
    local fixed, extra = 0, 0
    for _, spec in ipairs(fields) do
        if spec.kind == "tail" then
            extra = spec.bits * spec.max
        elseif spec.kind == "static" then
            fixed = fixed + spec.bits * spec.n
        else
            fixed = fixed + spec.bits
        end
    end
    return { fields = fields, fixed = fixed, min = math.ceil(fixed / 8),
        max = math.ceil((fixed + extra) / 8) }
end
for _, t in pairs(MESSAGES) do
    t.prefix = type_prefix(t.name)
    for _, spec in ipairs(t.fields) do make_field(t.prefix, spec) end
    t.message = layout(t.fields)
end
for _, t in pairs(SERVICES) do
    t.prefix = type_prefix(t.name)
    for _, form in ipairs({ "request", "response" }) do
        for _, spec in ipairs(t[form]) do make_field(t.prefix, spec) end
        t[form] = layout(t[form])
    end
end

local dc_fields = {}
for _, field in pairs(df) do dc_fields[#dc_fields + 1] = field end
dronecan.fields = dc_fields

local dce = {
    crc = ProtoExpert.new("dronecan.crc.bad", "Bad transfer CRC", expert.group.CHECKSUM,
        expert.severity.ERROR),
    length = ProtoExpert.new("dronecan.length.bad", "Payload length not the data type's",
        expert.group.MALFORMED, expert.severity.ERROR),
    orphan = ProtoExpert.new("dronecan.transfer.orphan",
        "Frame of a transfer whose earlier frames were not seen", expert.group.SEQUENCE,
        expert.severity.NOTE),
    toggle = ProtoExpert.new("dronecan.transfer.toggle", "Toggle bit out of sequence",
        expert.group.SEQUENCE, expert.severity.WARN),
    unknown = ProtoExpert.new("dronecan.type.unknown", "Data type not known to hwfoc",
        expert.group.UNDECODED, expert.severity.NOTE),
}
dronecan.experts = { dce.crc, dce.length, dce.orphan, dce.toggle, dce.unknown }

-- CRC-16/CCITT-FALSE (poly 0x1021) of the bytes of `s`, from `crc`.
local function crc16_ccitt(crc, s)
    for k = 1, #s do
        crc = bxor16(crc, s:byte(k) * 256)
        for _ = 1, 8 do
            local high = crc >= 0x8000
            crc = (crc * 2) % 65536
            if high then crc = bxor16(crc, 0x1021) end
        end
    end
    return crc
end
-- The CRC of a signature's 8 bytes, little-endian: where a transfer's CRC starts.
local function base_crc(t)
    if not t.base_crc then
        local bytes = {}
        for k = 8, 1, -1 do bytes[#bytes + 1] = string.char(tonumber(t.sig:sub(2 * k - 1, 2 * k), 16)) end
        t.base_crc = crc16_ccitt(0xFFFF, table.concat(bytes))
    end
    return t.base_crc
end

-- `width` bits at bit `pos` of `s` (DSDL: each byte most significant bit first, a field's
-- bytes little-endian, the last one its `width % 8` low bits).
local function get_bits(s, pos, width)
    local out, scale, left = 0, 1, width
    while left > 0 do
        local n = math.min(left, 8)
        local byte = 0
        for _ = 1, n do
            local b = s:byte(math.floor(pos / 8) + 1) or 0
            byte = byte * 2 + math.floor(b / 2 ^ (7 - pos % 8)) % 2
            pos = pos + 1
        end
        out = out + byte * scale
        scale, left = scale * 256, left - n
    end
    return out
end

-- The value of float16 bits (exact).
local function float16(h)
    local sign = h >= 0x8000 and -1 or 1
    local e, m = math.floor(h / 1024) % 32, h % 1024
    if e == 31 then return m == 0 and sign * math.huge or 0 / 0 end
    if e == 0 then return sign * m * 2 ^ -24 end
    return sign * (1 + m / 1024) * 2 ^ (e - 15)
end

-- Adds the fields of a payload (`p`, a Tvb or TvbRange, `s` its bytes) to `tree`; returns the
-- values by DSDL name and a summary.
local function decode_fields(layout_, p, s, tree)
    local values, parts = {}, {}
    local pos = 0
    local function range(at, width)
        local first = math.floor(at / 8)
        return p(first, math.floor((at + width - 1) / 8) - first + 1)
    end
    local function add(spec, raw, at, width)
        local r = range(at, width)
        local value, shown
        if spec.kind == "i" then
            value = raw >= 2 ^ (width - 1) and raw - 2 ^ width or raw
        elseif spec.kind == "f16" then
            value = float16(raw)
        elseif spec.kind == "bool" then
            value = raw == 1
        else
            value = raw
        end
        if spec.div then value = value / spec.div end
        if spec.kind == "bool" then
            shown = value and "yes" or "no"
        elseif spec.kind == "f16" or spec.div then
            shown = fmt(value)
        elseif spec.hex then
            shown = string.format("0x%0" .. math.ceil(width / 4) .. "X", value)
        else
            shown = string.format("%d", value)
        end
        if spec.vs and spec.vs[value] then shown = spec.vs[value] .. " (" .. shown .. ")" end
        if spec.unit then shown = shown .. " " .. spec.unit end
        local item = tree:add(spec.pf, r, value, spec.label .. ": " .. shown)
        if spec.div then item:append_text(string.format(" (raw %d)", raw >= 2 ^ (width - 1)
            and spec.kind == "i" and raw - 2 ^ width or raw)) end
        if spec.unit == "K" and value == value and math.abs(value) < math.huge then
            item:append_text(" (" .. fmt(value - 273.15) .. " \194\176C)")
        end
        return value, shown, item
    end
    for _, spec in ipairs(layout_.fields) do
        if spec.kind == "tail" or spec.kind == "static" then
            local n = spec.n or math.floor((#s * 8 - pos) / spec.bits)
            local list, shown = {}, {}
            for k = 1, n do
                local v, text = add(spec, get_bits(s, pos, spec.bits), pos, spec.bits)
                list[k], shown[k] = v, text
                pos = pos + spec.bits
            end
            values[spec.name] = list
            parts[#parts + 1] = spec.name .. " [" .. table.concat(shown, ", ") .. "]"
        else
            local v, shown, item = add(spec, get_bits(s, pos, spec.bits), pos, spec.bits)
            values[spec.name] = v
            values[spec.name .. " item"] = item
            parts[#parts + 1] = spec.name .. " " .. shown
            pos = pos + spec.bits
        end
    end
    return values, table.concat(parts, ", ")
end

-- What a type's decoded values add beyond their fields (returns a summary, or nil for the
-- fields' own).
local function type_extras(t, values, p, tree)
    if t.name == HW_ESC .. "StatusMsg1" then
        local ccw = math.floor(values.status / 0x4000) % 2 == 1
        values["status item"]:add(df.direction, p(4, 2), ccw and "CCW" or "CW")
            :append_text(ccw and " (counter-clockwise)" or " (clockwise)")
        return string.format("rpm %d, pwm %d, status 0x%04X (%s)", values.rpm, values.pwm,
            values.status, ccw and "CCW" or "CW")
    elseif t.name == HW_ESC .. "GetEscID" then
        local payload = values.payload
        if #payload == 1 and payload[1] == 0 then
            tree:add(df.escid_what, p, "request"):append_text(" for every ESC's node id and channel")
            return "request for ids"
        elseif #payload == 2 then
            tree:add(df.escid_what, p, "answer")
            tree:add(df.escid_node, p(0, 1))
            tree:add(df.escid_channel, p(1, 1))
            return string.format("answer: node %d, throttle channel %d", payload[1], payload[2])
        end
        if p then tree:add(df.escid_what, p, "other") else tree:add(df.escid_what, "other") end
    elseif t.name == HW_ESC .. "SetReportingFrequency" then
        local of = MESSAGES[values.MSG_ID]
        if of then values["MSG_ID item"]:append_text(" (" .. of.name .. ")") end
    end
    return nil
end

-- First pass over a file: the multi-frame transfers under way (by source, type, transfer kind
-- and destination) and, per frame, where it stands in its transfer.
local dc_partial = {}
local dc_frame = {}
function dronecan.init()
    dc_partial = {}
    dc_frame = {}
end

-- The fields of a 29-bit CAN id, or nil if it can be no DroneCAN id.
local function parse_id(id)
    local h = { priority = math.floor(id / 2 ^ 24) % 32, source = id % 128 }
    if math.floor(id / 128) % 2 == 1 then
        h.destination = math.floor(id / 256) % 128
        if h.source == 0 or h.destination == 0 then return nil end
        h.type_id = math.floor(id / 65536) % 256
        h.kind = math.floor(id / 32768) % 2 == 1 and "request" or "response"
    elseif h.source == 0 then
        h.kind = "anonymous"
        h.type_id = math.floor(id / 256) % 4
        h.discriminator = math.floor(id / 1024) % 16384
    else
        h.kind = "message"
        h.type_id = math.floor(id / 256) % 65536
    end
    return h
end

-- Where this frame stands in its transfer (first pass: worked out and kept; later passes: the
-- kept answer). Returns { single = true }, or { index, first, whole = payload with its CRC
-- when this frame ends the transfer }, or { orphan = reason }.
local function transfer_state(pinfo, h, tail, data)
    local kept = dc_frame[pinfo.number]
    if pinfo.visited and kept then return kept end
    local start, last = tail >= 0x80, math.floor(tail / 0x40) % 2 == 1
    local toggle, tid = math.floor(tail / 0x20) % 2 == 1, tail % 32
    local key = table.concat({ h.source, h.kind, h.type_id, h.destination or 0 }, ":")
    local state
    if start and last then
        state = { single = true }
    elseif start then
        dc_partial[key] = { bytes = { data }, tid = tid, toggle = false, first = pinfo.number }
        state = { index = 1, first = pinfo.number }
    else
        local p = dc_partial[key]
        if p and p.tid == tid and toggle ~= p.toggle then
            p.bytes[#p.bytes + 1] = data
            p.toggle = toggle
            state = { index = #p.bytes, first = p.first }
            if last then
                state.whole = table.concat(p.bytes)
                dc_partial[key] = nil
            end
        elseif p and p.tid == tid then
            state = { orphan = "toggle" }
            dc_partial[key] = nil
        else
            state = { orphan = "start" }
        end
    end
    dc_frame[pinfo.number] = state
    return state
end

local function dronecan_frame(tvb, pinfo, tree)
    local xtd, rtr, err, idf = f_can_xtd(), f_can_rtr(), f_can_err(), f_can_id()
    if not (xtd and xtd.value) or (rtr and rtr.value) or (err and err.value) or not idf then
        return false
    end
    local n = tvb:len()
    if n < 1 or n > 8 then return false end
    local h = parse_id(idf.value)
    if not h then return false end
    local tail = tvb(n - 1, 1):uint()
    local start, toggle = tail >= 0x80, math.floor(tail / 0x20) % 2 == 1
    if start and toggle then return false end
    local single = start and math.floor(tail / 0x40) % 2 == 1
    if h.kind == "anonymous" and not single then return false end

    local t, layout_
    if h.kind == "message" then
        t = MESSAGES[h.type_id]
        layout_ = t and t.message
    elseif h.kind ~= "anonymous" then
        t = SERVICES[h.type_id]
        layout_ = t and t[h.kind]
    end
    local short = t and t.name:match("([^.]*)$") or string.format("data type %d", h.type_id)
    pinfo.cols.protocol = "DroneCAN"
    local route = h.destination and string.format("%d \226\134\146 %d", h.source, h.destination) or
        string.format("node %d", h.source)
    local root = tree:add(dronecan, tvb(), "DroneCAN " .. KIND_NAMES[h.kind]:lower() .. " " ..
        (t and t.name or string.format("of unknown data type %d", h.type_id)) .. ", " .. route)
    root:add(df.priority, h.priority):set_generated()
    root:add(df.kind, h.kind):set_generated()
    root:add(df.type_id, h.type_id):set_generated()
    if t then
        root:add(df.type_name, t.name):set_generated()
    else
        root:add_proto_expert_info(dce.unknown, string.format(
            "Data type %d (%s) is not one hwfoc knows: its payload is shown undecoded", h.type_id,
            h.kind))
    end
    root:add(df.source, h.source):set_generated()
    if h.destination then root:add(df.destination, h.destination):set_generated() end
    if h.discriminator then root:add(df.discriminator, h.discriminator):set_generated() end
    local tail_item = root:add(df.tail, tvb(n - 1, 1))
    tail_item:add(df.tail_start, tvb(n - 1, 1))
    tail_item:add(df.tail_end, tvb(n - 1, 1))
    tail_item:add(df.tail_toggle, tvb(n - 1, 1))
    tail_item:add(df.tail_tid, tvb(n - 1, 1))

    local info = string.format("%s %s %s", short, h.kind ~= "message" and h.kind or "", route)
        :gsub("  ", " ")
    local state = transfer_state(pinfo, h, tail, tvb:raw(0, n - 1))

    -- The payload to decode: this frame's, or the transfer's it completes.
    local p, s
    if state.single then
        s = tvb:raw(0, n - 1)
        p = n > 1 and tvb(0, n - 1) or nil
    elseif state.orphan then
        local item = root:add(df.payload, tvb(0, n - 1))
        if state.orphan == "toggle" then
            item:add_proto_expert_info(dce.toggle,
                "Toggle bit not the alternate of the last frame's: the transfer is dropped")
        else
            item:add_proto_expert_info(dce.orphan,
                "Continues a transfer whose first frame was not seen")
        end
        pinfo.cols.info = info .. " (frame of a transfer not seen from its start)"
        return true
    else
        root:add(df.frame_index, state.index):set_generated()
        root:add(df.first_frame, state.first):set_generated()
        if not state.whole then
            root:add(df.payload, tvb(0, n - 1)):append_text(" (part of a multi-frame transfer)")
            pinfo.cols.info = string.format("%s (frame %d of a transfer)", info, state.index)
            return true
        end
        root:add(df.frames, state.index):set_generated()
        local whole = ByteArray.new(state.whole, true):tvb("Reassembled DroneCAN transfer")
        local carried = whole(0, 2):le_uint()
        local crc_item = root:add(df.crc, whole(0, 2), carried)
        local summary_crc
        if t then
            s = state.whole:sub(3)
            local computed = crc16_ccitt(base_crc(t), s)
            crc_item:add(df.crc_computed, whole(0, 2), computed):set_generated()
            local ok = computed == carried
            crc_item:add(df.crc_status, whole(0, 2), ok and 1 or 0):set_generated()
            if ok then
                crc_item:append_text(" [CRC ok]")
            else
                crc_item:append_text(string.format(" [CRC bad: 0x%04X computed]", computed))
                crc_item:add_proto_expert_info(dce.crc, string.format(
                    "Bad transfer CRC: 0x%04X carried, 0x%04X computed", carried, computed))
                summary_crc = "CRC bad"
            end
        else
            crc_item:append_text(" (not checked: the data type's signature is not known)")
        end
        if #state.whole > 2 then p = whole(2) end
        if summary_crc then
            if p then root:add(df.payload, p) end
            pinfo.cols.info = string.format("%s (%d frames): %s", info, state.index, summary_crc)
            return true
        end
    end

    local length = s and #s or (n - 1)
    root:add(df.length, length):set_generated()
    if not layout_ then
        if p then root:add(df.payload, p) end
        pinfo.cols.info = info
        return true
    end
    local fits = length >= layout_.min and length <= layout_.max
    for _, spec in ipairs(layout_.fields) do
        if spec.kind == "tail" and (length * 8 - layout_.fixed) % spec.bits ~= 0 then fits = false end
    end
    if not fits then
        local item = root:add(df.payload, p or tvb(0, 0))
        item:add_proto_expert_info(dce.length, string.format(
            "%d payload bytes: a %s %s has %s", length, t.name, h.kind,
            layout_.min == layout_.max and tostring(layout_.min) or
            string.format("%d to %d", layout_.min, layout_.max)))
        pinfo.cols.info = info .. ": bad length"
        return true
    end
    local body = root:add(dronecan, p or tvb(0, 0), short .. " " .. h.kind)
    local values, summary = decode_fields(layout_, p, s or "", body)
    summary = type_extras(t, values, p, body) or summary
    if summary ~= "" then
        body:append_text(": " .. summary)
        info = info .. ": " .. summary
    end
    pinfo.cols.info = info
    return true
end

dronecan:register_heuristic("can", dronecan_frame)
