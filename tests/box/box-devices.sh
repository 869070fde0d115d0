#!/bin/sh
# box-devices: makes the box's robot devices at boot: can1 up for the ODrive emulator, gpio-sim as gpiochip0.
#
# The kernel modules are loaded by /etc/modules-load.d/boticelli-box.conf. gpio-sim's
# lines read their pull when nothing drives them: the e-stop (line 17, a normally closed
# switch to GND) reads low = released with the default pull-down; the bumper (line 27,
# normally open to GND, active low) gets a pull-up = no contact. tests/box/run.sh changes
# the pulls to press the e-stop or break its wire.
set -eu

# can0 and can1 are two SJA1000 controllers (qemu's kvaser_pci) on one qemu CAN bus, in PCI
# slot order: can0 is the robot's (the package's boticelli-can0.service brings it up as on the
# Pi), can1 the ODrive emulator's end of the bus, at the same bitrate.
ip link set can1 down 2>/dev/null || true
ip link set can1 up type can bitrate 250000 restart-ms 100

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
echo "box-devices: can1 (the ODrives' end, 250 kbit/s), $(basename "$chip") (gpio-sim, 58 lines)"
