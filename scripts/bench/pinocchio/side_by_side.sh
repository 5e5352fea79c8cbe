#!/usr/bin/env bash
# Pinocchio's aba and the generated code timed in turn, round after round, so that each
# ratio compares two figures taken within seconds of each other (the shared machine's speed
# moves by up to 30 % between minutes; see BENCHMARKS.md).
#
#   scripts/bench/pinocchio/side_by_side.sh PIN_DIR FORM_DIR [ROUNDS]
#
# PIN_DIR: the OUT_DIR of run.sh (its aba_chain binary). FORM_DIR: the OUTDIR of
# `cargo run --release -p camchain-codegen --example formulations -- FORM_DIR [--native] N…`
# (its built timing programs, native ones preferred). ROUNDS: default 5.
# Writes FORM_DIR/side_by_side.csv (or, when that exists, side_by_side.TIME.PID.csv: an
# earlier run's file is never overwritten), one line per round and chain:
#   round,family,n,aba_ns,rhs_best_ns,free_best_ns,constrained_ratio,unconstrained_ratio,
#   state_rhs_best_ns,state_ratio
# where rhs_best is the faster route's constrained reduced right-hand side f(t, y)
# (`derivative_at`, given t and y as aba is given q, v and tau), free_best the faster
# route's unconstrained forward dynamics of the chain without its contact, state_rhs_best
# the same right-hand side through `derivative` after writing t, q and q̇ into a State
# (which also rebuilds y from them), and the ratios aba / those (all thread CPU time).
# Prints the median ratios per chain.
set -euo pipefail

if [[ $# -lt 2 || $# -gt 3 ]]; then
  echo "usage: $0 PIN_DIR FORM_DIR [ROUNDS]" >&2
  exit 2
fi
PIN="$1/aba_chain"
FORM="$2"
ROUNDS="${3:-5}"
if ! [[ "$ROUNDS" =~ ^[1-9][0-9]*$ ]]; then
  echo "error: ROUNDS must be a positive integer, not '$ROUNDS'" >&2
  exit 2
fi
if [[ ! -x "$PIN" ]]; then
  echo "error: $PIN is missing: run scripts/bench/pinocchio/run.sh $1 first" >&2
  exit 1
fi
BIN="$FORM/target-native/release"
[[ -d "$BIN" ]] || BIN="$FORM/target/release"
shopt -s nullglob
programs=("$BIN"/formulations_spatial* "$BIN"/formulations_planar*)
shopt -u nullglob
runnable=()
for p in "${programs[@]}"; do
  [[ -x "$p" && "$p" != *.d ]] && runnable+=("$p")
done
if [[ ${#runnable[@]} -eq 0 ]]; then
  echo "error: no timing program in $BIN: run the formulations example first" >&2
  exit 1
fi
SCRATCH="$(mktemp -d)"
trap 'rm -rf "$SCRATCH"' EXIT
echo "round,family,n,aba_ns,rhs_best_ns,free_best_ns,constrained_ratio,unconstrained_ratio,state_rhs_best_ns,state_ratio" >"$SCRATCH/out.csv"
for ((r = 1; r <= ROUNDS; r++)); do
  "$PIN" "$SCRATCH/wall.csv" "$SCRATCH/check.csv" "$SCRATCH/cpu.csv" >"$SCRATCH/pin.log" 2>&1 ||
    { cat "$SCRATCH/pin.log" >&2; exit 1; }
  for p in "${runnable[@]}"; do
    name="${p##*/formulations_}"
    family="${name%%[0-9]*}"
    n="${name#"$family"}"
    # Pinocchio's families: the spatial chain is "chain", the planar one "planar".
    pin_family="chain"
    [[ "$family" == planar ]] && pin_family="planar"
    aba=$(awk -F, -v f="$pin_family" -v n="$n" '$1 == f && $2 == n { print $3 }' "$SCRATCH/cpu.csv")
    [[ -n "$aba" ]] || continue
    # The timing program prints: derivative (dense, articulated), the unconstrained
    # forward dynamics (dense, articulated), derivative_at (dense, articulated).
    read -r sd sa fd fa rd ra < <("$p")
    awk -v r="$r" -v f="$family" -v n="$n" -v aba="$aba" -v rd="$rd" -v ra="$ra" -v fd="$fd" -v fa="$fa" \
      -v sd="$sd" -v sa="$sa" \
      'BEGIN { rb = rd < ra ? rd : ra; fb = fd < fa ? fd : fa; sb = sd < sa ? sd : sa;
               printf "%d,%s,%d,%.1f,%.1f,%.1f,%.3f,%.3f,%.1f,%.3f\n", r, f, n, aba, rb, fb, aba / rb, aba / fb, sb, aba / sb }' \
      >>"$SCRATCH/out.csv"
  done
done
# noclobber: an existing file, an earlier run's or anything else, is never replaced.
OUT="$FORM/side_by_side.csv"
if ! (set -o noclobber && cat "$SCRATCH/out.csv" >"$OUT") 2>/dev/null; then
  OUT="$FORM/side_by_side.$(date +%Y%m%d-%H%M%S).$$.csv"
  (set -o noclobber && cat "$SCRATCH/out.csv" >"$OUT")
fi
echo "wrote $OUT"
echo "family,n,median aba/rhs (constrained),median aba/free (unconstrained),median aba/rhs from a state,rounds"
# The median of column $1 of the lines on stdin (sorted numerically first).
median() {
  cut -d, -f"$1" | sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}
tail -n +2 "$OUT" | cut -d, -f2,3 | sort -t, -k1,1 -k2,2n -u | while IFS=, read -r family n; do
  lines=$(awk -F, -v f="$family" -v n="$n" '$2 == f && $3 == n' "$OUT")
  echo "$family,$n,$(median 7 <<<"$lines"),$(median 8 <<<"$lines"),$(median 10 <<<"$lines"),$(wc -l <<<"$lines")"
done
