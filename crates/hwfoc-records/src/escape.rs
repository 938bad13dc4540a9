//! Strings from inputs shown to a person: a recording's port names and comments, an ESC's
//! device-information text, a configuration's keys, whatever an error quotes.
//!
//! Such a string can hold control characters, and a terminal obeys them: a crafted recording
//! could clear the screen (`ESC [2J`), set the window title (`ESC ]0;…BEL`), or overwrite a
//! line it printed with `\r` to fake another. Every human text output shows those strings
//! through [`Escaped`], which writes control characters as escapes (`\x1b`, `\r`), so the text
//! a person reads is the text the file holds. Machine outputs (JSON, CSV, Arrow) keep the exact
//! string, escaped by their own format's rules.
//!
//! ```
//! use hwfoc_records::Escaped;
//!
//! let name = "tail\r\x1b[2Jfront";
//! assert_eq!(Escaped(name).to_string(), "tail\\r\\x1b[2Jfront");
//! assert_eq!(format!("[{:<6}]", Escaped("a\tb")), "[a\\tb  ]");
//! ```

use std::fmt::{self, Write};

/// A value shown with control characters escaped: `Escaped(name)` wherever `name` came from an
/// input and is printed for a person.
///
/// Escaped: the C0 and C1 controls and DEL (`\n`, `\r`, `\t`, `\x1b`, `\u{9b}`), and the
/// Unicode characters that reorder or break the lines around them (the bidirectional
/// overrides, embeddings and isolates, U+2028 and U+2029). Width and alignment (`{:<8}`) apply
/// to the escaped text. A backslash is shown as itself: the text is for reading (a Windows
/// port `\\.\COM3` stays as written), not for parsing back.
///
/// Written here rather than with `char::escape_debug`: that one also escapes quotes,
/// backslashes and every character without a glyph, which a port name or a comment shows as
/// written.
#[derive(Debug, Clone, Copy)]
pub struct Escaped<T>(pub T);

impl<T: fmt::Display> fmt::Display for Escaped<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if f.width().is_some() || f.precision().is_some() {
            let mut text = String::new();
            write!(Escaper(&mut text), "{}", self.0)?;
            return f.pad(&text);
        }
        write!(Escaper(f), "{}", self.0)
    }
}

/// Whether `c` is shown as an escape.
fn hidden(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{061C}'
                | '\u{200E}'
                | '\u{200F}'
                | '\u{2028}'
                | '\u{2029}'
                | '\u{202A}'..='\u{202E}'
                | '\u{2066}'..='\u{2069}'
        )
}

/// A writer that passes text on with the [`hidden`] characters escaped.
struct Escaper<W>(W);

impl<W: Write> Write for Escaper<W> {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        let mut rest = s;
        while let Some(at) = rest.find(hidden) {
            self.0.write_str(&rest[..at])?;
            let c = rest[at..].chars().next().unwrap_or_default();
            match c {
                '\n' => self.0.write_str("\\n")?,
                '\r' => self.0.write_str("\\r")?,
                '\t' => self.0.write_str("\\t")?,
                c if c.is_ascii() => write!(self.0, "\\x{:02x}", u32::from(c))?,
                c => write!(self.0, "\\u{{{:x}}}", u32::from(c))?,
            }
            rest = &rest[at + c.len_utf8()..];
        }
        self.0.write_str(rest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controls_are_escaped_and_the_rest_is_kept() {
        let cases = [
            ("/dev/ttyUSB0", "/dev/ttyUSB0"),
            ("\x1b[2Jclear", "\\x1b[2Jclear"),
            ("\x1b]0;title\x07", "\\x1b]0;title\\x07"),
            ("ok\rfake", "ok\\rfake"),
            ("two\nlines\ttab\0nul\x7f", "two\\nlines\\ttab\\x00nul\\x7f"),
            ("c1 \u{9b}2J", "c1 \\u{9b}2J"),
            ("bidi \u{202e}txt.exe", "bidi \\u{202e}txt.exe"),
            ("ünïcødé ✓ \\\\.\\COM3 \"q\"", "ünïcødé ✓ \\\\.\\COM3 \"q\""),
            ("", ""),
        ];
        for (raw, shown) in cases {
            assert_eq!(Escaped(raw).to_string(), shown, "{raw:?}");
            assert!(!Escaped(raw).to_string().chars().any(hidden));
        }
        // Any Display, and padding applies to the escaped text.
        assert_eq!(Escaped(format_args!("a{}b", '\x1b')).to_string(), "a\\x1bb");
        assert_eq!(format!("{:>6}|", Escaped("\r")), "    \\r|");
    }
}
