//! The shared library as C hosts load it. `cargo test` leaves `libkodawari.so` in `deps/` only when it
//! happens to need it, so the tests that load it build it themselves (`cargo build --lib`), with the same
//! profile and target directory as the test binary, and use the copy in `target/<profile>/`.

use std::path::PathBuf;
use std::process::Command;
use std::sync::OnceLock;

/// `target/<profile>/`: integration test binaries live in its `deps/` folder.
pub fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test binary path");
    exe.parent().and_then(|deps| deps.parent()).expect("target profile dir").to_path_buf()
}

/// Builds the cdylib (once per test binary) and returns the directory holding `libkodawari.so`.
pub fn shared_library_dir() -> PathBuf {
    static BUILT: OnceLock<PathBuf> = OnceLock::new();
    BUILT
        .get_or_init(|| {
            let dir = profile_dir();
            let release = dir.file_name().is_some_and(|name| name == "release");
            let mut cargo = Command::new(env!("CARGO"));
            cargo.args(["build", "--quiet", "--lib", "-p", "kodawari", "--manifest-path"]);
            cargo.arg(concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml"));
            if release {
                cargo.arg("--release");
            }
            // Same target directory as this test binary, wherever CARGO_TARGET_DIR put it.
            cargo.env("CARGO_TARGET_DIR", dir.parent().expect("target dir"));
            let status = cargo.status().expect("run cargo build");
            assert!(status.success(), "cargo build --lib failed");
            let library = dir.join("libkodawari.so");
            assert!(library.exists(), "{} was not built", library.display());
            dir
        })
        .clone()
}
