//! Compiles `c/hwfoc.h` (through `shim/shim.c`, and with `HWFOC_NO_FOC_INFO` through
//! `shim/noinfo.c`) with the `cc` crate, with the warnings the header promises to build clean
//! under made errors.

fn main() {
    // Read when the script runs, not when it was compiled: a target folder reused by another
    // checkout must compile that checkout's header.
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let header_dir = format!("{manifest}/../../c");
    println!("cargo:rerun-if-changed=shim/shim.c");
    println!("cargo:rerun-if-changed=shim/noinfo.c");
    println!("cargo:rerun-if-changed=shim/flat_out.h");
    // Relative to this crate, as cargo takes it: the watch follows the checkout.
    println!("cargo:rerun-if-changed=../../c/hwfoc.h");
    cc::Build::new()
        .file("shim/shim.c")
        .file("shim/noinfo.c")
        .include(&header_dir)
        .std("c99")
        .flag_if_supported("-Wall")
        .flag_if_supported("-Wextra")
        .flag_if_supported("-Wpedantic")
        .warnings_into_errors(true)
        .compile("hwfoc_c_shim");
}
