#!/usr/bin/env bash
# Checks the .deb's maintainer scripts. preinst makes the groups the udev rule names; postinst never starts or restarts a unit (installing
# or upgrading must not set the robot driving) but the firmware held after an upgrade. Then runs them against a scratch root
# (DPKG_ROOT, with deb-systemd-helper's real bookkeeping): the first installation enables the
# units, an upgrade keeps an administrator's disable, remove and purge leave nothing enabled.
#   maintainer_scripts.sh PACKAGING_DIR
set -euo pipefail
pkg=$1

# The start is read from the script itself: under DPKG_ROOT (below) and on a machine without
# a running systemd its systemd calls are skipped, so running it cannot show one. Comments
# and quoted text (messages to the operator) are left out; any tool that starts a unit
# counts, and so does `enable --now`.
# One start is allowed: the firmware's, after an upgrade, within five lines after a file was
# written (`: >"$held"`, quotes stripped; the run below checks it is the start-held file that
# makes the firmware wait for the operator's `resume`).
starts=$(sed -e 's/#.*//' -e 's/"[^"]*"//g' -e "s/'[^']*'//g" "$pkg/postinst" |
  awk '/^ *: *> *$/ { held = NR }
       /(deb-systemd-invoke|systemctl|invoke-rc\.d|service)( |.* )(start|restart|try-restart|reload-or-restart|try-reload-or-restart|condrestart)( |$)|--now/ {
         if (!($0 ~ /deb-systemd-invoke start boticelli\.service/ && held && NR - held <= 5))
           print NR ": " $0
       }' || true)
if [ -n "$starts" ]; then
  printf '%s\n' "$starts"
  echo "FAIL: postinst starts or restarts a unit: installing or upgrading would set the robot off"
  exit 1
fi
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

# preinst makes every group the udev rule names before the rule is unpacked: udev drops a
# GROUP= it cannot resolve when it reads the rule (at any device event during the unpack) and
# does not read an unchanged rules directory again on postinst's reload. Here nothing exists
# yet (getent finds nothing) and the stand-ins write down what was made.
mkdir -p "$root/fakebin-new"
printf '#!/bin/sh\nexit 2\n' >"$root/fakebin-new/getent"
for tool in adduser addgroup; do
  printf '#!/bin/sh\necho "%s $*" >>"%s"\n' "$tool" "$root/made" >"$root/fakebin-new/$tool"
done
chmod +x "$root/fakebin-new/"*
PATH="$root/fakebin-new:$PATH" sh "$pkg/preinst" install
for group in $(sed -n 's/.*GROUP="\([^"]*\)".*/\1/p' "$pkg/60-boticelli.rules" | sort -u); do
  grep -qE "^(addgroup --system $group|adduser --system --group .* $group)\$" "$root/made" ||
    fail "preinst does not make the group '$group' that 60-boticelli.rules names (made: $(tr '\n' ';' <"$root/made"))"
done

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
[ -e "$root/var/lib/boticelli/start-held" ] && fail "an upgrade of a stopped firmware held it"

# An upgrade of a running firmware (prerm left its marker): started again held.
mkdir -p "$root/run"
: >"$root/run/boticelli.upgrade-restart"
sh "$pkg/postinst" configure 0.1.0 2>/dev/null
[ -e "$root/var/lib/boticelli/start-held" ] || fail "an upgrade of a running firmware did not hold it"
[ -e "$root/run/boticelli.upgrade-restart" ] && fail "postinst left the upgrade marker"

sh "$pkg/prerm" remove
sh "$pkg/postrm" remove
sh "$pkg/postrm" purge
enabled boticelli-can0.service && fail "purge left boticelli-can0.service enabled"
echo "maintainer scripts: the udev rule's groups made before the unpack, nothing started but" \
  "a held firmware after an upgrade, enable on first install, admin's disable kept on" \
  "upgrade, purge clean"
