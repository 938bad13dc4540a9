-- hwfoc.lua: a Wireshark dissector for Hobbywing ESC telemetry recorded by hwfoc: HW-FOC frames,
-- and the older formats hwfoc reads (Platinum V4 data and info frames, Platinum V3 frames, HW5
-- telemetry frames; docs/OLDER-PROTOCOLS.md, docs/HW5-AND-CAN.md).
--
-- `hwfoc record` (and `hwfoc simulate -o FILE.pcapng`, and the monitor's recording) write pcapng
-- files with link type USER0 (147): each packet holds the raw bytes of one serial port (one
-- interface per port, described as "HW-FOC telemetry, 19200 baud 8N1"). Recordings written since
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
-- only takes packets of interfaces hwfoc described ("HW-FOC telemetry" in the interface
-- description); other USER0 packets go to the dissector that had USER0 before (the "User DLTs"
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
    ef.partial, ef.cut, ef.reassembled }

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
    local ours = (desc and tostring(desc.value):find("HW-FOC telemetry", 1, true)) or
        hwfoc.prefs.all_user0
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
        if item.to > c then
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
