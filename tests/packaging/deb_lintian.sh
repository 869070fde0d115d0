#!/usr/bin/env bash
# Builds the .deb of a configured and built preset with CPack and requires lintian to report
# no error and no warning on it.
#   deb_lintian.sh BUILD_DIR
set -euo pipefail
build=$1
if ! command -v lintian >/dev/null 2>&1; then
  echo "SKIPPED: lintian is not installed (toolchain/install-deps.sh --cross installs it)"
  exit 0
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
if ! (cd "$build" && cpack -G DEB -B "$out" >"$out/cpack.log" 2>&1); then
  cat "$out/cpack.log"
  echo "FAIL: cpack could not build the package"
  exit 1
fi
deb=$(ls "$out"/boticelli_*.deb)
echo "lintian $(basename "$deb")"
# Every tag at warning level and above is a failure; info tags are shown, not counted.
set +e
lintian --info --display-info --fail-on error,warning "$deb"
rc=$?
set -e
if [ "$rc" != 0 ]; then
  echo "FAIL: lintian reported errors or warnings (exit $rc)"
  exit 1
fi
echo "lintian: no errors, no warnings"
