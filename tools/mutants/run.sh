#!/usr/bin/env bash
# Mutation check: applies each deliberate bug in tools/mutants/*.patch to a scratch copy of
# the tree, builds the sim-preset test binary the patch names and runs it through ctest;
# reports each mutant as caught (the test failed) or survived (docs/testing.md). A patch with a
# "Known:" line is a survivor no test catches yet (the line says why); it does not fail the run.
#
#   tools/mutants/run.sh [NAME...]     NAME: a patch's file name without .patch (default all)
#
# The scratch copy and its build are kept between runs (MUTANTS_SCRATCH, default
# ${TMPDIR:-/tmp}/boticelli-mutants) so that later runs rebuild only what a patch touches.
# JOBS (default 1) is the build's parallelism. Exit code 0 when every mutant was caught.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
scratch=${MUTANTS_SCRATCH:-${TMPDIR:-/tmp}/boticelli-mutants}
jobs=${JOBS:-1}
src=$scratch/src
mkdir -p "$src"

# Copies the working tree (tracked and untracked, not ignored) into the scratch copy; files
# that did not change keep their time stamps, so the build there stays incremental, and a
# changed one gets the copy's time (not its own, which can be older than an object built
# there from its previous text).
sync_tree() {
  (cd "$root" && git ls-files -co --exclude-standard -z) |
    while IFS= read -r -d '' f; do
      [ -f "$root/$f" ] || continue
      if ! cmp -s "$root/$f" "$src/$f"; then
        mkdir -p "$(dirname "$src/$f")"
        cp --preserve=mode "$root/$f" "$src/$f"
      fi
    done
}

field() { sed -n "s/^$1: //p" "$2" | head -n1; }

patches=()
if [ "$#" -gt 0 ]; then
  for name in "$@"; do patches+=("$here/$name.patch"); done
else
  patches=("$here"/*.patch)
fi

sync_tree
log=$scratch/last.log
(cd "$src" && cmake --preset sim -DBOTICELLI_BUILD_BENCH=OFF >"$log" 2>&1) || {
  cat "$log" >&2
  echo "mutants: configuring the scratch copy failed" >&2
  exit 2
}

build_and_test() {  # TEST -> 0 passed, 1 failed, 2 did not build
  (cd "$src" && cmake --build --preset sim -j "$jobs" --target "$1" >"$log" 2>&1) || return 2
  # The binary's ctest entries: its own name, or one per test group (test_mission_Mission...);
  # a name that matches none is an error, not a pass.
  (cd "$src" && timeout 1200 ctest --preset sim --no-tests=error -R "^$1(_[A-Z][A-Za-z]*)?\$" \
    >>"$log" 2>&1) || return 1
  return 0
}

# Every test named must pass on the unmutated tree first.
declare -A baseline=()
for p in "${patches[@]}"; do
  [ -f "$p" ] || { echo "mutants: no such patch: $p" >&2; exit 2; }
  t=$(field Test "$p")
  [ -n "${baseline[$t]:-}" ] && continue
  if build_and_test "$t"; then
    baseline[$t]=ok
  else
    tail -n 30 "$log" >&2
    echo "mutants: $t fails on the unmutated tree" >&2
    exit 2
  fi
done

caught=0
survived=0
known=0
for p in "${patches[@]}"; do
  name=$(basename "$p" .patch)
  t=$(field Test "$p")
  if ! (cd "$src" && patch -p1 --forward --silent <"$p" >"$log" 2>&1); then
    echo "NOT APPLIED  $name (the code it mutates has changed; update the patch)"
    survived=$((survived + 1))
    sync_tree
    continue
  fi
  status=0
  build_and_test "$t" || status=$?
  (cd "$src" && patch -p1 -R --silent <"$p" >/dev/null)
  case $status in
    0)
      if [ -n "$(field Known "$p")" ]; then
        echo "known        $name survives: $(field Known "$p")"; known=$((known + 1))
      else
        echo "SURVIVED     $name ($t passes with: $(field Mutant "$p"))"; survived=$((survived + 1))
      fi ;;
    1) echo "caught       $name ($t)"; caught=$((caught + 1)) ;;
    *) echo "NOT BUILT    $name (the mutant does not compile; make it one that does)"; survived=$((survived + 1)) ;;
  esac
done
# Leave the scratch build unmutated for the next run.
(cd "$src" && cmake --build --preset sim -j "$jobs" --target "${!baseline[@]}" >"$log" 2>&1) || true
echo "mutants: $caught caught, $survived not caught, $known known survivors, of ${#patches[@]}"
[ "$survived" = 0 ]
