-- hwfoc.lua: a Wireshark dissector for Hobbywing HW-FOC ESC telemetry recorded by hwfoc.
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
    [0x16] = { len = DATA_LEN, command = 0x02, name = "Data frame" },
    [0x4C] = { len = INFO_LEN, command = 0x01, name = "Device-information frame" },
}

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

-- The frames and noise in `s`: a list of items {kind, from, to, what} (0-based, `to` exclusive),
-- `what` one of "good", "bad", "cut" (a frame cut short by the next one), "partial" (cut by the
-- end of `s`) or "noise". Valid frames are those the hwfoc decoder finds in the same bytes.
local function scan(s)
    local n = #s
    local items = {}
    local noise_from = nil
    local function noise_to(i)
        if noise_from then
            items[#items + 1] = { from = noise_from, to = i, what = "noise" }
            noise_from = nil
        end
    end
    local i = 0
    while i < n do
        local kind, state = candidate(s, n, i)
        if state == "undecided" then
            noise_to(i)
            items[#items + 1] = { kind = kind, from = i, to = n, what = "partial" }
            return items
        elseif state == "good" then
            noise_to(i)
            items[#items + 1] = { kind = kind, from = i, to = i + kind.len, what = "good" }
            i = i + kind.len
        elseif state == "bad" then
            -- The decoder goes on at the next byte: a valid (or still arriving) frame that starts
            -- inside this one ends it.
            local whole = n - i >= kind.len
            local cut = nil
            for j = i + 1, math.min(i + kind.len, n) - 1 do
                local _, inner = candidate(s, n, j)
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
    return items
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

-- Adds one frame (good or bad) found at `r`.
local function frame(item, r, tree, pinfo, when)
    local kind = item.kind
    local len = kind.len
    local subtree = tree:add(hwfoc, r, kind.name)
    subtree:add(f.kind, r, kind.len == DATA_LEN and "data" or "info")
    -- Every frame this dissector reads is an ESC's own HW-FOC frame.
    subtree:add(f.protocol, r(0, 1), "hw-foc"):set_generated()
    -- Its first byte's time: that of the first byte of the packet it is in (or, reassembled, of
    -- the packet where it began), plus a byte time per byte before it (10 bits at the baud rate).
    local ns = math.floor(when.k * when.byte_s * 1e9 + 0.5)
    local offset = NSTime(math.floor(ns / 1e9), ns % 1e9)
    local time = when.epoch + offset
    subtree:add(f.time, r(0, 1), time):set_generated()
    subtree:add(f.time_epoch, r(0, 1), time):set_generated()
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
    local items = scan(s)
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
            pending[iface] = { bytes = s:sub(last.from + 1), segs = kept, t_last = byte_time(n - 1) }
        else
            pending[iface] = nil
        end
    end

    local root = tree:add(hwfoc, tvb(), "HW-FOC telemetry")
    local infos = {}
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
    return n
end

local encap = DissectorTable.get("wtap_encap")
fallback = encap:get_dissector(wtap_encaps.USER0)
encap:add(wtap_encaps.USER0, hwfoc)
