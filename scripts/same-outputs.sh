#!/usr/bin/env bash
# Compares two ratecal binaries on the shared examples and a dry run: every JSON output
# byte for byte and every exit code. For refactors that must not change behaviour.
#   scripts/same-outputs.sh OLD_BINARY NEW_BINARY
# Prints one line per command (same / DIFFERENT) and exits 1 if any differs.
set -uo pipefail
old=$1 new=$2
root=$(cd "$(dirname "$0")/.." && pwd)
shared=$root/../shared
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
differ=0

# A dry run (made once, by the new binary) that both binaries then read.
"$new" run "$root/procedures/imu-2d-standard" --dry-run --seed 7 --out "$work/dry" >/dev/null 2>&1
runs=("$work/dry")
for ex in "$shared"/examples/*/; do
  [ -f "$ex/manifest.yaml" ] && runs+=("${ex%/}")
done

# compare NAME ARGS...: runs both binaries, each on a fresh copy of every run folder at the
# same path (a command that writes into one does not feed the other), and compares standard
# output and exit code.
compare() {
  local name=$1; shift
  for side in old new; do
    rm -rf "$work/runs"; mkdir -p "$work/runs"
    for r in "${runs[@]}"; do cp -r "$r" "$work/runs/"; done
    local bin=${!side}
    local args=("${@//@RUNS@/$work/runs}")
    (cd "$root" && "$bin" "${args[@]}" >"$work/$side.out" 2>/dev/null; echo "exit $?" >>"$work/$side.out")
  done
  if cmp -s "$work/old.out" "$work/new.out"; then
    echo "same       $name ($(tail -1 "$work/new.out"))"
  else
    echo "DIFFERENT  $name"; differ=1
    diff <(head -c 2000 "$work/old.out") <(head -c 2000 "$work/new.out") | head -20
  fi
}

for r in "${runs[@]}"; do
  b=$(basename "$r")
  compare "analyze $b" analyze "@RUNS@/$b"
  compare "analyze $b --procedure" analyze "@RUNS@/$b" --procedure procedures/imu-2d-standard
  compare "explain $b" explain "@RUNS@/$b" --format json
  compare "verify $b" verify "@RUNS@/$b"
done
compare "explain dry --twin" explain "@RUNS@/dry" --twin "@RUNS@/dry" --format json
compare "explain dry --procedure" explain "@RUNS@/dry" --procedure procedures/imu-2d-standard --format json
compare "report dry" report "@RUNS@/dry"
compare "check standard" check procedures/imu-2d-standard
compare "check all" check procedures/imu-2d-standard procedures/imu-2d-consumer procedures/size-effect procedures/station-check
compare "check folder@1.0.0" check procedures/imu-2d-standard@1.0.0
compare "diff json" diff procedures/imu-2d-standard@1.0.0 procedures/imu-2d-standard@1.1.0 --format json
compare "log" log procedures/imu-2d-standard
compare "fmt --check" fmt --check procedures/imu-2d-standard/1.1.0.rcal
compare "check missing" check no/such/procedure
compare "verify missing" verify no/such/run
exit $differ
