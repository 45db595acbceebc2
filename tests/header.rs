//! include/kodawari.h is generated and checked in; this fails when it no longer matches src/ffi/.

#[test]
fn checked_in_header_is_current() {
    let dir = kodawari_gen_bindings::crate_dir();
    let generated = kodawari_gen_bindings::generate_header(&dir);
    let checked_in =
        std::fs::read_to_string(dir.join(kodawari_gen_bindings::HEADER_PATH)).expect("read include/kodawari.h");
    assert!(generated == checked_in, "include/kodawari.h is stale: run `cargo gen-bindings` and commit the result");
}
