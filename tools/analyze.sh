#!/usr/bin/env bash
# Static analysis: clang-tidy (checks in .clang-tidy) over the firmware's own sources with the
# sim preset's compile commands, and cppcheck over the same files; exits non-zero on any
# finding (docs/testing.md). Needs `cmake --preset sim` first (make analyze does it).
#   tools/analyze.sh [FILE...]     default: every .cpp under algo, hal, firmware and boards
set -euo pipefail
cd "$(dirname "$0")/.."
db=build/sim
[ -f "$db/compile_commands.json" ] || { echo "analyze: run cmake --preset sim first" >&2; exit 2; }
if [ "$#" -gt 0 ]; then
  files=("$@")
else
  mapfile -t files < <(git ls-files 'algo/*.cpp' 'hal/*.cpp' 'firmware/*.cpp' 'boards/*.cpp')
fi
status=0
echo "analyze: clang-tidy on ${#files[@]} files"
for f in "${files[@]}"; do
  clang-tidy-14 -p "$db" --quiet "$f" 2>/dev/null || status=1
done
echo "analyze: cppcheck"
# Inline suppressions (// cppcheck-suppress ID) carry their reason beside them.
cppcheck --quiet --error-exitcode=1 --inline-suppr --std=c++20 --language=c++ \
  --enable=warning,performance,portability --suppress=missingIncludeSystem \
  `# cppcheck 2.10 cannot parse some C++20 (concepts, requires) and says so as internalAstError` \
  --suppress=internalAstError \
  -I algo/core/include -I algo/aln/include -I algo/image/include -I algo/stereo/include \
  -I algo/evidence/include -I algo/fusion/include -I algo/mapping/include \
  -I algo/planning/include -I hal/include -I hal/linux/include -I hal/linux/codec/include \
  -I hal/sim/include -I firmware/include \
  "${files[@]}" || status=1
[ "$status" = 0 ] && echo "analyze: no findings"
exit "$status"
