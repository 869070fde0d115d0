#!/usr/bin/env bash
# Builds gpio-sim out of tree for Debian's kernel (its config does not build it), once per version.
#
#   tests/kernel/gpio-sim.sh SOURCE_DEB HEADERS_DIR OUT_DIR
#
# Leaves OUT_DIR/gpio-sim.ko (kept when it is there already). Used by the kernel-in-the-loop
# test and the robot computer in a box. gpio-sim needs irq_sim (CONFIG_IRQ_SIM is off too,
# so it is compiled into the same module), and in 6.1 irq_to_desc is not exported: its one
# call becomes generic_handle_irq.
set -euo pipefail

[ "$#" = 3 ] || { echo "usage: $0 SOURCE_DEB HEADERS_DIR OUT_DIR" >&2; exit 2; }
source_deb=$1
headers=$2
gsim=$3
fail() {
  echo "gpio-sim: $*" >&2
  exit 1
}
[ -f "$gsim/gpio-sim.ko" ] && exit 0
[ -f "$source_deb" ] || fail "no kernel source package $source_deb"
[ -d "$headers" ] || fail "$headers is missing (toolchain/install-deps.sh --kernel)"
rm -rf "$gsim" && mkdir -p "$gsim/src"
series=$(basename "$source_deb" | sed 's/^linux-source-\([0-9.]*\)_.*/\1/')
dpkg-deb --fsys-tarfile "$source_deb" |
  tar -xO "./usr/src/linux-source-$series.tar.xz" |
  tar -xJ -C "$gsim/src" --strip-components=1 --wildcards \
    "linux-source-$series/drivers/gpio/gpio-sim.c" \
    "linux-source-$series/drivers/gpio/gpiolib*.h" \
    "linux-source-$series/kernel/irq/irq_sim.c"
cp "$gsim"/src/drivers/gpio/gpio-sim.c "$gsim/gpio-sim-main.c"
cp "$gsim"/src/drivers/gpio/gpiolib*.h "$gsim/"
sed 's/handle_simple_irq(irq_to_desc(irqnum))/generic_handle_irq(irqnum)/' \
  "$gsim/src/kernel/irq/irq_sim.c" >"$gsim/irq_sim.c"
grep -q 'generic_handle_irq(irqnum)' "$gsim/irq_sim.c" ||
  fail "irq_sim.c of $(basename "$source_deb") no longer has the call this script replaces"
printf 'obj-m := gpio-sim.o\ngpio-sim-y := gpio-sim-main.o irq_sim.o\n' >"$gsim/Kbuild"
make -s -C "$headers" M="$gsim" modules >"$gsim/build.log" 2>&1 ||
  { tail -n 20 "$gsim/build.log" >&2; fail "building gpio-sim failed"; }
