//! Output names given once for every ESC: `{esc}` in a path or port name stands for the ESC's
//! index (`esc{esc}.bin` is `esc0.bin`, `esc1.bin`, ...), for files, ports and pseudo-terminals
//! alike.

/// `template` with `{esc}` replaced by the ESC's index.
pub fn expand(template: &str, esc: usize) -> String {
    template.replace("{esc}", &esc.to_string())
}
