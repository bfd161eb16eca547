#!/usr/bin/env bash
# The main job: builds the viewer and the `pmc` binary (the viewer is embedded in it), then serves
# the default planet at http://127.0.0.1:8080/, editable, its edits kept in out/world.pmcw
# (created on first run; delete it to start over). Arguments replace that and go to `pmc serve`:
#   ./scripts/run.sh --preset mars --seed 3 --port 9000
#   ./scripts/run.sh --world my.pmcw
#   ./scripts/run.sh --dem earth.pmcdem    (a real planet: see pmc dem import)
#   ./scripts/run.sh --dem earth.pmcdem --imagery earth.pmcimg   (coloured: see pmc imagery import)
# The planet is also served as OGC 3D Tiles (/tiles/tileset.json), with the CesiumJS example page
# at http://127.0.0.1:8080/cesium/ (CesiumJS installed in examples/cesium).
set -euo pipefail
cd "$(dirname "$0")/.."

echo "==> building the viewer (viewer/dist)" >&2
(cd viewer && { [ -d node_modules ] || npm ci --no-audit --no-fund --loglevel=error; } && npm run --silent build)

echo "==> installing CesiumJS for the example page (examples/cesium)" >&2
(cd examples/cesium && { [ -d node_modules/cesium ] || npm ci --no-audit --no-fund --loglevel=error; })

echo "==> building pmc (release)" >&2
cargo build --release --locked --bin pmc

if [ $# -eq 0 ]; then
  mkdir -p out
  set -- --world out/world.pmcw
fi
exec target/release/pmc serve --cesium-js examples/cesium/node_modules/cesium/Build/Cesium "$@"
