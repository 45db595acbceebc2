//! Compile check of the Unity package (bindings/unity/) without Unity: stand-ins of the UnityEngine and
//! UnityEditor API surface the package uses (tests/unity-stubs/, real namespaces and signatures, no
//! behaviour) are compiled with `mcs`, then every Runtime script and every Editor script is compiled against
//! them, as Unity's two assemblies (Kodawari.Runtime with unsafe code, Kodawari.Editor referencing it).
//! The Runtime is compiled a second time with the iOS defines (`__Internal` library name).
//!
//! Needs `mcs` (Debian: `apt-get install -y mono-mcs mono-runtime`); without it this fails, unless
//! `KDW_SKIP_MONO=1` is set.

mod mono;

use std::path::Path;

#[test]
fn unity_package_compiles_against_the_unity_api_stubs() {
    let Some(tools) = mono::tools() else { return };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let package = root.join("bindings/unity");
    let stubs = root.join("tests/unity-stubs");
    let out = std::env::temp_dir().join(format!("kodawari-unity-compile-{}", std::process::id()));
    std::fs::create_dir_all(&out).expect("create output dir");

    let engine_stub = out.join("UnityEngine.dll");
    let editor_stub = out.join("UnityEditor.dll");
    let runtime = out.join("Kodawari.Runtime.dll");
    let runtime_ios = out.join("Kodawari.Runtime.iOS.dll");
    let editor = out.join("Kodawari.Editor.dll");
    mono::compile(
        &tools,
        &["-target:library", "-nowarn:0660,0661"],
        &[],
        &[stubs.join("UnityEngine.cs")],
        &engine_stub,
    );
    mono::compile(
        &tools,
        &["-target:library"],
        std::slice::from_ref(&engine_stub),
        &[stubs.join("UnityEditor.cs")],
        &editor_stub,
    );

    let runtime_sources = mono::cs_files_recursive(&package.join("Runtime"));
    assert!(
        runtime_sources.iter().any(|p| p.ends_with("Runtime/Native/NativeMethods.g.cs"))
            && runtime_sources.iter().any(|p| p.ends_with("Runtime/Kodawari/Engine.cs"))
            && runtime_sources.iter().any(|p| p.ends_with("Runtime/Engine.cs")),
        "the Runtime folder lacks the generated bindings, the C# layer copy or the Engine component"
    );
    let strict = ["-unsafe", "-target:library", "-warn:4", "-warnaserror"];
    mono::compile(&tools, &strict, std::slice::from_ref(&engine_stub), &runtime_sources, &runtime);
    let ios = ["-unsafe", "-target:library", "-define:UNITY_IOS", "-warnaserror"];
    mono::compile(&tools, &ios, std::slice::from_ref(&engine_stub), &runtime_sources, &runtime_ios);

    let editor_sources = mono::cs_files_recursive(&package.join("Editor"));
    assert!(!editor_sources.is_empty(), "no Editor scripts");
    mono::compile(
        &tools,
        &["-target:library", "-warn:4", "-warnaserror"],
        &[engine_stub, editor_stub, runtime],
        &editor_sources,
        &editor,
    );

    // Package layout a UPM import needs.
    for path in [
        "package.json",
        "Runtime/Kodawari.Runtime.asmdef",
        "Editor/Kodawari.Editor.asmdef",
        "Plugins/README.md",
        "Plugins/x86_64/Linux/.gitkeep",
        "Plugins/x86_64/Windows/.gitkeep",
        "Plugins/x86_64/macOS/.gitkeep",
        "Plugins/Android/arm64-v8a/.gitkeep",
        "Plugins/iOS/.gitkeep",
    ] {
        assert!(package.join(path).exists(), "bindings/unity/{path} is missing");
    }
    let asmdef = std::fs::read_to_string(package.join("Runtime/Kodawari.Runtime.asmdef")).unwrap();
    assert!(asmdef.contains("\"allowUnsafeCode\": true"), "the Runtime assembly needs unsafe code");
    let editor_asmdef = std::fs::read_to_string(package.join("Editor/Kodawari.Editor.asmdef")).unwrap();
    assert!(editor_asmdef.contains("\"includePlatforms\": [\"Editor\"]"), "the Editor assembly must be Editor-only");
    let _ = std::fs::remove_dir_all(&out);
    println!("Unity package compiled: {} Runtime and {} Editor scripts", runtime_sources.len(), editor_sources.len());
}
