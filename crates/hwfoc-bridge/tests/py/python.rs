//! The Python that the tests with a Python receiver (pymavlink, pydronecan) run.
//!
//! Those tests are `#[ignore = "needs …"]`: `cargo test` lists them as ignored, with the reason,
//! and `.ci/mavlink.sh` and `.ci/dronecan.sh` run them with `--include-ignored`. Asked to run,
//! a test finds its Python here or fails saying how to get one: it never passes without having
//! run. Included by path from the tests of hwfoc-bridge and hwfoc-cli.

use std::process::{Command, Stdio};

/// A Python that imports `module`: the one the environment variable `var` names, else
/// `python3` from `PATH` if it has the module. Panics when there is none, naming `var` and
/// `script` (the CI script that makes one).
pub fn python_with(var: &str, module: &str, script: &str) -> String {
    let imports = |python: &str| {
        Command::new(python)
            .args(["-c", &format!("import {module}")])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    if let Some(python) = std::env::var_os(var) {
        let python = python.to_string_lossy().into_owned();
        assert!(
            imports(&python),
            "{var}={python} cannot import {module}: set {var} to a Python that has it \
             ({script} makes one)"
        );
        return python;
    }
    assert!(
        imports("python3"),
        "this test needs a Python with {module}: python3 has none; set {var} to one \
         ({script} makes one and runs this test)"
    );
    "python3".to_string()
}
