#!/usr/bin/env bash
# Runs every fuzz target (cargo fuzz, libFuzzer; nightly Rust) for RUNS executions each (default
# 1000000), seeded from the project's own fixture files, and prints each target's count. A
# finding (panic, hang over TIMEOUT s, memory over RSS_MB) stops that target and is saved under
# fuzz/artifacts/<target>/; keep it under fuzz/regressions/<target>/ once fixed.
#
#   fuzz/run.sh                   # every target, 10^6 executions each
#   RUNS=20000 fuzz/run.sh chunk_decode world_file
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS="${RUNS:-1000000}"
TIMEOUT="${TIMEOUT:-1}"
RSS_MB="${RSS_MB:-2048}"
TARGETS=("$@")
if [ ${#TARGETS[@]} -eq 0 ]; then
  TARGETS=(chunk_decode dem_netcdf dem_geotiff dem_png pmcdem world_file http_request)
fi
command -v cargo-fuzz >/dev/null || { echo "needs cargo-fuzz: cargo install cargo-fuzz" >&2; exit 2; }
rustup toolchain list | grep -q nightly || { echo "needs nightly Rust: rustup toolchain install nightly" >&2; exit 2; }

# the seeds: the fixtures the tests use, a world made by `pmc edit`, requests of the HTTP API
F=crates/pmc-dem/tests/fixtures
mkdir -p fuzz/corpus/{chunk_decode,dem_netcdf,dem_geotiff,dem_png,pmcdem,world_file,http_request}
cp -f viewer/test/fixtures/chunk-v1.bin fuzz/corpus/chunk_decode/
cp -f "$F/etopo60.cdf" fuzz/corpus/dem_netcdf/
cp -f "$F"/etopo5deg_*.tif fuzz/corpus/dem_geotiff/
cp -f "$F/etopo5deg.png" fuzz/corpus/dem_png/
cp -f "$F/etopo60_l6_v1.pmcdem" fuzz/corpus/pmcdem/
if [ ! -f fuzz/corpus/world_file/seed.pmcw ]; then
  PMC="${PMC_BIN:-target/release/pmc}"
  [ -x "$PMC" ] || cargo build --release -q -p pmc-cli --bin pmc
  tmp=$(mktemp -d)
  "$PMC" edit --world "$tmp/w.pmcw" --n-c 2 --n-t 8 add --at 0,0 --radius 3 >/dev/null
  "$PMC" edit --world "$tmp/w.pmcw" paint --at 1,1 --radius 2 --material snow >/dev/null
  "$PMC" edit --world "$tmp/w.pmcw" --undo >/dev/null
  cp "$tmp/w.pmcw" fuzz/corpus/world_file/seed.pmcw
  rm -rf "$tmp"
fi
h=fuzz/corpus/http_request
printf '\x00x=0&y=100&z=0&range=40&level=1' > "$h/chunks"
printf '\x01top/0/1/1/1?seams=5&priority=2' > "$h/chunk"
printf '\x02preset=moon&seed=18446744073709551615' > "$h/planet"
printf '\x03from=10,20&to=-5,30,2&clearance=1.8&max_slope=40&format=geojson' > "$h/path"
printf '\x04at=10,20&range=30&max_nodes=500' > "$h/navgrid"
printf '\x05\n{"brush":"paint","x":0,"y":100,"z":0,"radius":3,"strength":0.5,"material":"snow"}' > "$h/edit"
printf '\x06' > "$h/undo"
printf '\x07' > "$h/redo"
printf '\x08limit=3' > "$h/edits"
printf '\x09' > "$h/stats"
printf '\x0a\n{"chunks":[{"key":"top/0/1/1/1","seams":5,"priority":2},{"key":"north/1/0/0/0"}]}' > "$h/chunk-batch"

printf '%-14s %12s %10s %s\n' target executions seconds result
for t in "${TARGETS[@]}"; do
  log=$(mktemp)
  start=$(date +%s)
  if cargo +nightly fuzz run --sanitizer none -O "$t" "fuzz/corpus/$t" -- \
      -runs="$RUNS" -timeout="$TIMEOUT" -rss_limit_mb="$RSS_MB" -print_final_stats=1 >"$log" 2>&1; then
    result=ok
  else
    result="FINDING (see $log)"
  fi
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
  printf '%-14s %12s %10s %s\n' "$t" "$execs" "$(( $(date +%s) - start ))" "$result"
done
