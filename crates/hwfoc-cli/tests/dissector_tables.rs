//! The tables and formulas the Wireshark dissector (`wireshark/hwfoc.lua`) copies from the codec,
//! read from the Lua source and compared with the codec's own: the fault names of HW-FOC's
//! status word (with the fault table of `docs/PROTOCOL-NOTES.md`) and of HW5's fault byte, a
//! table for every format whose description has faults (names, and titles that say what the
//! description says), the ADC table of HW-FOC's temperatures, and the constants of V4's NTC
//! formula. The codec is the one source: a change there fails here until the copies follow.
//! (How the dissector shows what these tables give is checked through tshark in `wireshark.rs`.)

use std::path::Path;

use hwfoc::Protocol;

fn read(relative: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(relative);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn dissector() -> String {
    read("wireshark/hwfoc.lua")
}

/// The text of the Lua table `local NAME = { ... }` (between its braces).
fn lua_table<'a>(lua: &'a str, name: &str) -> &'a str {
    let start = lua
        .find(&format!("local {name} = {{"))
        .unwrap_or_else(|| panic!("hwfoc.lua has no table {name}"));
    let body = &lua[start..];
    let open = body.find('{').unwrap() + 1;
    let mut depth = 1;
    for (i, c) in body[open..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            _ => {}
        }
        if depth == 0 {
            return &body[open..open + i];
        }
    }
    panic!("hwfoc.lua: table {name} is not closed")
}

/// The first string of each `{ "name", "title" }` entry of a Lua table of faults, in order.
fn lua_fault_names(lua: &str, table: &str) -> Vec<String> {
    lua_table(lua, table)
        .lines()
        .filter_map(|line| line.trim().strip_prefix("{ \""))
        .map(|rest| rest.split('"').next().unwrap().to_string())
        .collect()
}

/// The names of a protocol's fault bits, bit 0 first, up to its last defined bit.
fn codec_fault_names(protocol: Protocol) -> Vec<String> {
    let names: Vec<Option<&str>> = (0..16).map(|bit| protocol.fault_name(bit)).collect();
    let defined = names.iter().rposition(Option::is_some).map_or(0, |i| i + 1);
    names[..defined]
        .iter()
        .map(|n| n.expect("fault bits are defined from bit 0 on").to_string())
        .collect()
}

/// The names of a document's fault table: rows `| BIT | `name` | ... |`, in order, from the
/// first row that names `first` to the end of that table.
fn document_fault_names(document: &str, first: &str) -> Vec<(u32, String)> {
    let text = read(&format!("../../docs/{document}"));
    let rows: Vec<&str> = text.lines().collect();
    let start = rows
        .iter()
        .position(|l| l.starts_with('|') && l.contains(&format!("`{first}`")))
        .unwrap_or_else(|| panic!("docs/{document}: no table row names `{first}`"));
    rows[start..]
        .iter()
        .take_while(|l| l.starts_with('|'))
        .map(|row| {
            let cells: Vec<&str> = row.split('|').map(str::trim).collect();
            let bit = cells[1]
                .parse()
                .unwrap_or_else(|_| panic!("docs/{document}: {row}"));
            (bit, cells[2].trim_matches('`').to_string())
        })
        .collect()
}

fn numbered(names: &[String]) -> Vec<(u32, String)> {
    (0..).zip(names.iter().cloned()).collect()
}

#[test]
fn the_dissectors_status_bits_are_the_codecs_fault_names() {
    let codec = codec_fault_names(Protocol::HwFoc);
    assert_eq!(codec.len(), 16);
    assert_eq!(lua_fault_names(&dissector(), "FAULTS"), codec);
    assert_eq!(
        document_fault_names("PROTOCOL-NOTES.md", &codec[0]),
        numbered(&codec)
    );
}

#[test]
fn the_dissectors_hw5_fault_bits_are_the_codecs_fault_names() {
    let codec = codec_fault_names(Protocol::Hw5);
    assert_eq!(codec.len(), 8);
    assert_eq!(lua_fault_names(&dissector(), "HW5_FAULTS"), codec);
}

/// Each `{ "name", "title" }` entry of a Lua table of faults, in order.
fn lua_faults(lua: &str, table: &str) -> Vec<(String, String)> {
    lua_table(lua, table)
        .lines()
        .filter_map(|line| line.trim().strip_prefix("{ \""))
        .map(|rest| {
            let mut quoted = rest.split('"').step_by(2);
            let name = quoted.next().unwrap().to_string();
            (name, quoted.next().unwrap_or_default().to_string())
        })
        .collect()
}

/// The words of `text`, in lower case (a hyphenated word is one: `start-up`).
fn words(text: &str) -> Vec<String> {
    text.split(|c: char| !c.is_alphanumeric() && c != '-')
        .filter(|w| !w.is_empty())
        .map(str::to_lowercase)
        .collect()
}

/// Whether the dissector's title of a fault says what the codec's description does: each of its
/// words is one of the description's (the title's `Reserved` is the description's `not
/// assigned`), so a title may drop a description's filler words but add or change none.
fn title_says(title: &str, description: &str) -> bool {
    let description = words(description);
    words(title)
        .iter()
        .flat_map(|w| match w.as_str() {
            "reserved" => vec!["not".to_string(), "assigned".to_string()],
            _ => vec![w.clone()],
        })
        .all(|w| description.contains(&w))
}

#[test]
fn every_described_fault_word_has_a_dissector_table_saying_its_descriptions() {
    let lua = dissector();
    let tables = ["FAULTS", "HW5_FAULTS"].map(|t| (t, lua_faults(&lua, t)));
    let mut with_faults = 0;
    for p in Protocol::ALL {
        let faults = p.description().faults;
        if faults.is_empty() {
            continue;
        }
        with_faults += 1;
        let names: Vec<&str> = faults.iter().map(|f| f.name).collect();
        let (table, entries) = tables
            .iter()
            .find(|(_, t)| t.iter().map(|(n, _)| n.as_str()).eq(names.iter().copied()))
            .unwrap_or_else(|| panic!("hwfoc.lua has no fault table of {p}'s bits {names:?}"));
        for ((name, title), fault) in entries.iter().zip(faults) {
            assert!(
                title_says(title, fault.description),
                "hwfoc.lua {table} {name}: {title:?} does not say the codec's {:?}",
                fault.description
            );
        }
    }
    // HW-FOC, DataLink (its hub records carry HW-FOC's status word) and HW5.
    assert_eq!(with_faults, 3);
}

#[test]
fn a_changed_description_fails_the_title_check() {
    assert!(title_says(
        "Input voltage too high",
        "input voltage is too high"
    ));
    assert!(title_says("Reserved (bit 3)", "not assigned (bit 3)"));
    assert!(!title_says(
        "Input voltage too high",
        "input voltage is too low"
    ));
    assert!(!title_says("Motor blocked", "motor locked"));
}

/// The integers of a Lua table of numbers.
fn lua_numbers(lua: &str, table: &str) -> Vec<u32> {
    lua_table(lua, table)
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap_or_else(|_| panic!("{table}: {s:?}")))
        .collect()
}

#[test]
fn the_dissectors_adc_table_is_the_codecs() {
    let lua = dissector();
    let codec: Vec<u32> = hwfoc::units::ADC_TABLE.iter().map(|&c| c.into()).collect();
    assert_eq!(lua_numbers(&lua, "ADC_TABLE"), codec);
    let bounds = format!(
        "local ADC_MAX, ADC_MIN = {}, {}\n",
        hwfoc::units::ADC_MAX,
        hwfoc::units::ADC_MIN
    );
    assert!(lua.contains(&bounds), "hwfoc.lua lacks {bounds:?}");
}

#[test]
fn the_dissectors_ntc_formula_has_the_codecs_constants() {
    let lua = dissector();
    let start = lua
        .find("local function ntc_celsius(adc)")
        .expect("hwfoc.lua has ntc_celsius");
    let function = &lua[start..start + lua[start..].find("\nend\n").unwrap()];
    let limit = hwfoc::v4::ADC_LIMIT;
    let expected = [
        format!("if adc == 0 or adc >= {limit} then return nil end"),
        format!(
            "local ratio = adc / ({limit} - adc) / {}",
            hwfoc::v4::NTC_R25_OVER_REFERENCE
        ),
        format!(
            "return 1 / (math.log(ratio) / {} + 1 / 298.15) - 273.15",
            hwfoc::v4::NTC_BETA
        ),
    ];
    for line in expected {
        assert!(function.contains(&line), "{function}\nlacks {line:?}");
    }
    // The codec's formula, with the constants the Lua text has (25 degC at R25).
    let t = hwfoc::v4::ntc_celsius(3377).unwrap();
    assert!((t - 25.0).abs() < 0.05, "{t}");
}

/// The value of the Lua constant `local NAME = VALUE` (an integer).
fn lua_constant(lua: &str, name: &str) -> u64 {
    let start = lua
        .find(&format!("local {name} = "))
        .unwrap_or_else(|| panic!("hwfoc.lua has no constant {name}"));
    let rest = &lua[start + format!("local {name} = ").len()..];
    let value = rest.split_whitespace().next().unwrap();
    value
        .parse()
        .unwrap_or_else(|e| panic!("hwfoc.lua: {name} = {value}: {e}"))
}

/// The physical ranges past which the codec rejects a frame whose checksum matched (issue 29):
/// the dissector rejects the same frames by the same limits.
#[test]
fn the_plausibility_ranges_are_the_codecs() {
    let lua = dissector();
    assert_eq!(
        lua_constant(&lua, "FOC_THROTTLE_MAX_RAW"),
        u64::from(hwfoc::foc::THROTTLE_MAX_RAW)
    );
    assert_eq!(
        lua_constant(&lua, "HW5_THROTTLE_MAX_PCT"),
        u64::from(hwfoc::hw5::THROTTLE_MAX_PCT)
    );
    assert_eq!(
        lua_constant(&lua, "HW5_VOLTAGE_MAX_RAW"),
        u64::from(hwfoc::hw5::VOLTAGE_MAX_RAW)
    );
}
