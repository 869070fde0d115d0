#!/bin/sh
# box-devices: makes the box's robot devices at boot: vcan can0 for the ODrive emulator, gpio-sim as gpiochip0.
#
# The kernel modules are loaded by /etc/modules-load.d/boticelli-box.conf. gpio-sim's
# lines read their pull when nothing drives them: the e-stop (line 17, a normally closed
# switch to GND) reads low = released with the default pull-down; the bumper (line 27,
# normally open to GND, active low) gets a pull-up = no contact. tests/box/run.sh changes
# the pulls to press the e-stop or break its wire.
set -eu

ip link show can0 >/dev/null 2>&1 || ip link add dev can0 type vcan

c=/sys/kernel/config/gpio-sim/boticelli
if [ ! -d "$c" ]; then
  mkdir "$c" "$c/bank0"
  echo 58 >"$c/bank0/num_lines"
  echo 1 >"$c/live"
fi
chip=$(ls -d /sys/devices/platform/gpio-sim.*/gpiochip*)
echo pull-up >"$chip/sim_gpio27/pull"
# The chip's udev rules (group gpio, 60-boticelli.rules) applied before boticelli.service,
# which starts after this unit, opens it: at boot the events are otherwise still queued.
udevadm settle --timeout=30 || true
echo "box-devices: can0 (vcan), $(basename "$chip") (gpio-sim, 58 lines)"
