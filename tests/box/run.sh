#!/usr/bin/env bash
# The robot computer in a box: boots the Debian 12 box under qemu, deploys the .deb and checks the service as an operator would.
#
#   tests/box/run.sh BUILD_DIR WORK_DIR
#
# BUILD_DIR is the linux-amd64 preset's build (its .deb and bin/boticelli-box-devices);
# WORK_DIR gets the box's logs (serial0.log: the box's own console, qemu.log), the ssh
# configuration and the results. The box image comes from the box cache that
# toolchain/install-deps.sh --box fills; qemu runs it with -snapshot, so every run starts
# from the same disk. Each check prints one line, `PASS name (detail)` or `FAIL name: why`;
# the last line is `N passed, N failed`. Exit 0 when every check passed, 1 otherwise, 77
# when qemu cannot run here. docs/testing.md, "The robot computer in a box", says what
# each check does. BOTICELLI_BOX_HOLD=1 keeps the box running after the checks (ssh -F
# WORK_DIR/ssh_config box) until the script is interrupted.
# Commands for the box are strings run by its shell (ssh): expanded here or there on purpose.
# shellcheck disable=SC2029,SC2016
set -euo pipefail

[ "$#" = 2 ] || { echo "usage: $0 BUILD_DIR WORK_DIR" >&2; exit 2; }
build=$(cd "$1" && pwd)
mkdir -p "$2"
work=$(cd "$2" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
if [ -n "${HOME:-}" ]; then default_box=${XDG_CACHE_HOME:-$HOME/.cache}/boticelli-box
else default_box=$repo/build/box-cache; fi
box=${BOTICELLI_BOX_CACHE:-$default_box}
port=${BOTICELLI_BOX_SSH_PORT:-2251}

die() {
  echo "test-robot: $*" >&2
  exit 1
}
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }
t_start=$(now)

command -v qemu-system-x86_64 >/dev/null ||
  { echo "SKIPPED: qemu-system-x86_64 is not installed (toolchain/install-deps.sh --box)"; exit 77; }
[ "$(uname -m)" = x86_64 ] || { echo "SKIPPED: the box is amd64 and this host is $(uname -m)"; exit 77; }
for f in root.img vmlinuz initrd.img id_ed25519 .built; do
  [ -f "$box/$f" ] || die "$box/$f is missing (toolchain/install-deps.sh --box builds the box)"
done
devices=$build/bin/boticelli-box-devices
[ -x "$devices" ] || die "$devices is missing (make package-linux-amd64 builds it)"
deb=$(find "$build" -maxdepth 1 -name 'boticelli_*_amd64.deb' -printf '%T@ %p\n' | sort -rn |
  head -n1 | cut -d' ' -f2-)
[ -n "$deb" ] || die "no boticelli_*_amd64.deb in $build (make package-linux-amd64)"

# ---------------------------------------------------------------------------------------
# The checks' bookkeeping: one line each.
passed=0
failed=0
results=$work/results.txt
: >"$results"
pass() {
  echo "PASS $1${2:+ ($2)}" | tee -a "$results"
  passed=$((passed + 1))
}
fail() {
  echo "FAIL $1: $2" | tee -a "$results"
  failed=$((failed + 1))
}

# ---------------------------------------------------------------------------------------
# The box: qemu with the box's disk (writes kept in memory), Debian's kernel, the i6300esb
# hardware watchdog, two SJA1000 CAN controllers on one CAN bus (can0 the robot's, can1 the
# ODrive emulator's), ttyS0 the box's own console (a log file), ttyS1 the robot's console
# UART on a host pty, ttyS2 the PTU adapter on the PTU emulator's pty, and ssh on a
# user-mode network that reaches nothing but the host's forwarded port.
qemu_pid=
ptu_pid=
console_pid=
cleanup() {
  if [ -n "$console_pid" ]; then kill "$console_pid" 2>/dev/null || true; fi
  if [ -n "${qmp_pid:-}" ]; then kill "$qmp_pid" 2>/dev/null || true; fi
  if [ -n "$qemu_pid" ]; then kill "$qemu_pid" 2>/dev/null || true; fi
  if [ -n "$ptu_pid" ]; then kill "$ptu_pid" 2>/dev/null || true; fi
  exec 3>&- 2>/dev/null || true
}
trap cleanup EXIT

"$devices" ptu "$work/ptu-tty" >"$work/ptu.log" 2>&1 &
ptu_pid=$!
for _ in $(seq 50); do [ -e "$work/ptu-tty" ] && break; sleep 0.1; done
[ -e "$work/ptu-tty" ] || die "the PTU emulator did not start: $(cat "$work/ptu.log")"

rm -f "$work/serial0.log" "$work/qemu.log"
boot_start=$(now)
nice qemu-system-x86_64 -accel tcg -m 1024M -smp 2 -display none -vga none \
  -kernel "$box/vmlinuz" -initrd "$box/initrd.img" \
  -append "root=/dev/vda rw console=ttyS0 quiet systemd.show_status=0" \
  -drive "file=$box/root.img,if=virtio,format=raw,snapshot=on" \
  -serial "file:$work/serial0.log" \
  -chardev pty,id=console -serial chardev:console \
  -chardev "serial,id=ptu,path=$work/ptu-tty" -serial chardev:ptu \
  -object can-bus,id=canbus0 -device kvaser_pci,canbus=canbus0,addr=0x10 \
  -device kvaser_pci,canbus=canbus0,addr=0x11 \
  -device i6300esb -watchdog-action reset -qmp "unix:$work/qmp.sock,server=on,wait=off" \
  -nic "user,model=virtio-net-pci,restrict=on,hostfwd=tcp:127.0.0.1:$port-:22" \
  </dev/null >"$work/qemu.log" 2>&1 &
qemu_pid=$!
pty=
for _ in $(seq 100); do
  pty=$(sed -n 's/.*char device redirected to \(\/dev\/pts\/[0-9]*\) (label console).*/\1/p' "$work/qemu.log")
  [ -n "$pty" ] && break
  kill -0 "$qemu_pid" 2>/dev/null || die "qemu stopped: $(cat "$work/qemu.log")"
  sleep 0.1
done
[ -n "$pty" ] || die "qemu named no pty for the console: $(cat "$work/qemu.log")"
# qemu's events (WATCHDOG, RESET), each with the host's time, into qmp.log.
qmp_pid=
(echo '{"execute":"qmp_capabilities"}'; while kill -0 "$qemu_pid" 2>/dev/null; do sleep 5; done) |
  socat - "UNIX-CONNECT:$work/qmp.sock" >"$work/qmp.log" 2>&1 &
qmp_pid=$!

cat >"$work/ssh_config" <<EOF
Host box
  HostName 127.0.0.1
  Port $port
  User robot
  IdentityFile $box/id_ed25519
  IdentitiesOnly yes
  StrictHostKeyChecking no
  UserKnownHostsFile /dev/null
  LogLevel ERROR
  ConnectTimeout 10
  ServerAliveInterval 5
  ServerAliveCountMax 6
EOF
ssh_flags=(-F "$work/ssh_config")
bx() { ssh "${ssh_flags[@]}" box "$@"; }

wait_ssh() { # SECONDS: until the box answers over ssh
  local end=$(($(date +%s) + $1))
  while [ "$(date +%s)" -lt "$end" ]; do
    bx true 2>/dev/null && return 0
    kill -0 "$qemu_pid" 2>/dev/null || die "qemu stopped: $(tail -n 5 "$work/qemu.log")"
    sleep 2
  done
  return 1
}
wait_ssh 600 || die "no ssh from the box after 600 s (the box's console: $work/serial0.log)"
boot_s=$(since "$boot_start")
echo "test-robot: the box is up (ssh) ${boot_s} s after qemu started; console on $pty"

# The base: the ODrive emulator as a unit of the box (it comes back after a reset), on the
# bus's other controller.
scp "${ssh_flags[@]}" -q "$devices" box:/tmp/ || die "cannot copy the device emulator into the box"
bx 'sudo install -m 0755 /tmp/boticelli-box-devices /usr/local/bin/ &&
  printf "%s\n" "[Unit]" "Description=ODrive emulator on can1" "After=box-devices.service" \
    "Requires=box-devices.service" "[Service]" \
    "ExecStart=/usr/local/bin/boticelli-box-devices odrive can1" \
    "[Install]" "WantedBy=multi-user.target" |
  sudo tee /etc/systemd/system/box-odrive.service >/dev/null &&
  sudo systemctl daemon-reload && sudo systemctl enable --now box-odrive.service' >/dev/null 2>&1 ||
  die "the ODrive emulator does not run in the box"

# ---------------------------------------------------------------------------------------
# Helpers of the checks.
unit_prop() { bx systemctl show -P "$1" boticelli.service || echo "(no answer)"; }
# The firmware process PID's real-time set-up line in the journal (empty if it has none).
startup_line() { # PID
  bx sudo journalctl -u boticelli "_PID=$1" --no-pager -o cat 2>&1 | grep -m1 'realtime: ' || true
}
main_pid() { unit_prop MainPID; }
active_state() { unit_prop ActiveState; }
# Frames the firmware sends the ODrives that make the wheels turn, over SECONDS (candump -L:
# "(t) can0 ID#DATA"): Set_Axis_State (0x07) to closed loop (8) and Set_Input_Vel (0x0D) with
# a velocity other than 0, for node 0 or 1.
motion_frames() { # SECONDS
  bx "timeout $1 candump -L can0 2>/dev/null | awk '{ split(\$3, f, \"#\"); id = f[1]; v = substr(f[2], 1, 8)
    if ((id == \"007\" || id == \"027\") && substr(f[2], 1, 2) == \"08\") n++
    if ((id == \"00D\" || id == \"02D\") && v != \"00000000\" && v != \"00000080\") n++ } END { print n + 0 }'" ||
    echo "candump failed"
}
# Until the unit is active/running with a MainPID other than $2, at most $1 s.
wait_running() { # SECONDS [OLD_PID]
  local end=$(($(date +%s) + $1)) state a s pid
  while [ "$(date +%s)" -lt "$end" ]; do
    state=$(bx systemctl show -p ActiveState -p SubState -p MainPID boticelli.service 2>/dev/null || true)
    a=$(sed -n 's/^ActiveState=//p' <<<"$state")
    s=$(sed -n 's/^SubState=//p' <<<"$state")
    pid=$(sed -n 's/^MainPID=//p' <<<"$state")
    if [ "$a" = active ] && [ "$s" = running ] && [ "$pid" != 0 ] && [ "$pid" != "${2:-}" ]; then
      return 0
    fi
    sleep 1
  done
  return 1
}

# The console: the robot's UART (the box's ttyS1) on the host's pty, with picocom's
# settings (115200 8N1, no flow control, raw). A reader takes everything the firmware sends
# into console.log at once, as a wire does (left unread, the pty would hold the UART back,
# which no real serial line does); console CMD writes CMD and prints the reply's lines up to
# OK or ERR (TLM and LOG lines left out), or TIMEOUT.
stty -F "$pty" 115200 cs8 -cstopb -parenb -crtscts -ixon -ixoff raw -echo
console_log=$work/console.log
: >"$console_log"
cat "$pty" >>"$console_log" &
console_pid=$!
exec 3>"$pty"
console() { # COMMAND [SECONDS]
  local off reply end=$(($(date +%s) + ${2:-10}))
  off=$(stat -c %s "$console_log")
  printf '%s\r' "$1" >&3
  while [ "$(date +%s)" -lt "$end" ]; do
    reply=$(tail -c "+$((off + 1))" "$console_log" | tr -d '\r' | grep -v -e '^TLM ' -e '^LOG ' -e '^$' || true)
    if grep -qE '^(OK|ERR )' <<<"$reply"; then
      sed -n '1,/^\(OK\|ERR \)/p' <<<"$reply"
      return 0
    fi
    sleep 0.05
  done
  echo TIMEOUT
  return 1
}
status_field() { # FIELD: from the console's status line (empty when it does not answer)
  console status | sed -n "s/^status .*\\b$1=\\([^ ]*\\).*/\\1/p" || true
}

# The gpio-sim line LINE's pull (pull-up / pull-down): what the wire does when nothing drives it.
gpio_pull() { # LINE PULL
  bx "echo $2 | sudo tee /sys/devices/platform/gpio-sim.*/gpiochip*/sim_gpio$1/pull >/dev/null"
}
# The switches as wired on the robot, after each start of the firmware: gpio-sim takes the
# bias the firmware requests (pull-up on the e-stop line) as the line's pull, which reads as
# a pressed e-stop; the closed e-stop switch holds its line low, the open bumper switches
# leave theirs high. The e-stop latched meanwhile is cleared from the console.
wire_switches() {
  gpio_pull 17 pull-down || true
  gpio_pull 27 pull-up || true
  sleep 0.5
  console clear-estop >/dev/null || true
  console resume >/dev/null || true
}

# ---------------------------------------------------------------------------------------
# 1. Install with make deploy (docs/flashing.md section 2), which must not start the
# firmware or move the base.
deploy_log=$work/deploy-install.log
if make -C "$repo" --no-print-directory deploy HOST=box PACKAGE=linux-amd64 \
     SSHFLAGS="-F $work/ssh_config" >"$deploy_log" 2>&1; then
  if grep -q "boticelli: not started" "$deploy_log"; then
    pass deploy_installs "make deploy; apt says 'not started'"
  else
    fail deploy_installs "make deploy succeeded but apt's output lacks 'boticelli: not started' ($deploy_log)"
  fi
else
  fail deploy_installs "make deploy failed: $(tail -n 3 "$deploy_log" | tr '\n' ' ')"
fi
state=$(active_state || echo unknown)
frames=$(motion_frames 3)
if [ "$state" != inactive ]; then
  fail install_does_not_start_motion "boticelli.service is '$state' after the install (expected inactive: postinst must not start it)"
elif [ "$frames" != 0 ]; then
  fail install_does_not_start_motion "$frames motion frames on can0 in 3 s after the install"
else
  pass install_does_not_start_motion "inactive, 0 motion frames on can0 in 3 s"
fi

# 1b. docs/flashing.md section 4 by hand: can0 (an SJA1000 controller, like the Pi's MCP2515
# a real CAN device with a bitrate) brought down and up with the section's commands; candump
# then shows the ODrives' heartbeats (0x001 and 0x021, every 100 ms). The install started
# nothing, boticelli-can0.service included: the firmware's start pulls it in (check 2) and
# the boot after the reset starts it (check 10).
can_by_hand=ok
bx sudo ip link set can0 down 2>"$work/can.err" || can_by_hand="ip link set can0 down: $(cat "$work/can.err")"
bx sudo ip link set can0 up type can bitrate 250000 restart-ms 100 2>"$work/can.err" ||
  can_by_hand="ip link set can0 up type can ...: $(cat "$work/can.err")"
can_details=$(bx ip -details -statistics link show can0 2>/dev/null || true)
heartbeats=$(bx timeout 2 candump can0 2>/dev/null || true)
hb0=$(grep -cE '^ *can0 +001 +\[' <<<"$heartbeats" || true)
hb1=$(grep -cE '^ *can0 +021 +\[' <<<"$heartbeats" || true)
if [ "$can_by_hand" != ok ]; then
  fail can_bringup_as_documented "$can_by_hand"
elif ! grep -q 'ERROR-ACTIVE' <<<"$can_details" || ! grep -q 'bitrate 250000' <<<"$can_details"; then
  fail can_bringup_as_documented "ip -details -statistics link show can0 lacks ERROR-ACTIVE or bitrate 250000: $(head -n 4 <<<"$can_details" | tr '\n' ' ')"
elif [ "$hb0" -lt 10 ] || [ "$hb1" -lt 10 ]; then
  fail can_bringup_as_documented "candump can0 showed $hb0 heartbeats of node 0 and $hb1 of node 1 in 2 s (expected about 20 each)"
else
  pass can_bringup_as_documented "down, up at 250 kbit/s: ERROR-ACTIVE, bitrate 250000; candump: $hb0 and $hb1 heartbeats of nodes 0 and 1 in 2 s"
fi

# 2. systemctl start returns when the firmware sent READY=1 (Type=notify).
t0=$(now)
if bx sudo systemctl start boticelli 2>"$work/start.err"; then
  ready_s=$(since "$t0")
  can_unit=$(bx systemctl is-active boticelli-can0.service 2>/dev/null || true)
  if [ "$(active_state)" != active ]; then
    fail start_reaches_ready "systemctl start returned but the unit is $(active_state)"
  elif [ "$can_unit" != active ]; then
    fail start_reaches_ready "the firmware runs, but boticelli-can0.service (its Wants=) is '$can_unit'"
  else
    pass start_reaches_ready "systemctl start returned after READY=1 in ${ready_s} s; boticelli-can0 active"
  fi
else
  ready_s=
  fail start_reaches_ready "systemctl start failed: $(cat "$work/start.err") $(bx sudo journalctl -u boticelli -n 20 --no-pager -o cat 2>&1 | tr '\n' ' ')"
fi

# 2b. docs/flashing.md section 5: journalctl -f shows the firmware's lines and follows them;
# the start-up line of the real-time set-up is among this process's lines. (Under TCG the
# overruns' warnings can fill the last ten lines -f starts with within a second.)
pid=$(main_pid)
follow=$(bx timeout 5 sudo journalctl -u boticelli -f --no-pager 2>&1 || true)
startup=$(startup_line "$pid")
if ! grep -q "boticelli\[$pid\]: " <<<"$follow"; then
  fail journal_follow_shows_startup "no line of the firmware (pid $pid) in 5 s of journalctl -u boticelli -f: $(tail -n 3 <<<"$follow" | tr '\n' ' ')"
elif [ -z "$startup" ]; then
  fail journal_follow_shows_startup "the journal has no 'realtime: ' line of the firmware (pid $pid)"
else
  pass journal_follow_shows_startup "$(grep -c "boticelli\[$pid\]: " <<<"$follow") lines of pid $pid in 5 s; $startup"
fi

# 3. systemctl status shows the mission's state (STATUS=, once a second).
wire_switches
sleep 2
status_text=$(unit_prop StatusText || true)
# As docs/flashing.md section 5 shows it: systemctl status's Active: and Status: lines.
status_out=$(bx systemctl status boticelli --no-pager 2>&1 || true)
status_line=$(grep -m1 -o 'Status: ".*"' <<<"$status_out" || true)
if ! [[ "$status_text" =~ state=[a-z]+\ cycle=[0-9]+\ healthy=[01]\ estop=[a-z]+\ target=[a-z]+ ]]; then
  fail status_shows_mission_state "StatusText is '$status_text' (expected state=... cycle=N healthy=N estop=... target=...)"
elif ! grep -q 'Active: active (running)' <<<"$status_out" || [[ "$status_line" != *state=* ]]; then
  fail status_shows_mission_state "systemctl status boticelli lacks 'Active: active (running)' or a Status: line with state=: $(head -n 5 <<<"$status_out" | tr '\n' ' ')"
else
  pass status_shows_mission_state "systemctl status: active (running), $status_line"
fi

# 4. The console answers on the UART: status, and its round trip (median of 5).
times=()
reply=
for _ in 1 2 3 4 5; do
  t0=$(now)
  reply=$(console status 10 || true)
  times+=("$(awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.3f", b - a }')")
done
round_trip=$(printf '%s\n' "${times[@]}" | sort -n | sed -n 3p)
if grep -q '^status state=' <<<"$reply" && grep -qx OK <<<"$reply"; then
  pass console_round_trip "status over the console pty, median ${round_trip} s of 5"
else
  fail console_round_trip "no status reply on the console pty (got: $(tr '\n' ' ' <<<"$reply"))"
fi

# 4b. picocom itself, as docs/flashing.md section 5 runs it from the laptop (115200 baud, the
# rest picocom's defaults: 8N1, no flow control), here on the console's pty. The operator's
# typing is its --initstring; the wire's reader is paused meanwhile, so picocom alone reads.
kill "$console_pid" 2>/dev/null || true
wait "$console_pid" 2>/dev/null || true
picocom_out=$(timeout 6 picocom -b 115200 -q --initstring "$(printf 'status\r')" --exit-after 3000 \
  "$pty" </dev/null 2>&1 | tr -d '\r' || true)
stty -F "$pty" 115200 cs8 -cstopb -parenb -crtscts -ixon -ixoff raw -echo
cat "$pty" >>"$console_log" &
console_pid=$!
if grep -q '^status state=' <<<"$picocom_out" && grep -qx OK <<<"$picocom_out"; then
  pass picocom_console "picocom -b 115200: $(grep -m1 '^status state=' <<<"$picocom_out" | cut -c 1-50) ... OK"
else
  fail picocom_console "no status reply through picocom -b 115200 (got: $(head -c 300 <<<"$picocom_out" | tr '\n' ' '))"
fi

# 5. Fault classes of docs/reliability.md the service survives, each with the same process.
pid=$(main_pid)
# CAN link down and up: the base is held, then healthy again.
bx sudo ip link set can0 down || true
sleep 3
down_healthy=$(status_field healthy)
bx sudo ip link set can0 up || true
ok=0
for _ in $(seq 20); do
  [ "$(status_field healthy)" = 1 ] && { ok=1; break; }
  sleep 1
done
if [ "$ok" = 1 ] && [ "$(main_pid)" = "$pid" ]; then
  pass fault_can_link_down_up "healthy=$down_healthy while down, healthy=1 again, same process"
else
  fail fault_can_link_down_up "after can0 down/up: healthy=$(status_field healthy), pid $(main_pid) (was $pid), state $(active_state)"
fi
# The camera's module unloaded and loaded again (the webcam unplugged and plugged in): its
# device is unbound first (as an unplug: the firmware's descriptor then fails with ENODEV and
# is closed), then vivid is unloaded and loaded.
reload=ok
bx 'echo vivid.0 | sudo tee /sys/bus/platform/drivers/vivid/unbind >/dev/null' || reload="unbind failed"
sleep 3
cam_healthy=$(status_field healthy)
bx sudo modprobe -r vivid 2>"$work/modprobe.err" || reload="modprobe -r vivid: $(cat "$work/modprobe.err")"
bx sudo modprobe vivid || reload="$reload; modprobe vivid failed"
ok=0
for _ in $(seq 25); do
  [ "$(status_field healthy)" = 1 ] && { ok=1; break; }
  sleep 1
done
if [ "$reload" != ok ]; then
  fail fault_camera_reload "$reload"
elif [ "$ok" = 1 ] && [ "$(main_pid)" = "$pid" ]; then
  pass fault_camera_reload "healthy=$cam_healthy while gone, healthy=1 again, same process"
else
  fail fault_camera_reload "after vivid unloaded and loaded: healthy=$(status_field healthy), pid $(main_pid) (was $pid), state $(active_state)"
fi
# A broken e-stop wire: the normally closed switch's line floats high = pressed: the e-stop
# latches and the base stays stopped; mended, clear-estop and resume run on.
estop_before=$(status_field estop)
gpio_pull 17 pull-up || true
sleep 2
estop=$(status_field estop)
frames=$(motion_frames 2)
gpio_pull 17 pull-down || true
cleared=$(console clear-estop | tail -n1)
resumed=$(console resume | tail -n1)
if [ "$estop_before" != none ]; then
  fail fault_estop_wire_broken "estop=$estop_before before the wire broke (expected none)"
elif [ "$estop" = button ] && [ "$frames" = 0 ] && [ "$(main_pid)" = "$pid" ]; then
  pass fault_estop_wire_broken "estop=none, then button, 0 motion frames, same process; clear-estop $cleared, resume $resumed"
else
  fail fault_estop_wire_broken "with the e-stop line high: estop=$estop, $frames motion frames in 2 s, pid $(main_pid) (was $pid)"
fi

# 6. journald keeps the firmware's priorities: its warnings and errors (the console's log
# ring, `log show`, has every line with its level) are exactly what journalctl -p warning
# lists for the firmware's process, and its info lines are not among them.
sleep 1
ring_all=$(console "log show" 20 || true)
# The ring keeps the last 64 lines; once it has wrapped the journal holds older ones too,
# so only "every ring warning is in the journal, no ring info line is" can be checked.
ring_lines=$(grep -c '^log t_s=' <<<"$ring_all" || true)
ring=$(sed -n 's/^log t_s=[-0-9.]* \(warn\|error\) //p' <<<"$ring_all" | sort -u)
ring_info=$(sed -n 's/^log t_s=[-0-9.]* info //p' <<<"$ring_all" | sort -u)
journal=$(bx sudo journalctl -b "_PID=$pid" -p warning -o cat --no-pager | sort -u)
missing=$(comm -23 <(echo "$ring") <(echo "$journal") | sed '/^$/d')
extra=
if [ "$ring_lines" -lt 64 ]; then
  extra=$(comm -13 <(echo "$ring") <(echo "$journal") | sed '/^$/d')
fi
info_as_warning=$(comm -12 <(echo "$ring_info") <(echo "$journal") | sed '/^$/d')
if [ -z "$ring" ]; then
  fail journal_priorities "the console's log show has no warning to compare"
elif [ -n "$missing" ]; then
  fail journal_priorities "$(wc -l <<<"$missing") of the console's $(wc -l <<<"$ring") warning/error lines are not in journalctl -p warning, e.g. '$(head -n1 <<<"$missing")' (the firmware's LOG lines reach only the console)"
elif [ -n "$extra" ] || [ -n "$info_as_warning" ]; then
  fail journal_priorities "journalctl -p warning lists lines that are not warnings: $(echo "$extra" "$info_as_warning" | head -n 3 | tr '\n' ' ')"
else
  if [ "$ring_lines" -lt 64 ]; then
    pass journal_priorities "$(wc -l <<<"$journal") warning/error lines, the same in journalctl -p warning and log show"
  else
    pass journal_priorities "the ring's $(wc -l <<<"$ring") warning/error lines all in journalctl -p warning, none of its info lines (the ring had wrapped: the journal's older lines not compared)"
  fi
fi

# 7. A hung firmware (SIGSTOP) is killed by systemd's watchdog (WatchdogSec=2s) and restarted.
restarts=$(unit_prop NRestarts)
t0=$(now)
bx sudo systemctl kill -s SIGSTOP boticelli || true
if wait_running 30 "$pid"; then
  hung_s=$(since "$t0")
  if bx sudo journalctl -u boticelli -b --no-pager | grep -q 'Watchdog timeout'; then
    pass hung_firmware_restarted "watchdog timeout, running again after ${hung_s} s (NRestarts $restarts -> $(unit_prop NRestarts))"
  else
    fail hung_firmware_restarted "restarted, but no 'Watchdog timeout' in the journal"
  fi
else
  fail hung_firmware_restarted "not running again 30 s after SIGSTOP: $(active_state), NRestarts $(unit_prop NRestarts)"
fi

# 8. The exit codes: a signal ends the mission in order with exit code 3, which the unit
# does not restart (docs/flashing.md: "3 ... a signal — not restarted").
wait_running 30 || true
pid=$(main_pid)
restarts=$(unit_prop NRestarts)
bx sudo kill -TERM "$pid" || true
sleep 6
# The stopped process's exit status: ExecMainStatus while the unit is not restarted (a
# restart, itself a failure here, would show the new process's). systemd logs "Main process
# exited" only for a failure, and exit 3 is a success (SuccessExitStatus=3).
code=$(unit_prop ExecMainStatus)
state=$(active_state)
if [ "$code" = 3 ] && [ "$state" != active ] && [ "$state" != activating ] && [ "$(unit_prop NRestarts)" = "$restarts" ]; then
  pass signal_exit_3_not_restarted "exit code 3, unit $state, not restarted"
else
  fail signal_exit_3_not_restarted "after SIGTERM: exit code $code, unit $state, NRestarts $restarts -> $(unit_prop NRestarts)"
fi

# 9. An upgrade over a running firmware with a locally changed conffile: prerm stops the
# firmware, postinst does not start it again, and the local change is kept (the shipped
# conffile changed too: dpkg's question answered as --force-confold would). The new version
# is this .deb repacked as VERSION+box1 with one more comment line in its conffile, and is
# installed with make deploy DEB=FILE.
bx sudo systemctl reset-failed boticelli >/dev/null 2>&1 || true
bx sudo systemctl start boticelli 2>/dev/null || true
uw=$work/upgrade
rm -rf "$uw" && mkdir -p "$uw"
dpkg-deb -R "$deb" "$uw/pkg" || die "cannot unpack $deb for the upgrade"
ver=$(sed -n 's/^Version: //p' "$uw/pkg/DEBIAN/control")
sed -i "s/^Version: .*/Version: $ver+box1/" "$uw/pkg/DEBIAN/control"
echo "# (a later version's comment)" >>"$uw/pkg/etc/boticelli/boticelli.conf"
up=$uw/boticelli_${ver}+box1_amd64.deb
dpkg-deb -b --root-owner-group "$uw/pkg" "$up" >/dev/null || die "cannot repack the .deb for the upgrade"
bx "echo '# a local change' | sudo tee -a /etc/boticelli/boticelli.conf >/dev/null"
before=$(active_state)
up_log=$work/deploy-upgrade.log
if make -C "$repo" --no-print-directory deploy HOST=box DEB="$up" \
     SSHFLAGS="-F $work/ssh_config" >"$up_log" 2>&1; then
  up_ok=1
else
  up_ok=0
fi
state=$(active_state)
frames=$(motion_frames 3)
version=$(bx dpkg-query -W -f='\${Version}' boticelli)
if [ "$up_ok" != 1 ]; then
  fail upgrade_does_not_start_motion "the upgrade failed: $(tail -n 3 "$up_log" | tr '\n' ' ')"
elif [ "$frames" != 0 ]; then
  fail upgrade_does_not_start_motion "after the upgrade (was $before): unit $state, $frames motion frames in 3 s"
elif [ "$before" = active ]; then
  # A running firmware is started again held (DIR/start-held) until the operator's resume.
  paused=$(status_field paused || true)
  if [ "$state" = active ] && [ "$paused" = 1 ]; then
    pass upgrade_does_not_start_motion "was active, now $version, active and held (paused=1), 0 motion frames in 3 s"
  else
    fail upgrade_does_not_start_motion "after the upgrade (was active): unit $state, paused=$paused (expected active and held)"
  fi
elif [ "$state" != inactive ] && [ "$state" != failed ]; then
  fail upgrade_does_not_start_motion "after the upgrade (was $before): unit $state (expected stopped)"
else
  pass upgrade_does_not_start_motion "was $before, now $version and $state (stopped by prerm), 0 motion frames in 3 s"
fi
if bx grep -qx "'# a local change'" /etc/boticelli/boticelli.conf &&
   ! bx grep -q "'a later version'" /etc/boticelli/boticelli.conf; then
  pass conffile_kept_on_upgrade "the local change kept$(bx test -f /etc/boticelli/boticelli.conf.dpkg-dist && echo ', the new one as boticelli.conf.dpkg-dist')"
else
  fail conffile_kept_on_upgrade "the local change to /etc/boticelli/boticelli.conf is gone or the new one replaced it ($up_log)"
fi

# 9b. docs/flashing.md section 6: systemctl restart (after a configuration change) gives a new
# process, whose start-up lines journalctl -n 20 shows.
pid=$(main_pid)
if bx sudo systemctl restart boticelli 2>"$work/restart.err" && wait_running 30 "$pid"; then
  new_pid=$(main_pid)
  last20=$(bx sudo journalctl -u boticelli -n 20 --no-pager 2>&1 || true)
  startup=$(startup_line "$new_pid")
  if ! grep -q "boticelli\[$new_pid\]: " <<<"$last20"; then
    fail restart_as_documented "restarted (pid $new_pid), but journalctl -u boticelli -n 20 has none of its lines: $(tail -n 3 <<<"$last20" | tr '\n' ' ')"
  elif [ -z "$startup" ]; then
    fail restart_as_documented "restarted (pid $new_pid), but the journal has no 'realtime: ' line of it"
  else
    pass restart_as_documented "systemctl restart: pid $pid -> $new_pid; journalctl -n 20 shows it; $startup"
  fi
else
  fail restart_as_documented "systemctl restart failed or no new process: $(cat "$work/restart.err") unit $(active_state)"
fi
wire_switches

# 9c. docs/flashing.md section 5, "Running by hand": with the service stopped, the operator
# (in the groups video, dialout and gpio, as the section says) runs the firmware with a pty
# console and talks to it with picocom in the box, then runs a short mission.
bx sudo systemctl stop boticelli || true
bx sudo usermod -aG video,dialout,gpio robot || true
hand=$(bx 'rm -f /tmp/hand.err; boticelli --console pty </dev/null >/tmp/hand.out 2>/tmp/hand.err & h=$!
  p=; for i in $(seq 100); do
    p=$(sed -n "s/.*console on \(\/dev\/pts\/[0-9]*\).*/\1/p" /tmp/hand.err); [ -n "$p" ] && break; sleep 0.2; done
  [ -n "$p" ] || { echo "no console pty: $(head -c 300 /tmp/hand.err)"; kill -INT $h; exit 0; }
  sleep 3
  timeout 6 picocom -b 115200 -q --initstring "$(printf "status\r")" --exit-after 3000 "$p" </dev/null | tr -d "\r" | grep -m1 "^status state="
  kill -INT $h; wait $h; echo "exit $?"' 2>&1 || true)
if grep -q '^status state=' <<<"$hand" && grep -qx 'exit 3' <<<"$hand"; then
  pass by_hand_console_pty "boticelli --console pty, picocom on its pty: $(grep -m1 '^status state=' <<<"$hand" | cut -c 1-50); SIGINT: exit 3"
else
  fail by_hand_console_pty "$(tr '\n' ' ' <<<"$hand" | head -c 400)"
fi
# Its console is the terminal (stdio): the operator's typing after the start is what
# wire_switches does for the service (the e-stop line's pull set as the closed switch holds
# it, then clear-estop and resume). The mission ends within its 5 cycles (found, or nothing
# left to explore in a room of test bars). Meanwhile docs/flashing.md's check of the
# ODrives' watchdog feed runs: `candump -td can0,00D:01F` lists the Set_Input_Vel frames with
# the time since the one before; while a wheel turns, each axis must get its next setpoint
# well inside the ODrives' 0.2 s watchdog.
t0=$(now)
cycles=$(bx 'rm -rf /tmp/st; (timeout 600 candump -td can0,00D:01F >/tmp/setpoints.log 2>&1 &)
  { sleep 3; echo pull-down | sudo tee /sys/devices/platform/gpio-sim.*/gpiochip*/sim_gpio17/pull >/dev/null
    sleep 0.5; printf "clear-estop\nresume\n"
    while pgrep -x boticelli >/dev/null; do sleep 1; done; } |
    timeout 600 boticelli --max-cycles 5 --state /tmp/st >/tmp/cycles.out 2>&1; echo "exit $?"
  pkill -x candump; grep -a -m1 "^MISSION" /tmp/cycles.out; ls /tmp/st' 2>&1 || true)
cycles_s=$(since "$t0")
mission=$(grep -m1 -o '^MISSION .*' <<<"$cycles" || true)
n_cycles=$(sed -n 's/.* cycles=\([0-9]*\) .*/\1/p' <<<"$mission")
code=$(sed -n 's/^exit //p' <<<"$cycles")
if [ -z "$mission" ] || [ -z "$n_cycles" ] || [ "$n_cycles" -gt 5 ] || { [ "$code" != 0 ] && [ "$code" != 3 ]; }; then
  fail by_hand_max_cycles "after ${cycles_s} s: $(tr '\n' ' ' <<<"$cycles" | head -c 400)"
elif ! grep -q 'mission.state' <<<"$cycles"; then
  fail by_hand_max_cycles "no mission state in /tmp/st after the run"
else
  pass by_hand_max_cycles "boticelli --max-cycles 5 --state /tmp/st: $(cut -c 1-90 <<<"$mission")...; exit $code, ${cycles_s} s"
fi
# The setpoints: candump -td's lines "(0.010123)  can0  00D   [8]  VV VV VV VV ...": per
# node, the time from a frame with a velocity other than 0 to the node's next frame.
gaps=$(bx cat /tmp/setpoints.log 2>/dev/null | awk '
  { gsub(/[()]/, "", $1); t += $1; id = $3; v = $5 $6 $7 $8
    if (id != "00D" && id != "02D") next
    if (moving[id]) { g = t - last[id]; if (g > max) max = g; n++ }
    last[id] = t; moving[id] = (v != "00000000" && v != "00000080") }
  END { printf "%d %.3f\n", n, max }' || echo "0 0")
read -r n_gaps max_gap <<<"$gaps"
if [ "${n_gaps:-0}" -lt 10 ]; then
  fail setpoints_feed_odrive_watchdog "candump -td can0,00D:01F saw ${n_gaps:-0} setpoints after a turning wheel's (the mission did not drive?)"
elif awk -v g="$max_gap" 'BEGIN { exit !(g < 0.2) }'; then
  pass setpoints_feed_odrive_watchdog "$n_gaps setpoints after a turning wheel's, the longest ${max_gap} s after it (the ODrives' watchdog: 0.2 s)"
else
  fail setpoints_feed_odrive_watchdog "a turning wheel's axis waited ${max_gap} s for its next setpoint (the ODrives' watchdog idles it at 0.2 s)"
fi

# 10. A hung system: everything starved by a SCHED_FIFO 99 loop on each CPU (real-time
# throttling off), so neither the firmware nor systemd runs: the hardware watchdog
# (i6300esb, armed by the firmware at [watchdog] timeout_ms = 12000) resets the box. Then
# the enabled unit starts at boot: boot-to-READY from the journal.
bx sudo systemctl start boticelli 2>/dev/null || true
if [ "$(status_field watchdog)" != armed ]; then
  fail hardware_watchdog_resets "the console's status says watchdog=$(status_field watchdog), not armed"
  boot_ready_s=
else
  # A reset loses what is not on the disk yet: the earlier checks' writes (the conffile's
  # local change above, made with a plain shell redirection) are flushed first, as only the
  # firmware's own files are written with fsync. (Without this the box came back with NULs
  # in /etc/boticelli/boticelli.conf and the firmware rightly refused it.)
  bx sudo sync || true
  t0=$(now)
  # ssh itself is starved once the loops run: the command is left to time out.
  bx 'sudo sh -c "echo -1 >/proc/sys/kernel/sched_rt_runtime_us;
    for c in 0 1; do nohup taskset -c \$c chrt -f 99 sh -c \"while :; do :; done\" >/dev/null 2>&1 & done"' \
    >/dev/null 2>&1 &
  reset_s=
  for _ in $(seq 60); do
    event=$(grep -m1 '"event": *"WATCHDOG"' "$work/qmp.log" || true)
    if [ -n "$event" ]; then
      secs=$(sed -n 's/.*"seconds": *\([0-9]*\).*/\1/p' <<<"$event")
      usecs=$(sed -n 's/.*"microseconds": *\([0-9]*\).*/\1/p' <<<"$event")
      reset_s=$(awk -v s="$secs" -v u="$usecs" -v a="$t0" 'BEGIN { printf "%.1f", s + u / 1e6 - a }')
      break
    fi
    sleep 0.5
  done
  if [ -z "$reset_s" ]; then
    fail hardware_watchdog_resets "the hung box was not reset within 30 s (no WATCHDOG event from qemu)"
  elif awk -v s="$reset_s" 'BEGIN { exit !(s >= 10 && s <= 16) }'; then
    pass hardware_watchdog_resets "reset ${reset_s} s after the hang began (timeout 12 s)"
  else
    fail hardware_watchdog_resets "reset ${reset_s} s after the hang began (expected 12 s, 10 to 16)"
  fi
  boot_ready_s=
  if wait_ssh 600 && wait_running 120; then
    boot_ready_s=$(bx "sudo journalctl -b -o short-monotonic --no-pager -u boticelli" |
      sed -n 's/^\[ *\([0-9]*\.[0-9]\).*\].*Started boticelli.service.*/\1/p' | head -n1)
    can_unit=$(bx systemctl is-active boticelli-can0.service 2>/dev/null || true)
    can_boot=$(bx ip -details link show can0 2>/dev/null || true)
    if [ "$can_unit" != active ] || ! grep -q 'bitrate 250000' <<<"$can_boot"; then
      fail enabled_unit_ready_after_reset "after the boot boticelli-can0.service is '$can_unit' and can0 says: $(grep -o 'can state [A-Z-]*\|bitrate [0-9]*' <<<"$can_boot" | tr '\n' ' ')"
    elif [ -n "$boot_ready_s" ]; then
      pass enabled_unit_ready_after_reset "READY=1 ${boot_ready_s} s after the kernel started; boticelli-can0 brought can0 up at 250 kbit/s"
    else
      fail enabled_unit_ready_after_reset "running, but no 'Started boticelli.service' in this boot's journal"
    fi
  else
    fail enabled_unit_ready_after_reset "the box or the firmware did not come back after the reset: $(active_state 2>&1); $(bx sudo journalctl -b -u boticelli --no-pager -o cat -n 6 2>&1 | tr '\n' ' ')"
  fi
fi

# 11. apt purge removes what the package made: its files, the conffile, the state
# directory, the user, the units' enablement; it leaves the group gpio (other users of the
# GPIO chip may rely on it).
purge_log=$work/purge.log
bx sudo apt-get purge -y boticelli >"$purge_log" 2>&1 || true
left=$(bx 'for p in /usr/bin/boticelli /etc/boticelli /var/lib/boticelli /usr/lib/systemd/system/boticelli.service \
    /lib/systemd/system/boticelli.service /usr/lib/udev/rules.d/60-boticelli.rules \
    /lib/udev/rules.d/60-boticelli.rules /usr/share/doc/boticelli; do [ -e "$p" ] && echo "$p"; done
  find /etc/systemd/system -name "boticelli*" 2>/dev/null
  getent passwd boticelli >/dev/null && echo "user boticelli"
  dpkg-query -W -f="\${db:Status-Status}" boticelli 2>/dev/null | grep -v "^not-installed$" | sed "s/^/dpkg: /"
  true' | tr '\n' ' ')
if [ -z "$left" ]; then
  pass purge_removes_everything "files, conffile, state, user and enablement gone"
else
  fail purge_removes_everything "left after apt purge: $left"
fi

if [ -n "${BOTICELLI_BOX_HOLD:-}" ]; then
  echo "test-robot: the box stays up until this is interrupted: ssh -F $work/ssh_config box; console $pty"
  wait "$qemu_pid" || true
fi
echo "test-robot: box up in ${boot_s} s; start to READY ${ready_s:-?} s; boot to READY ${boot_ready_s:-?} s; console round trip ${round_trip:-?} s; total $(since "$t_start") s"
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
