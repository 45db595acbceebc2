//! Builds the plain-C test harness in `tests/c/` with gcc against the cdylib cargo built for this test run,
//! runs it, and runs it again under valgrind (required when `KDW_REQUIRE_VALGRIND=1`, skipped with a note
//! when valgrind is not installed and not required).
//!
//! `cargo test --test c_harness -- --nocapture` shows the harness output.

#[path = "common/native.rs"]
mod native;

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

const MANIFEST_DIR: &str = env!("CARGO_MANIFEST_DIR");

/// `libkodawari.so` of this test run's profile and target directory (debug or release, wherever
/// `CARGO_TARGET_DIR` points), built by the shared helper in `tests/common/native.rs`.
fn library_path() -> PathBuf {
    let name = format!("{}kodawari{}", std::env::consts::DLL_PREFIX, std::env::consts::DLL_SUFFIX);
    let path = native::shared_library_dir().join(name);
    assert!(path.is_file(), "the cdylib {} was not built", path.display());
    path
}

fn c_sources() -> Vec<PathBuf> {
    let dir = Path::new(MANIFEST_DIR).join("tests").join("c");
    let mut sources: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("read {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|path| path.extension() == Some(OsStr::new("c")))
        .collect();
    sources.sort();
    assert!(!sources.is_empty(), "no C sources in {}", dir.display());
    sources
}

fn tool_available(tool: &str) -> bool {
    Command::new(tool).arg("--version").output().is_ok_and(|output| output.status.success())
}

/// Compiles the harness once per test process and returns the executable.
fn harness_binary() -> &'static Path {
    static BINARY: OnceLock<PathBuf> = OnceLock::new();
    BINARY.get_or_init(build_harness)
}

fn build_harness() -> PathBuf {
    compile_c(&c_sources(), "test_kodawari")
}

/// Compiles C sources with the harness's strict flags against the cdylib; returns the executable.
fn compile_c(sources: &[PathBuf], name: &str) -> PathBuf {
    assert!(
        tool_available("gcc"),
        "gcc not found on PATH: the C harness needs gcc (install it, e.g. `apt-get install gcc`)"
    );
    let library = library_path();
    let lib_dir = library.parent().expect("library directory").to_path_buf();
    let profile = lib_dir.file_name().and_then(OsStr::to_str).unwrap_or("profile");
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("c_harness-{profile}"));
    std::fs::create_dir_all(&out_dir).unwrap_or_else(|e| panic!("create {}: {e}", out_dir.display()));
    let binary = out_dir.join(name);

    let mut gcc = Command::new("gcc");
    gcc.args(["-std=c11", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O1", "-g"])
        .arg("-I")
        .arg(Path::new(MANIFEST_DIR).join("include"))
        .arg("-I")
        .arg(Path::new(MANIFEST_DIR).join("tests").join("c"))
        .args(sources)
        .arg("-o")
        .arg(&binary)
        .arg("-L")
        .arg(&lib_dir)
        .arg(format!("-Wl,-rpath,{}", lib_dir.display()))
        .args(["-lkodawari", "-lm"]);
    println!("C harness against {}", library.display());
    println!("$ {gcc:?}");
    let output = gcc.output().expect("run gcc");
    print_output(&output);
    assert!(output.status.success(), "gcc failed to build {name} ({})", output.status);
    binary
}

fn print_output(output: &Output) {
    print!("{}", String::from_utf8_lossy(&output.stdout));
    eprint!("{}", String::from_utf8_lossy(&output.stderr));
}

/// The harness's last stdout line must read `N passed, 0 failed` with N > 0; returns N.
fn assert_all_passed(stdout: &str) -> u32 {
    let last = stdout.lines().last().unwrap_or("").trim();
    let parsed = last.strip_suffix(" passed, 0 failed").and_then(|n| n.parse::<u32>().ok());
    match parsed {
        Some(n) if n > 0 => n,
        _ => panic!("the C harness did not report `N passed, 0 failed` (N > 0); last line: {last:?}"),
    }
}

#[test]
fn c_harness_passes() {
    let binary = harness_binary();
    let output = Command::new(binary).output().unwrap_or_else(|e| panic!("run {}: {e}", binary.display()));
    print_output(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let passed = assert_all_passed(&stdout);
    assert!(output.status.success(), "the C harness exited with {}", output.status);
    println!("C harness: {passed} tests passed");
}

#[test]
fn c_harness_is_clean_under_valgrind() {
    let required = std::env::var("KDW_REQUIRE_VALGRIND").is_ok_and(|v| v == "1");
    if !tool_available("valgrind") {
        assert!(
            !required,
            "KDW_REQUIRE_VALGRIND=1 but valgrind is not on PATH: install valgrind (e.g. `apt-get install valgrind`)"
        );
        println!("note: valgrind not found on PATH; skipping the valgrind run of the C harness");
        return;
    }
    let binary = harness_binary();
    let output = Command::new("valgrind")
        .args([
            "--error-exitcode=99",
            "--leak-check=full",
            "--errors-for-leak-kinds=definite,indirect,possible",
            "--show-leak-kinds=definite,indirect,possible",
        ])
        .arg(binary)
        .output()
        .expect("run valgrind");
    print_output(&output);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let passed = assert_all_passed(&stdout);
    assert!(output.status.success(), "the C harness under valgrind exited with {}", output.status);
    assert!(stderr.contains("ERROR SUMMARY: 0 errors"), "valgrind reported errors");
    println!("C harness under valgrind: {passed} tests passed, no errors, no leaks");
}

/// The C quick start quoted in the README compiles with the strict flags, runs, and is quoted verbatim.
#[test]
fn readme_quick_start_compiles_runs_and_is_quoted_verbatim() {
    let source = Path::new(MANIFEST_DIR).join("examples").join("c").join("quickstart.c");
    let binary = compile_c(std::slice::from_ref(&source), "quickstart");
    let output = Command::new(&binary).output().unwrap_or_else(|e| panic!("run {}: {e}", binary.display()));
    print_output(&output);
    assert!(output.status.success(), "the quick start exited with {}", output.status);
    let frames = String::from_utf8_lossy(&output.stdout).lines().filter(|l| l.starts_with("frame")).count();
    assert_eq!(frames, 5, "the quick start prints one line per 60 frames");
    let text = std::fs::read_to_string(&source).unwrap();
    let readme = std::fs::read_to_string(Path::new(MANIFEST_DIR).join("README.md")).unwrap();
    assert!(readme.contains(&text), "README.md must quote examples/c/quickstart.c verbatim");
}
