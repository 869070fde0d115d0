#!/usr/bin/env bash
# Builds the robot computer in a box: a Debian 12 amd64 disk image (systemd, journald, ssh) with Debian's kernel.
#
#   toolchain/build-box.sh KERNEL_CACHE BOX_CACHE
#
# Called by `toolchain/install-deps.sh --box` (which first fills the kernel cache): all
# packages come from Debian's archive through mmdebstrap, the kernel is the kernel cache's
# linux-image .deb and the out-of-tree gpio-sim module is built from its linux-source.
# BOX_CACHE then holds root.img (a 2 GiB ext4 file system, booted read-only by tests/box:
# qemu -snapshot), vmlinuz, initrd.img, the ssh key of the box's `robot` user (id_ed25519)
# and .built, which names the kernel version and a checksum of this script and
# tests/box/box-devices.sh: a change to either or a new kernel builds the image again. Nothing is downloaded when the box runs.
set -euo pipefail

[ "$#" = 2 ] || { echo "usage: $0 KERNEL_CACHE BOX_CACHE" >&2; exit 2; }
kernel_cache=$1
box=$2
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/.." && pwd)
fail() {
  echo "build-box: $*" >&2
  exit 1
}
for tool in mmdebstrap mkfs.ext4 ssh-keygen dpkg-deb; do
  command -v "$tool" >/dev/null || fail "$tool is missing (toolchain/install-deps.sh --box)"
done

image_deb=$(find "$kernel_cache" -maxdepth 1 -name 'linux-image-*-amd64_*_amd64.deb' | head -n1)
[ -n "$image_deb" ] || fail "no kernel package in $kernel_cache (toolchain/install-deps.sh --kernel)"
kver=$(dpkg-deb -f "$image_deb" Package) && kver=${kver#linux-image-}
pkgver=$(dpkg-deb -f "$image_deb" Version)
source_deb=$(find "$kernel_cache" -maxdepth 1 -name "linux-source-*_${pkgver}_all.deb" | head -n1)
[ -n "$source_deb" ] || fail "no linux-source package $pkgver in $kernel_cache"

stamp="$kver $(cat "$0" "$repo/tests/box/box-devices.sh" | sha256sum | cut -c1-16)"
if [ -f "$box/.built" ] && [ "$(cat "$box/.built")" = "$stamp" ]; then exit 0; fi

# The same gpio-sim module as the kernel-in-the-loop test, in the same place.
gsim=$kernel_cache/gpio-sim-$pkgver
"$repo/tests/kernel/gpio-sim.sh" "$source_deb" "/usr/src/linux-headers-$kver" "$gsim"

mkdir -p "$box"
rm -rf "$box/root" "$box/.built" "$box/root.img"
echo "build-box: building the box's Debian 12 image with kernel $kver in $box (a few minutes)"

# What the robot computer runs: systemd and journald, ssh and sudo for the operator, the
# kernel's tools; and every package the boticelli .deb depends on or recommends, so that
# installing it there needs nothing from the network (the box has none to the outside).
pkgs=(
  systemd systemd-sysv udev dbus kmod iproute2 openssh-server sudo procps less
  initramfs-tools linux-base apt adduser init-system-helpers
  libgpiod2 libpng16-16 libtomlplusplus3 libstdc++6 picocom can-utils
)
sources=/etc/apt/sources.list.d/debian.sources
[ -f "$sources" ] || sources=/etc/apt/sources.list
include=$(IFS=,; echo "${pkgs[*]}")
log=$box/mmdebstrap.log
if ! nice mmdebstrap --mode=root --variant=apt --include="$include" \
     --customize-hook="copy-in $image_deb /tmp" \
     --customize-hook="chroot \"\$1\" dpkg -i /tmp/$(basename "$image_deb")" \
     --customize-hook="rm -f \"\$1\"/tmp/*.deb" \
     --customize-hook="mkdir -p \"\$1\"/lib/modules/$kver/extra" \
     --customize-hook="copy-in $gsim/gpio-sim.ko /lib/modules/$kver/extra" \
     --customize-hook="chroot \"\$1\" depmod $kver" \
     bookworm "$box/root" "$sources" >"$log" 2>&1; then
  tail -n 30 "$log" >&2
  fail "mmdebstrap failed (the whole log: $log)"
fi
root=$box/root
[ -f "$root/boot/initrd.img-$kver" ] || fail "the kernel's initramfs was not made"

# The box's own configuration: the robot computer's devices made from the kernel's virtual
# ones (docs/testing.md, "The robot computer in a box").
echo boticelli-box >"$root/etc/hostname"
printf '127.0.1.1 boticelli-box\n' >>"$root/etc/hosts"
printf '/dev/vda / ext4 defaults 0 1\n' >"$root/etc/fstab"
# User-mode network: DHCP from qemu's slirp on the one NIC.
mkdir -p "$root/etc/systemd/network"
printf '[Match]\nName=en* eth*\n\n[Network]\nDHCP=ipv4\n' >"$root/etc/systemd/network/10-user.network"
ln -sf /lib/systemd/system/systemd-networkd.service \
  "$root/etc/systemd/system/multi-user.target.wants/systemd-networkd.service"
# The robot's devices: two SJA1000 CAN controllers on one qemu CAN bus (kvaser_pci, PCI
# devices qemu adds: can0 the robot's, can1 the ODrive emulator's), vivid as the webcam,
# gpio-sim as the header's chip (58 lines like the BCM2711's), i6300esb (a PCI device qemu
# adds) as the hardware watchdog.
printf 'kvaser_pci\ncan-raw\nvivid\nconfigfs\ngpio-sim\n' >"$root/etc/modules-load.d/boticelli-box.conf"
printf 'options vivid n_devs=1 node_types=0x1\n' >"$root/etc/modprobe.d/boticelli-box.conf"
install -m 0755 "$repo/tests/box/box-devices.sh" "$root/usr/local/sbin/box-devices"
cat >"$root/etc/systemd/system/box-devices.service" <<'UNIT'
# box-devices.service: makes the box's virtual robot devices (the ODrives' end of the CAN bus, gpiochip0) at boot.
[Unit]
Description=The robot computer in a box: the ODrives' CAN controller and GPIO
After=systemd-modules-load.service sys-kernel-config.mount sys-subsystem-net-devices-can1.device
Wants=sys-kernel-config.mount
BindsTo=sys-subsystem-net-devices-can1.device
Before=boticelli.service boticelli-can0.service

[Service]
Type=oneshot
RemainAfterExit=yes
ExecStart=/usr/local/sbin/box-devices

[Install]
WantedBy=multi-user.target
UNIT
ln -sf /etc/systemd/system/box-devices.service \
  "$root/etc/systemd/system/multi-user.target.wants/box-devices.service"
# The serial lines: ttyS1 is the Pi's console UART, ttyS2 the PTU's USB-serial adapter.
cat >"$root/etc/udev/rules.d/70-boticelli-box.rules" <<'RULES'
# The robot computer in a box: the second UART as the Pi's console UART, the third as the PTU adapter.
KERNEL=="ttyS1", SUBSYSTEM=="tty", SYMLINK+="ttyAMA0", TAG+="systemd"
KERNEL=="ttyS2", SUBSYSTEM=="tty", SYMLINK+="ttyUSB0", TAG+="systemd"
RULES
# Journald keeps the journal on disk (the hardware-watchdog check reads the boot before).
mkdir -p "$root/var/log/journal"

# The operator: `robot`, ssh key only, sudo without a password (like the Pi's default user).
chroot "$root" useradd -m -s /bin/bash -G sudo robot
printf 'robot ALL=(ALL) NOPASSWD:ALL\n' >"$root/etc/sudoers.d/robot"
chmod 0440 "$root/etc/sudoers.d/robot"
rm -f "$box/id_ed25519" "$box/id_ed25519.pub"
ssh-keygen -q -t ed25519 -N '' -C boticelli-box -f "$box/id_ed25519"
install -d -m 0700 "$root/home/robot/.ssh"
install -m 0600 "$box/id_ed25519.pub" "$root/home/robot/.ssh/authorized_keys"
chroot "$root" chown -R robot:robot /home/robot/.ssh
printf 'PasswordAuthentication no\nUseDNS no\n' >"$root/etc/ssh/sshd_config.d/boticelli-box.conf"
# Root has no password; the serial console ttyS0 logs in root for debugging the box.
chroot "$root" passwd -d root >/dev/null

cp "$root/boot/vmlinuz-$kver" "$box/vmlinuz"
cp "$root/boot/initrd.img-$kver" "$box/initrd.img"
nice mkfs.ext4 -q -L boticelli-box -d "$root" "$box/root.img" 2G >/dev/null
rm -rf "$root"
echo "$stamp" >"$box/.built"
echo "build-box: done ($(du -h "$box/root.img" | cut -f1) image)"
