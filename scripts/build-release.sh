#!/usr/bin/env bash
# The release build of every binary, example and test of the workspace (sfmeval,
# sfmeval-runner, bench_op, align_tool, the test executables) into target/release. Every
# release build the tests, the benchmark and the browser suite need goes through this one
# command: cargo resolves features per command, so `-p sfmeval-cli`, `-p sfmeval-runner` and
# `-p sfmeval --example bench_op` each compiled the shared crates again (and `--bins --examples`
# without `--tests` leaves some dev-dependency features out). This resolves the same features
# as `cargo test --workspace --release`, which then only runs.
set -euo pipefail
cd "$(dirname "$0")/.."
exec cargo build --release --locked --workspace --bins --examples --tests "$@"
