//! The fault-injection suite (issue 19; cases, classes and commands in `docs/reliability.md`).
//!
//! It lives in the root package because most cases are about the program a user runs: every case runs the
//! `bouncelab` binary under a timeout and checks its exit code, that its message names the file, frame or
//! field, that nothing panicked, and that nothing was lost (outputs compared with an uninterrupted run).
//! The property tests (`props.rs`) drive the libraries directly: frame decoding, `session.toml`/`clips.csv`
//! and `model.toml` parsing and the formula evaluator, with a fixed number of cases so the run is bounded.
//!
//! `cargo test --test faults` (part of `cargo test --workspace`).

mod cli;
mod common;
mod disk;
#[path = "../common/files.rs"]
mod files;
mod kills;
mod physics;
mod props;
mod session;
mod store;
