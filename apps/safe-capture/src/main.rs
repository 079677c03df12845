//! The safe-capture command-line tool.
fn main() {}
