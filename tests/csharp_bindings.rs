//! The C# bindings: `bindings/csharp/NativeMethods.g.cs` (and its Unity copies) must match what
//! `cargo gen-bindings` generates from src/ffi/, and the C# tests in tests/csharp/ must pass under Mono
//! against the real shared library.
//!
//! Needs `mcs` and `mono` (Debian: `apt-get install -y mono-mcs mono-runtime`); without them the Mono test
//! fails, unless `KDW_SKIP_MONO=1` is set.

mod mono;
#[path = "common/native.rs"]
mod native;

use std::path::Path;
use std::process::Command;

#[test]
fn checked_in_csharp_bindings_are_current() {
    let dir = kodawari_gen_bindings::crate_dir();
    let mut stale = Vec::new();
    for (relative, generated) in kodawari_gen_bindings::generate_csharp_outputs(&dir) {
        let checked_in = std::fs::read_to_string(dir.join(&relative)).unwrap_or_default();
        if checked_in != generated {
            stale.push(relative);
        }
    }
    for orphan in kodawari_gen_bindings::orphaned_unity_copies(&dir) {
        stale.push(format!("{} (its original is gone)", orphan.display()));
    }
    assert!(stale.is_empty(), "stale C# bindings: {stale:?}: run `cargo gen-bindings` and commit the result");
}

/// Every function of the C header has a P/Invoke declaration (a second check on the generator).
#[test]
fn every_header_function_is_declared_in_csharp() {
    let dir = kodawari_gen_bindings::crate_dir();
    let header = std::fs::read_to_string(dir.join(kodawari_gen_bindings::HEADER_PATH)).expect("read header");
    let csharp = std::fs::read_to_string(dir.join(kodawari_gen_bindings::CSHARP_PATH)).expect("read C#");
    let mut functions = Vec::new();
    for line in header.lines().filter(|l| !l.trim_start().starts_with("//") && !l.starts_with('#')) {
        let mut rest = line;
        while let Some(start) = rest.find("kdw_") {
            let name: String = rest[start..].chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
            let after = &rest[start + name.len()..];
            if after.starts_with('(') && !functions.contains(&name) {
                functions.push(name.clone());
            }
            rest = after;
        }
    }
    assert!(functions.len() >= 30, "parsed only {} header functions", functions.len());
    let missing: Vec<&String> =
        functions.iter().filter(|f| !csharp.contains(&format!("EntryPoint = \"{f}\""))).collect();
    assert!(missing.is_empty(), "header functions without a C# declaration: {missing:?}");
    for constant in ["KDW_ABI_VERSION", "KDW_STATUS_OK", "KDW_STATUS_PANIC", "KDW_ANCHOR_OWN"] {
        assert!(csharp.contains(&format!(" {constant} = ")), "{constant} missing from the C# constants");
    }
    assert!(csharp.contains("#if UNITY_IOS && !UNITY_EDITOR") && csharp.contains("\"__Internal\""));
    assert!(!csharp.contains(" bool "), "no bool may cross the boundary");
    println!("{} header functions, all declared in {}", functions.len(), kodawari_gen_bindings::CSHARP_PATH);
}

#[test]
fn csharp_tests_pass_under_mono() {
    let Some(tools) = mono::tools() else { return };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let library_dir = native::shared_library_dir();
    let out_dir = native::profile_dir().join("csharp-tests");
    std::fs::create_dir_all(&out_dir).expect("create output dir");
    let exe = out_dir.join("kodawari-csharp-tests.exe");

    let mut sources = vec![root.join(kodawari_gen_bindings::CSHARP_PATH)];
    sources.extend(mono::cs_files(&root.join(kodawari_gen_bindings::CSHARP_LAYER_DIR)));
    sources.extend(mono::cs_files(&root.join("tests/csharp")));
    mono::compile(&tools, &["-unsafe", "-warn:4", "-warnaserror", "-target:exe"], &[], &sources, &exe);

    let output = Command::new(&tools.mono)
        .arg("--debug")
        .arg(&exe)
        .env("LD_LIBRARY_PATH", &library_dir)
        .output()
        .expect("run mono");
    let stdout = String::from_utf8_lossy(&output.stdout);
    println!("{stdout}");
    eprintln!("{}", String::from_utf8_lossy(&output.stderr));
    let last = stdout.lines().last().unwrap_or_default();
    assert!(output.status.success() && last.ends_with(" passed, 0 failed"), "C# tests failed: {last}");
}

/// README.md and bindings/csharp/README.md show exactly the snippet that tests/csharp/ReadmeSnippet.cs compiles and runs.
#[test]
fn readme_snippet_is_the_tested_one() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(root.join("tests/csharp/ReadmeSnippet.cs")).expect("read snippet");
    let marker = "// --- README snippet begin ---\n";
    let begin = source.find(marker).expect("begin marker") + marker.len();
    let end = source[begin..].find("        // --- README snippet end ---").expect("end marker") + begin;
    let snippet: String =
        source[begin..end].lines().map(|l| format!("{}\n", l.strip_prefix("        ").unwrap_or(l))).collect();
    for readme in ["README.md", "bindings/csharp/README.md"] {
        let text = std::fs::read_to_string(root.join(readme)).expect("read README");
        assert!(
            text.contains(&format!("```csharp\n{snippet}```")),
            "{readme} must show tests/csharp/ReadmeSnippet.cs's snippet verbatim:\n{snippet}"
        );
    }
}
