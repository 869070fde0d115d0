#!/usr/bin/env bash
# Behaviour check for changes that must not change what the robot does: records the trace and
# the state file of a mission in every shipped world and every tests/worlds world at seeds 1-3,
# and compares two such records byte for byte (docs/testing.md, "Same behaviour").
#
#   tools/same_behaviour.sh record DIR [BIN]   run the missions with BIN (default
#                                              build/sim/bin/boticelli) and keep their files
#                                              and a manifest of checksums in DIR
#   tools/same_behaviour.sh compare A B        exit 0 when the two records are identical;
#                                              else name every run that differs
#
# SEEDS (default "1 2 3"), MAX_CYCLES (default 60) and JOBS (default nproc) are knobs. The
# manifest holds, per world and seed, the trace's and the state file's SHA-256 and the MISSION
# line without its wall time (the only part that may differ between two identical runs).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
seeds=${SEEDS:-1 2 3}
max_cycles=${MAX_CYCLES:-60}
jobs=${JOBS:-$(nproc)}

usage() {
  sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}

run_one() {  # BIN OUT WORLD SEED -> writes OUT/NAME-sSEED.{csv,state,line}
  local bin=$1 out=$2 world=$3 seed=$4
  local name
  name=$(basename "$(dirname "$world")")-$(basename "$world" .sdf)-s$seed
  local work
  work=$(mktemp -d "${TMPDIR:-/tmp}/boticelli-same-XXXXXX")
  local rc=0
  "$bin" --world "$world" --seed "$seed" --max-cycles "$max_cycles" --console stdio \
    --trace "$out/$name.csv" --state "$work" </dev/null >"$work/console.txt" 2>"$work/stderr.txt" ||
    rc=$?
  # Both copies of the state (A and B), one after the other.
  cat "$work/mission.state.a" "$work/mission.state.b" >"$out/$name.state" 2>/dev/null || :
  # The MISSION line without wall_time_s, and the exit code.
  { grep '^MISSION ' "$work/console.txt" | sed 's/ wall_time_s=[^ ]*//' || echo "no MISSION line"
    echo "exit=$rc"; } >"$out/$name.line"
  rm -rf "$work"
}
export -f run_one
export max_cycles

case "${1:-}" in
  record)
    [ "$#" -ge 2 ] || usage
    out=$2
    bin=${3:-$root/build/sim/bin/boticelli}
    [ -x "$bin" ] || { echo "same_behaviour: no firmware binary at $bin" >&2; exit 2; }
    bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
    mkdir -p "$out"
    out=$(cd "$out" && pwd)
    rm -f "$out"/*.csv "$out"/*.state "$out"/*.line "$out/manifest"
    cd "$root"
    for world in boards/sim/worlds/*.sdf tests/worlds/*.sdf; do
      for seed in $seeds; do printf '%s\0%s\0' "$world" "$seed"; done
    done | xargs -0 -n 2 -P "$jobs" bash -c 'run_one "$0" "$1" "$2" "$3"' "$bin" "$out"
    (cd "$out" && for f in *.line; do
      n=${f%.line}
      printf '%s trace=%s state=%s %s\n' "$n" "$(sha256sum <"$n.csv" | cut -c1-16)" \
        "$(sha256sum <"$n.state" | cut -c1-16)" "$(tr '\n' ' ' <"$f")"
    done) >"$out/manifest"
    echo "same_behaviour: $(wc -l <"$out/manifest") runs recorded in $out/manifest"
    ;;
  compare)
    [ "$#" -eq 3 ] || usage
    if diff -u "$2/manifest" "$3/manifest"; then
      echo "same_behaviour: $(wc -l <"$2/manifest") runs identical"
    else
      echo "same_behaviour: the runs above differ" >&2
      exit 1
    fi
    ;;
  *) usage ;;
esac
