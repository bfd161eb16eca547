#!/usr/bin/env bash
# The main job: builds the viewer and the `pmc` binary (the viewer is embedded in it), then serves
# the default planet at http://127.0.0.1:8080/. Extra arguments go to `pmc serve`, e.g.
#   ./scripts/run.sh --preset mars --seed 3 --port 9000
set -euo pipefail
cd "$(dirname "$0")/.."

echo "==> building the viewer (viewer/dist)" >&2
(cd viewer && { [ -d node_modules ] || npm ci --no-audit --no-fund --loglevel=error; } && npm run --silent build)

echo "==> building pmc (release)" >&2
cargo build --release --locked --bin pmc

exec target/release/pmc serve "$@"
