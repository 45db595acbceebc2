//! Placeholder: the performance benchmark is being written.
fn main() {}
