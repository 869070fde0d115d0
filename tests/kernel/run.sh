#!/usr/bin/env bash
# Kernel in the loop: boots Debian's amd64 kernel under qemu (TCG) with a busybox initramfs
# holding the test program, the modules it needs and the out-of-tree gpio-sim, and reads the
# results from the serial console (docs/testing.md).
#
#   tests/kernel/run.sh KERNEL_TESTS WORK_DIR
#
# Exit 0: every part passed; 1: a part failed (the console log says which); 77: skipped
# because qemu cannot run here (the reason is printed). The kernel and source packages come
# from the kernel cache that toolchain/install-deps.sh --kernel fills; the unpacked kernel
# and the gpio-sim module are kept there too, the initramfs and the console log in WORK_DIR.
set -euo pipefail

tests_bin=$(readlink -f "$1")
work=$2
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
# The same default as toolchain/install-deps.sh.
if [ -n "${HOME:-}" ]; then default_cache=${XDG_CACHE_HOME:-$HOME/.cache}/boticelli-kernel
else default_cache=$repo/build/kernel-cache; fi
cache=${BOTICELLI_KERNEL_CACHE:-$default_cache}
mkdir -p "$work"
work=$(cd "$work" && pwd)

skip() {
  echo "SKIPPED: $*"
  exit 77
}
fail() {
  echo "kernel_in_the_loop: $*" >&2
  exit 1
}
t_start=$(date +%s.%N)
elapsed() { awk -v a="$t_start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }

command -v qemu-system-x86_64 >/dev/null ||
  skip "qemu-system-x86_64 is not installed (toolchain/install-deps.sh --kernel installs it)"
[ "$(uname -m)" = x86_64 ] || skip "the guest kernel is amd64 and this host is $(uname -m)"
# The rest is installed by the same install-deps option: missing pieces are failures.
for tool in busybox cpio objcopy dpkg-deb candump xz; do
  command -v "$tool" >/dev/null || fail "$tool is missing (toolchain/install-deps.sh --kernel)"
done
busybox=$(command -v busybox)

image_deb=$(ls "$cache"/linux-image-*-amd64_*_amd64.deb 2>/dev/null | head -n1 || true)
[ -n "$image_deb" ] || fail "no kernel package in $cache (toolchain/install-deps.sh --kernel)"
kver=$(dpkg-deb -f "$image_deb" Package) && kver=${kver#linux-image-}
pkgver=$(dpkg-deb -f "$image_deb" Version)
source_deb=$(ls "$cache"/linux-source-*_"$pkgver"_all.deb 2>/dev/null | head -n1 || true)
[ -n "$source_deb" ] || fail "no linux-source package $pkgver in $cache"
headers=/usr/src/linux-headers-$kver
[ -d "$headers" ] || fail "$headers is missing (toolchain/install-deps.sh --kernel)"

# 1. The kernel, unpacked once per version into the kernel cache (so that fresh clones
# share it; about 400 MB), older versions' products removed.
for old in "$cache"/unpacked-* "$cache"/gpio-sim-*; do
  case "$old" in *-"$pkgver") ;; *) [ -d "$old" ] && rm -rf "$old" ;; esac
done
kdir=$cache/unpacked-$pkgver
if [ ! -f "$kdir/.unpacked" ]; then
  rm -rf "$kdir"
  dpkg-deb -x "$image_deb" "$kdir"
  touch "$kdir/.unpacked"
fi
modules=$kdir/lib/modules/$kver

# 2. gpio-sim, built out of tree once per version (Debian's config does not build it).
gsim=$cache/gpio-sim-$pkgver
"$here/gpio-sim.sh" "$source_deb" "$headers" "$gsim" || fail "no gpio-sim module"

# 3. The initramfs: busybox, the test program and candump with their shared libraries, the
# modules' dependency closure, and the guest's init.
root=$work/root
rm -rf "$root"
mkdir -p "$root"/{bin,sbin,dev,proc,sys,tmp,lib64,etc} "$root/lib/modules/$kver"
cp "$busybox" "$root/bin/busybox"
cp "$tests_bin" "$root/bin/kernel_tests"
cp "$(command -v candump)" "$root/bin/candump"
for bin in "$root/bin/kernel_tests" "$root/bin/candump"; do
  for lib in $(ldd "$bin" | awk '/=> \// { print $3 } /^\t\/lib64/ { print $1 }'); do
    mkdir -p "$root$(dirname "$lib")"
    cp -L "$lib" "$root$lib"
  done
done
cp "$here/init.sh" "$root/init"
chmod +x "$root/init"

modinfo_field() { # FILE FIELD
  objcopy -O binary --only-section=.modinfo "$1" /dev/stdout 2>/dev/null |
    tr '\0' '\n' | sed -n "s/^$2=//p"
}
declare -A module_file=()
while read -r n f; do
  n=${n%.ko}
  module_file[${n//-/_}]=$f
done < <(find "$modules/kernel" -name '*.ko' -printf '%f %p\n')
module_file[gpio_sim]=$gsim/gpio-sim.ko
declare -A have=()
add_module() {
  local name=${1//-/_} f dep
  [ -n "${have[$name]:-}" ] && return 0
  f=${module_file[$name]:-}
  [ -n "$f" ] || fail "module $1 is not in $kver"
  have[$name]=1
  for dep in $(modinfo_field "$f" depends | tr ',' ' '); do add_module "$dep"; done
  mkdir -p "$root/lib/modules/$kver/kernel"
  cp "$f" "$root/lib/modules/$kver/kernel/"
}
for m in vcan can-raw vivid softdog configfs gpio-sim; do add_module "$m"; done
cp "$modules"/modules.builtin "$modules"/modules.order "$root/lib/modules/$kver/"
"$busybox" depmod -b "$root" "$kver"
(cd "$root" && find . | cpio -o -H newc --quiet | gzip -1) >"$work/initrd.gz"
prepared=$(elapsed)

# 4. Boot. Each line of the console is stamped with the host's time since the boot began.
console=$work/console.log
echo "kernel_in_the_loop: $kver ($pkgver), ${#have[@]} modules; prepared in ${prepared} s"
boot_start=$(date +%s.%N)
set +e
timeout 240 qemu-system-x86_64 -accel tcg -m 512M -smp 1 -nographic -no-reboot -nic none -vga none \
  -kernel "$kdir/boot/vmlinuz-$kver" -initrd "$work/initrd.gz" \
  -append "console=ttyS0 quiet panic=-1 printk.time=1" </dev/null 2>&1 |
  while IFS= read -r line; do
    line=${line%$'\r'}
    printf '%6.1f %s\n' "$(awk -v a="$boot_start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')" "$line"
  done | tee "$console"
qemu_rc=${PIPESTATUS[0]}
set -e
echo "kernel_in_the_loop: qemu exited with $qemu_rc after $(awk -v a="$boot_start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s; total $(elapsed) s"
[ "$qemu_rc" = 124 ] && fail "the guest did not finish in 240 s"

# 5. The verdict: every part the guest started must have ended with rc=0, all of them must
# have run, and the last one must have been ended by the watchdog's reset.
status=0
for part in can can-record camera gpio watchdog; do
  line=$(grep -E "KTEST PART $part rc=" "$console" | tail -n1 || true)
  if [ -z "$line" ]; then
    echo "kernel_in_the_loop: part $part did not run" >&2
    status=1
  elif ! grep -q "rc=0 " <<<"$line"; then
    echo "kernel_in_the_loop: part $part failed: $line" >&2
    status=1
  fi
done
# The watchdog reset: softdog's message after the test's last keepalive, within the 2 s
# timeout (+0.5 s for the 1 s timer's granularity), both on the guest's printk clock.
printk_time() { grep -F "$1" "$console" | tail -n1 | sed -n 's/.*\[ *\([0-9.]*\)\].*/\1/p'; }
kick=$(printk_time "boticelli-kernel-test: last watchdog keepalive")
reset=$(printk_time "softdog: Initiating system reboot")
if [ -z "$kick" ] || [ -z "$reset" ]; then
  echo "kernel_in_the_loop: no watchdog reset seen (keepalive at '${kick}', reset at '${reset}')" >&2
  status=1
elif grep -q "KTEST END" "$console"; then
  echo "kernel_in_the_loop: the guest ran to its end: the watchdog did not reset it" >&2
  status=1
else
  delay=$(awk -v a="$kick" -v b="$reset" 'BEGIN { printf "%.2f", b - a }')
  echo "kernel_in_the_loop: watchdog reset ${delay} s after the last keepalive (timeout 2 s)"
  awk -v d="$delay" 'BEGIN { exit !(d >= 1.5 && d <= 2.5) }' ||
    { echo "kernel_in_the_loop: the reset came ${delay} s after the last keepalive" >&2; status=1; }
fi
grep -E "KTEST PART .* rc=" "$console" | sed 's/^ *[0-9.]* //' || true
[ "$status" = 0 ] && echo "kernel_in_the_loop: passed"
exit "$status"
