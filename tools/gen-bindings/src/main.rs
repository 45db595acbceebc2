//! `cargo gen-bindings`: rewrites include/kodawari.h from src/ffi/.

fn main() {
    let dir = kodawari_gen_bindings::crate_dir();
    let header = kodawari_gen_bindings::generate_header(&dir);
    let path = dir.join(kodawari_gen_bindings::HEADER_PATH);
    std::fs::write(&path, header).expect("write header");
    println!("wrote {}", path.display());
}
