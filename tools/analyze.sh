#!/usr/bin/env bash
# Static analysis: clang-tidy (checks in .clang-tidy) over the firmware's own sources with the
# presets' compile commands, and cppcheck over the same files; exits non-zero on any finding
# (docs/testing.md). Needs `cmake --preset sim` and `cmake --preset rpi4` first (make analyze
# does both): boards/rpi4 is compiled only by the rpi4 preset, everything else by sim.
#   tools/analyze.sh [FILE...]     default: every .cpp under algo, hal, firmware, boards, tools
# JOBS (default: the number of cores) clang-tidy processes run at once.
set -euo pipefail
cd "$(dirname "$0")/.."
for db in build/sim build/rpi4; do
  [ -f "$db/compile_commands.json" ] || {
    echo "analyze: run cmake --preset ${db#build/} first" >&2
    exit 2
  }
done
if [ "$#" -gt 0 ]; then
  files=("$@")
else
  mapfile -t files < <(git ls-files 'algo/*.cpp' 'hal/*.cpp' 'firmware/*.cpp' 'boards/*.cpp' \
    'tools/*.cpp')
fi
jobs=${JOBS:-$(nproc)}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# One file: its findings go to $out/N.txt, its exit status to $out/N.rc.
# clang's -Wdouble-promotion (unlike GCC's, which the build enforces) flags every implicit
# float-to-double conversion, also the lossless ones in initialisations and arguments that the
# host-only sim code makes on purpose; it is a compiler warning, not one of the checks chosen.
tidy_one() {
  local n=$1 f=$2 db=build/sim
  case "$f" in boards/rpi4/*) db=build/rpi4 ;; esac
  local rc=0
  clang-tidy-14 -p "$db" --quiet --extra-arg=-Wno-double-promotion "$f" >"$out/$n.txt" \
    2>/dev/null || rc=1
  echo "$rc" >"$out/$n.rc"
}

echo "analyze: clang-tidy on ${#files[@]} files, $jobs at a time"
start=$SECONDS
running=0
for i in "${!files[@]}"; do
  tidy_one "$i" "${files[$i]}" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n
    running=$((running - 1))
  fi
done
wait
status=0
for i in "${!files[@]}"; do
  if [ "$(cat "$out/$i.rc")" != 0 ]; then
    status=1
    cat "$out/$i.txt"
  fi
done
echo "analyze: clang-tidy took $((SECONDS - start)) s"

echo "analyze: cppcheck"
# Inline suppressions (// cppcheck-suppress ID) carry their reason beside them.
cppcheck --quiet --error-exitcode=1 --inline-suppr --std=c++20 --language=c++ \
  --enable=warning,performance,portability --suppress=missingIncludeSystem \
  `# cppcheck 2.10 cannot parse some C++20 (concepts, requires) and says so as internalAstError` \
  --suppress=internalAstError \
  -I algo/core/include -I algo/aln/include -I algo/image/include -I algo/stereo/include \
  -I algo/evidence/include -I algo/fusion/include -I algo/mapping/include \
  -I algo/planning/include -I hal/include -I hal/linux/include -I hal/linux/codec/include \
  -I hal/sim/include $(find firmware -type d -name include -printf '-I %p ') \
  "${files[@]}" || status=1
[ "$status" = 0 ] && echo "analyze: no findings"
exit "$status"
