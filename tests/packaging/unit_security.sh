#!/usr/bin/env bash
# Rates a systemd unit with `systemd-analyze security --offline=yes` and fails above MAX.
#   unit_security.sh UNIT_FILE MAX     e.g. boticelli.service 3.0
set -euo pipefail
unit=$1
max=$2
if ! command -v systemd-analyze >/dev/null 2>&1; then
  echo "SKIPPED: systemd-analyze is not installed (Debian package systemd)"
  exit 0
fi
# Offline mode reads the file itself, not the running system's copy; the name must end in
# .service, so it is rated from a private copy named like the shipped unit.
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cp "$unit" "$dir/"
out=$(cd "$dir" && systemd-analyze security --offline=yes --no-pager "$(basename "$unit")" 2>&1) || true
line=$(printf '%s\n' "$out" | grep 'Overall exposure level' || true)
if [ -z "$line" ]; then
  printf '%s\n' "$out"
  echo "FAIL: no 'Overall exposure level' line from systemd-analyze"
  exit 1
fi
figure=$(printf '%s\n' "$line" | sed -E 's/.*: ([0-9]+\.[0-9]+) .*/\1/')
echo "$(basename "$unit"): exposure $figure (at most $max)"
if ! awk -v f="$figure" -v m="$max" 'BEGIN { exit !(f <= m) }'; then
  printf '%s\n' "$out" | grep '✗' || true
  echo "FAIL: exposure $figure is above $max"
  exit 1
fi
