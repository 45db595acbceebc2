#![allow(dead_code)] // each test binary uses part of it
//! Finding and driving Mono (`mcs`, `mono`) for the C# and Unity compile tests.

use std::path::{Path, PathBuf};
use std::process::Command;

pub struct Tools {
    pub mcs: PathBuf,
    pub mono: PathBuf,
}

fn which(program: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path).map(|dir| dir.join(program)).find(|candidate| candidate.is_file())
}

/// `mcs` and `mono`, or `None` when `KDW_SKIP_MONO=1` and they are missing (a note is printed). Without them
/// and without the opt-out this panics: CI must install them.
pub fn tools() -> Option<Tools> {
    match (which("mcs"), which("mono")) {
        (Some(mcs), Some(mono)) => Some(Tools { mcs, mono }),
        _ if std::env::var("KDW_SKIP_MONO").is_ok_and(|v| v == "1") => {
            println!("note: mcs/mono not found and KDW_SKIP_MONO=1: skipping the C#/Unity checks");
            None
        }
        _ => panic!(
            "mcs and mono are required for the C# and Unity checks: install them with \
             `apt-get update && apt-get install -y mono-mcs mono-runtime` (or set KDW_SKIP_MONO=1 to skip)"
        ),
    }
}

/// The `.cs` files directly in `dir`, sorted.
pub fn cs_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("read {}: {e}", dir.display()))
        .map(|entry| entry.expect("dir entry").path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "cs"))
        .collect();
    files.sort();
    files
}

/// The `.cs` files anywhere under `dir`, sorted.
pub fn cs_files_recursive(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(current) = stack.pop() {
        for entry in std::fs::read_dir(&current).unwrap_or_else(|e| panic!("read {}: {e}", current.display())) {
            let path = entry.expect("dir entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|ext| ext == "cs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// Compiles `sources` with `mcs` to `out`; panics with the compiler's output on failure.
pub fn compile(tools: &Tools, flags: &[&str], references: &[PathBuf], sources: &[PathBuf], out: &Path) {
    let mut mcs = Command::new(&tools.mcs);
    mcs.args(flags).arg(format!("-out:{}", out.display()));
    for reference in references {
        mcs.arg(format!("-r:{}", reference.display()));
    }
    mcs.args(sources);
    let output = mcs.output().expect("run mcs");
    let text = format!("{}{}", String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
    assert!(output.status.success(), "mcs failed for {}:\n{text}", out.display());
    if !text.trim().is_empty() {
        println!("{text}");
    }
    println!("compiled {} ({} sources)", out.display(), sources.len());
}
