//! The shared library exports the C API and nothing else, and every exported function is in the header.

#[path = "common/native.rs"]
mod native;

use std::process::Command;

#[test]
fn only_kdw_symbols_are_exported_and_all_are_declared() {
    let library = native::shared_library_dir().join("libkodawari.so");
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
