#!/usr/bin/env bash
# Times Pinocchio's forward dynamics (aba; crba + nonLinearEffects; + Cholesky solve) on the
# scaling-study chains of codegen/tests/common/chain.rs. See README.md in this directory.
#
#   scripts/bench/pinocchio/run.sh OUT_DIR
#
# Makes (or reuses) a venv in OUT_DIR/venv, pip-installs Pinocchio from PyPI (the `pin`
# wheel, pinned below) and the Eigen headers (`cmeel-eigen`: the wheels ship Boost and
# Pinocchio's headers but not Eigen's), compiles aba_chain.cpp header-only with
# g++ -O3 -march=native -DNDEBUG, runs it and writes
#   OUT_DIR/pinocchio.csv        family,n,aba_ns,crba_nle_ns,crba_nle_solve_ns (wall clock)
#   OUT_DIR/pinocchio_cpu.csv    the same batches timed by the thread's CPU time
#   OUT_DIR/pinocchio_check.csv  aba's accelerations at one fixed state (%.17g)
#   OUT_DIR/pinocchio_env.txt    versions, flags, CPU, load and the time of each phase
#   OUT_DIR/build.log            the compiler's output
# Environment: PYTHON (default python3), CXX (default g++).
set -euo pipefail

PIN_VERSION=4.1.0        # Pinocchio (pin = Python bindings; libpinocchio = headers + library)
EIGEN_VERSION=3.4.1      # cmeel-eigen: Eigen headers (eigenpy's build dependency, >= 3.4.1)
BOOST_VERSION=1.90.0     # cmeel-boost: what pin 4.1.0 requires (~= 1.90.0)

if [[ $# -ne 1 ]]; then
  echo "usage: $0 OUT_DIR" >&2
  exit 2
fi
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
mkdir -p "$1"
OUT="$(cd "$1" && pwd)"
PYTHON="${PYTHON:-python3}"
CXX="${CXX:-g++}"
VENV="$OUT/venv"

now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }

# ---- 1. venv + wheels ----
t0=$(now)
if [[ ! -x "$VENV/bin/python" ]]; then
  echo "== creating $VENV"
  "$PYTHON" -m venv "$VENV"
fi
installed=$("$VENV/bin/python" -m pip show pin 2>/dev/null | awk '/^Version:/ { print $2 }' || true)
eigen_installed=$("$VENV/bin/python" -m pip show cmeel-eigen 2>/dev/null | awk '/^Version:/ { print $2 }' || true)
if [[ "$installed" != "$PIN_VERSION" || "$eigen_installed" != "$EIGEN_VERSION" ]]; then
  echo "== pip install pin==$PIN_VERSION cmeel-eigen==$EIGEN_VERSION cmeel-boost==$BOOST_VERSION"
  "$VENV/bin/python" -m pip install --disable-pip-version-check -q \
    "pin==$PIN_VERSION" "cmeel-eigen==$EIGEN_VERSION" "cmeel-boost==$BOOST_VERSION"
else
  echo "== reusing $VENV (pin $installed, cmeel-eigen $eigen_installed)"
fi
PY_PIN=$("$VENV/bin/python" -c 'import pinocchio; print(pinocchio.__version__)')
t1=$(now)

# ---- 2. headers: the cmeel prefix inside the venv's site-packages ----
SITE=$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
PREFIX="$SITE/cmeel.prefix"
INC="$PREFIX/include"
for header in pinocchio/config.hpp eigen3/Eigen/Core boost/version.hpp; do
  if [[ ! -f "$INC/$header" ]]; then
    echo "error: $INC/$header not found (the wheels' layout changed?)" >&2
    exit 1
  fi
done
HDR_PIN=$(sed -n 's/^# *define PINOCCHIO_VERSION "\(.*\)"/\1/p' "$INC/pinocchio/config.hpp")
HDR_EIGEN=$(awk '/#define EIGEN_(WORLD|MAJOR|MINOR)_VERSION/ { v = v (v ? "." : "") $3 } END { print v }' \
  "$INC/eigen3/Eigen/src/Core/util/Macros.h")
HDR_BOOST=$(sed -n 's/^#define BOOST_LIB_VERSION "\(.*\)"/\1/p' "$INC/boost/version.hpp")
echo "== headers: Pinocchio $HDR_PIN (Python module $PY_PIN), Eigen $HDR_EIGEN, Boost $HDR_BOOST"
echo "   under $INC"

# ---- 3. compile ----
# Header-only: PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION is left undefined, so every algorithm
# is instantiated in this translation unit at -O3 -march=native. The Boost.MPL/Fusion limits
# are the INTERFACE_COMPILE_DEFINITIONS of the pinocchio::pinocchio_headers CMake target:
# the joint variant has 25 alternatives, above Boost.MPL's default list limit of 20.
# -Wno-stringop-overread: GCC 12 false positives in Eigen's AVX-512 code (68 of them).
DEFS=(-DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30
      -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_FUSION_INVOKE_MAX_ARITY=12)
FLAGS=(-std=c++17 -O3 -march=native -DNDEBUG -Wno-stringop-overread)
MODE=header-only
BIN="$OUT/aba_chain"
STAMP_NEW=$( { cat "$HERE/aba_chain.cpp"; echo "${FLAGS[*]} ${DEFS[*]} $INC"; "$CXX" --version | head -1;
               echo "$HDR_PIN $HDR_EIGEN $HDR_BOOST"; } | sha256sum | cut -d' ' -f1)
t2=$(now)
if [[ -x "$BIN" && -f "$BIN.stamp" && "$(cat "$BIN.stamp")" == "$STAMP_NEW" ]]; then
  echo "== reusing $BIN (same source, flags, compiler and headers)"
  MODE=$(cat "$BIN.mode")
else
  rm -f "$BIN" "$BIN.stamp" "$BIN.mode"
  echo "== compiling header-only: $CXX ${FLAGS[*]} (about 2.5 min of CPU; log in $OUT/build.log)"
  if ! nice -n 10 "$CXX" "${FLAGS[@]}" "${DEFS[@]}" -I"$INC" -I"$INC/eigen3" \
       "$HERE/aba_chain.cpp" -o "$BIN" >"$OUT/build.log" 2>&1; then
    # Fallback: the wheel's explicitly instantiated library. Its Eigen objects were built
    # for generic x86-64 (16-byte alignment); -march=native can change Eigen's alignment and
    # hence the ABI, so the fallback compiles without it.
    echo "   header-only compilation failed (see $OUT/build.log); linking libpinocchio_default"
    MODE=linked
    FLAGS=(-std=c++17 -O3 -DNDEBUG -DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION)
    nice -n 10 "$CXX" "${FLAGS[@]}" "${DEFS[@]}" -I"$INC" -I"$INC/eigen3" \
      "$HERE/aba_chain.cpp" -o "$BIN" -L"$PREFIX/lib" -lpinocchio_default \
      -Wl,-rpath,"$PREFIX/lib" >>"$OUT/build.log" 2>&1
  fi
  echo "$STAMP_NEW" >"$BIN.stamp"
  echo "$MODE" >"$BIN.mode"
fi
if ldd "$BIN" | grep -q pinocchio; then MODE=linked; fi
t3=$(now)

# ---- 4. run ----
LOAD_BEFORE=$(cut -d' ' -f1-3 /proc/loadavg)
echo "== running ($MODE; load average $LOAD_BEFORE)"
"$BIN" "$OUT/pinocchio.csv" "$OUT/pinocchio_check.csv" "$OUT/pinocchio_cpu.csv"
LOAD_AFTER=$(cut -d' ' -f1-3 /proc/loadavg)
t4=$(now)

CPU=$(awk -F': ' '/^model name/ { print $2; exit }' /proc/cpuinfo)
{
  echo "pinocchio $HDR_PIN (pip: pin==$PIN_VERSION, Python module $PY_PIN)"
  echo "eigen $HDR_EIGEN (pip: cmeel-eigen==$EIGEN_VERSION), boost $HDR_BOOST (pip: cmeel-boost==$BOOST_VERSION)"
  echo "compiler: $("$CXX" --version | head -1)"
  echo "build: $MODE, ${FLAGS[*]}"
  echo "cpu: $CPU, $(nproc) cores"
  echo "load average before/after the run: $LOAD_BEFORE / $LOAD_AFTER"
  echo "seconds: install $(elapsed "$t0" "$t1"), compile $(elapsed "$t2" "$t3"), run $(elapsed "$t3" "$t4"), total $(elapsed "$t0" "$t4")"
} >"$OUT/pinocchio_env.txt"

echo
echo "== $OUT/pinocchio.csv"
cat "$OUT/pinocchio.csv"
echo
echo "== $OUT/pinocchio_cpu.csv (thread CPU time: use it if the load average was high)"
cat "$OUT/pinocchio_cpu.csv"
echo
echo "== $OUT/pinocchio_check.csv"
cat "$OUT/pinocchio_check.csv"
echo
echo "== $OUT/pinocchio_env.txt"
cat "$OUT/pinocchio_env.txt"
