//! The shared library exports the C API and nothing else, and every exported function is in the header.

use std::path::PathBuf;
use std::process::Command;

/// `target/<profile>/`: the integration test binary lives in its `deps/` folder.
fn library_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test binary path");
    exe.parent().and_then(|deps| deps.parent()).expect("target profile dir").to_path_buf()
}

#[test]
fn only_kdw_symbols_are_exported_and_all_are_declared() {
    let library = library_dir().join("libkodawari.so");
    assert!(library.exists(), "{} not built", library.display());
    let output = Command::new("nm").args(["-D", "--defined-only"]).arg(&library).output().expect("run nm (binutils)");
    assert!(output.status.success());
    let listing = String::from_utf8_lossy(&output.stdout);
    let symbols: Vec<&str> = listing.lines().filter_map(|l| l.split_whitespace().nth(2)).collect();
    let foreign: Vec<&&str> = symbols.iter().filter(|s| !s.starts_with("kdw_")).collect();
    assert!(foreign.is_empty(), "non-kdw symbols exported: {foreign:?}");
    let header = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/include/kodawari.h")).unwrap();
    for symbol in &symbols {
        assert!(header.contains(&format!("{symbol}(")), "{symbol} is exported but not declared in the header");
    }
    assert!(symbols.len() >= 30, "expected the whole C API, found {} symbols", symbols.len());
    println!("{} exported symbols, all kdw_ and declared", symbols.len());
}
