#!/usr/bin/env bash
# Writes crates/sfmeval-wasm/js/report.d.ts, the npm package's TypeScript types of the
# `sfmeval.report/3` report (and dtu-report.d.ts, those of `sfmeval.dtu/1`; poses-report.d.ts, those of `sfmeval.poses/1`; eth3d-report.d.ts, those of `sfmeval.eth3d/1`; tnt-report.d.ts, those of `sfmeval.tanksandtemples/2`), from the core's Rust types (feature `ts`: ts-rs derives; the test
# `report::typescript` in crates/sfmeval/src/report.rs). With --check it writes nothing and fails
# when the committed file is not what the types generate (scripts/test.sh runs that).
# A debug build of the core alone (a few minutes from scratch).
set -euo pipefail
cd "$(dirname "$0")/.."
case "${1:-}" in
  --check) ;;
  "") export SFMEVAL_WRITE_REPORT_TYPES=1 ;;
  *) echo "usage: $0 [--check]" >&2; exit 2 ;;
esac
cargo test --locked -p sfmeval --features ts --lib report::typescript::report_types_are_the_committed_ones
# the poses report's (crates/sfmeval-wasm/js/poses-report.d.ts, importing the shared Note types)
cargo test --locked -p sfmeval --features ts --lib pose::poses_report::typescript::poses_report_types_are_the_committed_ones
# the DTU report's (crates/sfmeval-wasm/js/dtu-report.d.ts)
cargo test --locked -p sfmeval-dtu --features ts --lib report::typescript::dtu_report_types_are_the_committed_ones
# the ETH3D report's (crates/sfmeval-wasm/js/eth3d-report.d.ts)
cargo test --locked -p sfmeval-eth3d --features ts --lib report::typescript::eth3d_report_types_are_the_committed_ones
# the Tanks and Temples report's (crates/sfmeval-wasm/js/tnt-report.d.ts, importing the shared types)
cargo test --locked -p sfmeval-tnt --features ts --lib report::typescript::tnt_report_types_are_the_committed_ones
