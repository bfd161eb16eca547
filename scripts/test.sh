#!/usr/bin/env bash
# Runs every test of the project: formatting, lints, the Rust test suite, the Python package (its
# wheel built and tested with pytest), and the external checks of exported planets (Khronos glTF
# validator, trimesh). Installs what it needs on a fresh machine.
#
#   ./scripts/test.sh           every test (what CI runs)
#   ./scripts/test.sh --quick   the inner loop: formatting, lints, the viewer's unit tests, the
#                               Rust suite and the Python package; no exports, external validators
#                               or browser tests
set -euo pipefail
cd "$(dirname "$0")/.."

QUICK=0
for arg in "$@"; do
  case "$arg" in
    --quick) QUICK=1 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "test.sh: unknown option $arg (--quick, --help)" >&2; exit 2 ;;
  esac
done

# Each step says when it starts, counted from the start of the suite (bash's SECONDS).
elapsed() { printf '%d min %02d s' $((SECONDS / 60)) $((SECONDS % 60)); }
step() { printf '\n==> %s (at %s)\n' "$*" "$(elapsed)"; }

step "install external validators"
if [ ! -d tools/gltf-validate/node_modules/gltf-validator ]; then
  (cd tools/gltf-validate && npm ci --no-audit --no-fund --loglevel=error)
fi
if [ ! -d tools/tiles-check/node_modules/@loaders.gl/3d-tiles ]; then
  (cd tools/tiles-check && npm ci --no-audit --no-fund --loglevel=error)
fi
if ! python3 -c "import trimesh, numpy" 2>/dev/null; then
  python3 -m pip install --quiet --disable-pip-version-check -r tools/requirements.txt
fi

# Runs the named functions side by side, each with its output in target/NAME.out, and prints
# each one's output, in the order given, once it and those before it are done; fails if any
# failed. The suite's steps that use less than the 2 cores of a small machine share them: the
# Rust tests alone keep 1.5 busy on average (some of their binaries end with one long test).
side_by_side() {
  local names=("$@") pids=() f i failed=()
  mkdir -p target
  for f in "$@"; do
    ( (set -euo pipefail; "$f") > "target/$f.out" 2>&1; rc=$?; elapsed > "target/$f.at"; exit $rc ) &
    pids+=($!)
  done
  for i in "${!pids[@]}"; do
    f=${names[$i]}
    if wait "${pids[$i]}"; then
      printf '\n--- %s: passed (at %s)\n' "$f" "$(cat "target/$f.at")"
    else
      printf '\n--- %s: FAILED (at %s)\n' "$f" "$(cat "target/$f.at")"
      failed+=("$f")
    fi
    cat "target/$f.out"
  done
  if [ ${#failed[@]} -gt 0 ]; then
    echo "test.sh: failed: ${failed[*]} (above)" >&2
    exit 1
  fi
}

# Cargo's own CARGO_TARGET_DIR is followed (a build directory shared between checkouts keeps the
# dependencies compiled).
TARGET_DIR="${CARGO_TARGET_DIR:-target}"
case "$TARGET_DIR" in /*) ;; *) TARGET_DIR="$PWD/$TARGET_DIR" ;; esac
mkdir -p "$TARGET_DIR"

# The Python package's virtual environment (maturin, numpy, pytest, dask, ...), made in the
# background while the Rust code builds: mostly downloads. Debian's python3 needs python3-venv.
if ! python3 -c "import ensurepip, venv" 2>/dev/null; then
  if [ "$(id -u)" = 0 ]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-venv
  else
    echo "the tests need Python's venv module: sudo apt-get install python3-venv" >&2
    exit 1
  fi
fi
VENV="$TARGET_DIR/python-venv"
(
  [ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check -r python/requirements-test.txt
) > "$TARGET_DIR/python-venv.log" 2>&1 &
VENV_JOB=$!

step "install the viewer's packages, CesiumJS, Chromium for its end-to-end tests, and the real Earth's data"
if [ ! -d viewer/node_modules ]; then
  (cd viewer && npm ci --no-audit --no-fund --loglevel=error)
fi
if [ ! -d examples/cesium/node_modules/cesium ]; then
  (cd examples/cesium && npm ci --no-audit --no-fund --loglevel=error)
fi
# Debian packages: chromium (the end-to-end tests), Mesa's EGL and software driver (llvmpipe, the
# WebGL of most steps: viewer/e2e/harness.mjs), ferret-datasets (NOAA's ETOPO5 and ETOPO20 relief,
# read by the data-kept tests) and xplanet-images (NASA's Visible Earth, the imagery tests and
# pictures).
missing=()
command -v chromium >/dev/null 2>&1 || missing+=(chromium)
ls /usr/lib/*/libEGL_mesa.so.0 >/dev/null 2>&1 || missing+=(libegl-mesa0)
ls /usr/lib/*/dri/swrast_dri.so >/dev/null 2>&1 || missing+=(libgl1-mesa-dri)
[ -f /usr/share/ferret-vis/data/etopo5.cdf ] || missing+=(ferret-datasets)
[ -f /usr/share/xplanet/images/earth.jpg ] || missing+=(xplanet-images)
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}"
  else
    echo "the tests need Debian's ${missing[*]}: sudo apt-get install ${missing[*]}" >&2
    exit 1
  fi
fi

lints() {
  cargo fmt --all -- --check
  # With the test profile, clippy and `cargo test` below share the build scripts, their outputs
  # (SQLite's C compiled once) and the procedural macros: about 50 s less on a cold build.
  cargo clippy --workspace --all-targets --locked --profile test -- -D warnings
}

viewer_tests() {
  cd viewer
  npx tsc --noEmit
  npm test
}

step "side by side: cargo fmt --check and cargo clippy, warnings denied (lints); the viewer's type check and unit tests (viewer_tests: tsc, vitest)"
side_by_side lints viewer_tests
VITEST=$(sed 's/\x1b\[[0-9;]*m//g' target/viewer_tests.out | awk '/^ *Tests +[0-9]+ passed/ { print $2 }' | tail -1)

step "viewer: build (embedded into pmc by the next step)"
(cd viewer && npm run --silent build)

step "cargo test: the build"
# pmc-bench holds the criterion benchmarks alone (no test; clippy above checks and lints them):
# leaving it out of the test build spares compiling criterion and the reference crates the
# benchmarks compare with (about a minute of one core).
cargo test --workspace --exclude pmc-bench --locked --no-run
# The pmc binary the CLI's tests run, built by `cargo test` with the test profile (optimised,
# viewer/dist embedded): the Python tests, the exports and the end-to-end tests below use it too,
# so the suite compiles the workspace once, not a second time for a release build.
PMC="$TARGET_DIR/debug/pmc"

step "Python package: the wheel (maturin)"
if ! wait "$VENV_JOB"; then
  cat "$TARGET_DIR/python-venv.log" >&2
  echo "test.sh: the Python virtual environment could not be made (above)" >&2
  exit 1
fi
# The development profile has the tests' settings (Cargo.toml), so the wheel's build reuses the
# crates `cargo test` compiled.
rm -rf "$TARGET_DIR/wheels"
"$VENV/bin/maturin" build --quiet --locked --out "$TARGET_DIR/wheels" -m python/Cargo.toml
"$VENV/bin/python" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps "$TARGET_DIR"/wheels/pmc-*.whl

# The tests' scratch files (std::env::temp_dir, tempfile) go to a directory of the build's,
# emptied at each run, rather than piling up in /tmp run after run.
SCRATCH="$TARGET_DIR/test-scratch"
rm -rf "$SCRATCH"
mkdir -p "$SCRATCH"

rust_tests() {
  TMPDIR="$SCRATCH" cargo test --workspace --exclude pmc-bench --locked
}

python_tests() {
  # From another directory, so that `import pmc` is the installed wheel, not the source folder.
  (cd "$TARGET_DIR" && PMC_BIN="$PMC" TMPDIR="$SCRATCH" "$VENV/bin/python" -m pytest "$OLDPWD/python/tests" -q -p no:cacheprovider)
}

OUT=target/test-artifacts
exports() {
  mkdir -p "$OUT"
  "$PMC" generate --quiet --preset sphere --n-c 4 --n-t 16 -o "$OUT/sphere.glb"
  "$PMC" generate --quiet --preset sphere --n-c 4 --n-t 16 -o "$OUT/sphere.ply"
  "$PMC" generate --quiet --preset earthlike --seed 7 -o "$OUT/earthlike.glb"
  "$PMC" generate --quiet --preset earthlike --seed 7 --n-c 4 -o "$OUT/earthlike.ply"
  "$PMC" generate --quiet --preset moon --seed 3 --n-c 4 -o "$OUT/moon.glb"
  "$PMC" generate --quiet --preset mars --seed 5 --n-c 4 -o "$OUT/mars.glb"
  node tools/gltf-validate/validate.mjs "$OUT/sphere.glb" "$OUT/earthlike.glb" "$OUT/moon.glb" "$OUT/mars.glb"
  # 3D Tiles: every tile content of a small planet's bake, by the same validator
  rm -rf "$OUT/tiles"
  "$PMC" tiles bake --quiet --preset moon --seed 3 --n-c 8 --n-t 16 -o "$OUT/tiles"
  find "$OUT/tiles/content" -name '*.glb' -print0 | xargs -0 node tools/gltf-validate/validate.mjs > "$OUT/tiles-validate.log"
  echo "gltf-validator: $(grep -c ': ok 0 errors' "$OUT/tiles-validate.log") tile contents valid"
  # The bake's tileset JSON against the 3D Tiles 1.1 schemas, loaded by loaders.gl (prints its summary)
  node tools/tiles-check/check.mjs "$OUT/tiles"

  # The sphere preset's radius: d_b + T/2 + 0.37 l_d with T = l_d n_t d_c.
  R=$(python3 -c "print(1744 + 4*16*2/2 + 0.37*4)")
  V=$(python3 -c "import math; print(4/3*math.pi*$R**3)")
  python3 tools/check_mesh.py "$OUT/sphere.ply" --expect-euler 2 --expect-volume "$V" --tolerance 0.005
  python3 tools/check_mesh.py "$OUT/earthlike.ply"
}

if [ "$QUICK" = 1 ]; then
  step "side by side: cargo test (rust_tests) and the Python package's tests (python_tests: pytest, a 2-worker Dask bake among them)"
  side_by_side rust_tests python_tests
else
  step "side by side: cargo test (rust_tests), the Python package's tests (python_tests: pytest, a 2-worker Dask bake among them), and planets exported and validated (exports: Khronos glTF validator, loaders.gl, trimesh)"
  side_by_side rust_tests python_tests exports
fi
PYTEST=$(awk '/ passed/ { for (i = 1; i < NF; i++) if ($(i + 1) ~ /^passed/) print $i }' target/python_tests.out | tail -1)

if [ "$QUICK" = 1 ]; then
  step "quick mode: exports, external validators and the end-to-end tests not run"
  awk -v ext="$((${VITEST:-0} + ${PYTEST:-0}))" '/^test result:/ { p += $4; f += $6 } END { printf "tests: %d passed, %d failed (quick)\n", p + ext, f }' target/rust_tests.out
  exit 0
fi

step "viewer: end-to-end tests in headless Chromium against pmc serve"
(cd viewer && PMC_BIN="$PMC" node e2e/run.mjs 2>&1) | tee target/e2e.log

step "all checks passed"
# One closing line: the Rust suite's totals plus the external checks above (the validator run
# and the two trimesh checks, the tiles' validator run, the tiles' schema and loaders.gl check;
# any failure there has already stopped the script).
EXTERNAL_CHECKS=5
E2E=$(sed 's/\x1b\[[0-9;]*m//g' target/e2e.log | awk '/^e2e: [0-9]+ passed/ { print $2 }' | tail -1)
awk -v ext="$((EXTERNAL_CHECKS + ${VITEST:-0} + ${E2E:-0} + ${PYTEST:-0}))" '/^test result:/ { p += $4; f += $6 } END { printf "tests: %d passed, %d failed\n", p + ext, f }' target/rust_tests.out
