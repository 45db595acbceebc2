//! `cargo gen-bindings`: rewrites include/kodawari.h and the C# bindings (bindings/csharp/NativeMethods.g.cs
//! and the Unity package's copies) from src/ffi/. `--header` or `--csharp` writes only that part.

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let only_header = args.iter().any(|a| a == "--header");
    let only_csharp = args.iter().any(|a| a == "--csharp");
    if let Some(unknown) = args.iter().find(|a| *a != "--header" && *a != "--csharp") {
        eprintln!("unknown argument {unknown}; usage: cargo gen-bindings [--header | --csharp]");
        std::process::exit(2);
    }
    let dir = kodawari_gen_bindings::crate_dir();

    if !only_csharp {
        let header = kodawari_gen_bindings::generate_header(&dir);
        let path = dir.join(kodawari_gen_bindings::HEADER_PATH);
        std::fs::write(&path, header).expect("write header");
        println!("wrote {}", path.display());
    }
    if !only_header {
        for (relative, text) in kodawari_gen_bindings::generate_csharp_outputs(&dir) {
            let path = dir.join(relative);
            std::fs::create_dir_all(path.parent().expect("parent")).expect("create C# output directory");
            std::fs::write(&path, text).expect("write C# bindings");
            println!("wrote {}", path.display());
        }
        for orphan in kodawari_gen_bindings::orphaned_unity_copies(&dir) {
            std::fs::remove_file(&orphan).expect("remove stale Unity copy");
            println!("removed {}", orphan.display());
        }
    }
}
