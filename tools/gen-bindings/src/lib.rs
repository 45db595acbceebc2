//! Generates the C header from `src/ffi/` with cbindgen. Shared by the `gen-bindings` binary and the
//! staleness test, so both use the one configuration in `cbindgen.toml`.

use std::path::{Path, PathBuf};

/// The kodawari crate's root directory.
pub fn crate_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().expect("crate root")
}

/// The header text cbindgen generates for the crate at `crate_dir`.
pub fn generate_header(crate_dir: &Path) -> String {
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).expect("cbindgen.toml");
    // Parse only src/ffi/: the core's public items are not part of the C API.
    let bindings = cbindgen::Builder::new()
        .with_src(crate_dir.join("src/ffi/mod.rs"))
        .with_config(config)
        .generate()
        .expect("cbindgen failed to generate the header");
    let mut out = Vec::new();
    bindings.write(&mut out);
    String::from_utf8(out).expect("cbindgen writes UTF-8")
}

pub const HEADER_PATH: &str = "include/kodawari.h";
