#!/usr/bin/env bash
# Runs the .deb's maintainer scripts against a scratch root (DPKG_ROOT, with deb-systemd-helper's
# real bookkeeping): the first installation enables the units, an upgrade keeps an
# administrator's disable, remove and purge leave nothing enabled.
#   maintainer_scripts.sh PACKAGING_DIR
set -euo pipefail
pkg=$1
if ! command -v deb-systemd-helper >/dev/null 2>&1 || ! command -v systemctl >/dev/null 2>&1; then
  echo "SKIPPED: deb-systemd-helper or systemctl is not installed (init-system-helpers, systemd)"
  exit 0
fi
root=$(mktemp -d)
trap 'rm -rf "$root"' EXIT
export DPKG_ROOT=$root
# What dpkg sets for a maintainer script (deb-systemd-helper refuses to run without it).
export DPKG_MAINTSCRIPT_PACKAGE=boticelli DPKG_MAINTSCRIPT_NAME=postinst
# The user and group tools would change this machine: stand-ins that only succeed.
mkdir -p "$root/fakebin" "$root/lib/systemd/system" "$root/etc/systemd/system" "$root/var/lib"
for tool in adduser addgroup deluser getent udevadm; do
  printf '#!/bin/sh\nexit 0\n' >"$root/fakebin/$tool"
  chmod +x "$root/fakebin/$tool"
done
export PATH="$root/fakebin:$PATH"
cp "$pkg/boticelli.service" "$pkg/boticelli-can0.service" "$root/lib/systemd/system/"
wants=$root/etc/systemd/system/multi-user.target.wants
enabled() { [ -L "$wants/$1" ]; }
fail() { echo "FAIL: $*"; exit 1; }

sh "$pkg/postinst" configure ""
enabled boticelli.service || fail "first installation did not enable boticelli.service"
enabled boticelli-can0.service || fail "first installation did not enable boticelli-can0.service"

# The administrator disables the firmware; an upgrade must not enable it again.
systemctl --root="$root" --quiet disable boticelli.service
enabled boticelli.service && fail "systemctl disable did not disable (test set-up)"
sh "$pkg/prerm" upgrade 0.1.0
sh "$pkg/postinst" configure 0.1.0
enabled boticelli.service && fail "an upgrade re-enabled the service the administrator disabled"
enabled boticelli-can0.service || fail "an upgrade disabled boticelli-can0.service"

sh "$pkg/prerm" remove
sh "$pkg/postrm" remove
sh "$pkg/postrm" purge
enabled boticelli-can0.service && fail "purge left boticelli-can0.service enabled"
echo "maintainer scripts: enable on first install, admin's disable kept on upgrade, purge clean"
