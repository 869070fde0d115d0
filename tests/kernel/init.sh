#!/bin/busybox sh
# Guest init of the kernel-in-the-loop test: loads each part's modules, sets up its virtual
# device, runs its test group and prints "KTEST PART name rc=N" for run.sh; ends with the
# watchdog part, whose last test must get the guest reset by softdog.
/bin/busybox --install -s /bin
export PATH=/bin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
mkdir -p /dev/pts && mount -t devpts devpts /dev/pts
mount -t tmpfs tmpfs /tmp

uptime_s() { cut -d' ' -f1 /proc/uptime; }
part() {
  name=$1
  shift
  t0=$(uptime_s)
  echo "KTEST PART $name start"
  "$@"
  rc=$?
  echo "KTEST PART $name rc=$rc seconds=$(awk -v a="$t0" -v b="$(uptime_s)" 'BEGIN { print b - a }')"
}

# CAN: vcan0 recorded by candump (host->ODrive and ODrive->host frames; error frames are not
# recorded), then the record checked against docs/protocols.md.
can() {
  modprobe vcan && modprobe can-raw || return 101
  ip link add dev vcan0 type vcan && ip link set up vcan0 || return 102
  candump -L vcan0 >/tmp/can.log &
  dump=$!
  kernel_tests -v -sg KernelCan
  rc=$?
  kill $dump
  wait $dump
  kernel_tests -v -sg KernelCanLink || rc=$((rc + $?))
  return $rc
}

# Camera: vivid with one video capture node (/dev/video0); its input 0 is the webcam.
camera() {
  modprobe vivid n_devs=1 node_types=0x1 || return 101
  kernel_tests -v -sg KernelCamera
}

# GPIO: one gpio-sim chip with 8 lines (/dev/gpiochip0), made through configfs.
gpio() {
  modprobe configfs && modprobe gpio-sim || return 101
  mount -t configfs configfs /sys/kernel/config || return 102
  c=/sys/kernel/config/gpio-sim/boticelli
  mkdir $c && mkdir $c/bank0 && echo 8 >$c/bank0/num_lines && echo 1 >$c/live || return 103
  export GPIO_SIM_LINES=$(ls -d /sys/devices/platform/gpio-sim.*/gpiochip*)
  kernel_tests -v -sg KernelGpio
}

watchdog() {
  modprobe softdog soft_margin=5 || return 101
  kernel_tests -v -sg KernelWatchdog
}

echo "KTEST BEGIN kernel $(uname -r)"
part can can
part can-record kernel_tests -v -sg KernelCanRecord
part camera camera
part gpio gpio
part watchdog watchdog
part watchdog-reset kernel_tests -v -sg KernelWatchdogReset
echo "KTEST END"
poweroff -f
