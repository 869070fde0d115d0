#!/usr/bin/env bash
# Installs, from Debian's packages only, what Boticelli's build, tests and benchmarks need.
#
#   toolchain/install-deps.sh            host build and tests (sim, asan presets)
#   toolchain/install-deps.sh --cross    also the aarch64 cross compiler, qemu-user and the
#                                        :arm64 libraries (rpi4 preset)
#   toolchain/install-deps.sh --armhf    also the 32-bit arm-linux-gnueabihf compiler and
#                                        the :armhf libraries (armhf preset)
#   toolchain/install-deps.sh --bench    also the peers the benchmarks compare against
#                                        (OctoMap; OpenCV comes with the tests' set); never
#                                        needed by the firmware
#   toolchain/install-deps.sh --analyze  also clang-tidy and cppcheck (make analyze)
#   toolchain/install-deps.sh --kernel   also what the kernel-in-the-loop test needs (qemu,
#                                        busybox, can-utils, the kernel headers) and Debian's
#                                        amd64 kernel and kernel source packages, fetched with
#                                        apt-get download into the kernel cache (below)
#   toolchain/install-deps.sh --box      also --kernel, and the robot computer in a box
#                                        (make test-robot): mmdebstrap, picocom, socat, ssh;
#                                        builds the box's Debian 12 image into the box cache
#
# The kernel cache is $BOTICELLI_KERNEL_CACHE, by default ~/.cache/boticelli-kernel (so fresh
# clones share it); it holds the two .deb files (about 210 MB), never installed into the host.
# The box cache is $BOTICELLI_BOX_CACHE, by default ~/.cache/boticelli-box: a 2 GiB disk image
# made by toolchain/build-box.sh from Debian's packages and the kernel cache's kernel.
# Idempotent: when everything is present it prints nothing and exits 0.
set -euo pipefail

want_cross=0
want_bench=0
want_armhf=0
want_analyze=0
want_kernel=0
want_box=0
for arg in "$@"; do
  case "$arg" in
    --cross) want_cross=1 ;;
    --bench) want_bench=1 ;;
    --armhf) want_armhf=1 ;;
    --analyze) want_analyze=1 ;;
    --kernel) want_kernel=1 ;;
    --box) want_kernel=1; want_box=1 ;;
    -h|--help) sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "install-deps: unknown option '$arg' (try --help)" >&2; exit 2 ;;
  esac
done

# systemd: systemd-analyze for the unit's rating; libsdformat-dev: the test that loads every
# world with SDFormat (tests only, never linked into the firmware); clang-14 with its runtime
# (libFuzzer, sanitizers): the fuzz preset, which make test runs. libtomlplusplus-dev: the
# configuration file's parser (a shared library, libtomlplusplus3, which the .deb depends on).
# libopencv-dev, opencv-doc: tests only, never linked into the firmware: the stereo tests run
# the tracker on the Middlebury "Aloe" pair that opencv-doc ships in its sample data (read with
# OpenCV's imread), and the camera model is checked against OpenCV's.
host_pkgs=(
  g++ make cmake ninja-build pkg-config clang-format file systemd clang-14 libclang-rt-14-dev
  libeigen3-dev libcpputest-dev libgpiod-dev libtinyxml2-dev libpng-dev libtomlplusplus-dev
  libsdformat-dev libopencv-dev opencv-doc
)
# lintian: the rpi4 preset's test of the .deb (tests/packaging).
cross_pkgs=(
  g++-aarch64-linux-gnu qemu-user
  libcpputest-dev:arm64 libgpiod-dev:arm64 libtinyxml2-dev:arm64 libpng-dev:arm64
  libtomlplusplus-dev:arm64 lintian
)
armhf_pkgs=(
  g++-arm-linux-gnueabihf
  libcpputest-dev:armhf libgpiod-dev:armhf libtinyxml2-dev:armhf libtomlplusplus-dev:armhf
)
bench_pkgs=(liboctomap-dev)
analyze_pkgs=(clang-tidy-14 cppcheck)
# tests/kernel: qemu boots Debian's kernel with a busybox initramfs; candump records the CAN
# bus; binutils (objcopy) reads the modules' dependencies; xz-utils unpacks the kernel source.
# The headers of the image's kernel ABI (for the out-of-tree gpio-sim module) are added below.
kernel_pkgs=(qemu-system-x86 busybox-static cpio can-utils binutils xz-utils)
# The box (tests/box): mmdebstrap builds its image (e2fsprogs makes the file system), ssh
# reaches it, picocom and socat speak on its console's pty.
box_pkgs=(mmdebstrap e2fsprogs openssh-client picocom socat)

pkgs=("${host_pkgs[@]}")
[ "$want_cross" = 1 ] && pkgs+=("${cross_pkgs[@]}")
[ "$want_armhf" = 1 ] && pkgs+=("${armhf_pkgs[@]}")
[ "$want_bench" = 1 ] && pkgs+=("${bench_pkgs[@]}")
[ "$want_analyze" = 1 ] && pkgs+=("${analyze_pkgs[@]}")
[ "$want_kernel" = 1 ] && pkgs+=("${kernel_pkgs[@]}")
[ "$want_box" = 1 ] && pkgs+=("${box_pkgs[@]}")

repo=$(cd "$(dirname "$0")/.." && pwd)
if [ -n "${HOME:-}" ]; then default_cache=${XDG_CACHE_HOME:-$HOME/.cache}/boticelli-kernel
else default_cache=$repo/build/kernel-cache; fi
kernel_cache=${BOTICELLI_KERNEL_CACHE:-$default_cache}
if [ -n "${HOME:-}" ]; then default_box=${XDG_CACHE_HOME:-$HOME/.cache}/boticelli-box
else default_box=$repo/build/box-cache; fi
box_cache=${BOTICELLI_BOX_CACHE:-$default_box}
pkg_installed() {
  [ "$(dpkg-query -W -f='${db:Status-Status}' "$1" 2>/dev/null || true)" = installed ]
}
# The kernel cache is complete when it holds one image, the source of the same version, and
# that version's headers are installed.
kernel_ready() {
  local img abi ver
  img=$(ls "$kernel_cache"/linux-image-*-amd64_*_amd64.deb 2>/dev/null | head -n1)
  [ -n "$img" ] || return 1
  abi=$(dpkg-deb -f "$img" Package) && abi=${abi#linux-image-}
  ver=$(dpkg-deb -f "$img" Version)
  ls "$kernel_cache"/linux-source-*_"$ver"_all.deb >/dev/null 2>&1 || return 1
  pkg_installed "linux-headers-$abi"
}

if ! command -v dpkg-query >/dev/null 2>&1 || ! command -v apt-get >/dev/null 2>&1; then
  echo "install-deps: this script needs a Debian-based system (dpkg and apt-get); install by hand: ${pkgs[*]}" >&2
  exit 1
fi

native=$(dpkg --print-architecture)
missing=()
for p in "${pkgs[@]}"; do
  q=$p
  case "$p" in *:*) ;; *) q="$p:$native" ;; esac
  status=$(dpkg-query -W -f='${db:Status-Status}' "$q" 2>/dev/null || true)
  # Architecture-independent packages (e.g. Eigen) are known by their plain name.
  [ -n "$status" ] || status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [ "$status" = "installed" ] || missing+=("$p")
done
need_kernel=0
if [ "$want_kernel" = 1 ] && ! kernel_ready; then need_kernel=1; fi
# The box image is (re)built by its own script, which checks its stamp first.
build_box() {
  [ "$want_box" = 1 ] || return 0
  "$repo/toolchain/build-box.sh" "$kernel_cache" "$box_cache"
}
if [ "${#missing[@]}" = 0 ] && [ "$need_kernel" = 0 ]; then
  build_box
  exit 0
fi

sudo=()
if [ "$(id -u)" != 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo=(sudo)
  else
    echo "install-deps: missing packages (${missing[*]}) and not root, and sudo is not available" >&2
    exit 1
  fi
fi

[ "${#missing[@]}" = 0 ] || echo "install-deps: installing ${missing[*]}"
needs_arch() {
  local arch=$1
  printf '%s\n' "${missing[@]}" | grep -q ":$arch\$" || return 1
  dpkg --print-foreign-architectures | grep -qx "$arch" && return 1
  return 0
}
for arch in arm64 armhf; do
  if needs_arch "$arch"; then
    "${sudo[@]}" dpkg --add-architecture "$arch"
  fi
done

export DEBIAN_FRONTEND=noninteractive
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# A mirror in mid-sync can fail one index file; retry, then go on with the lists apt has
# (the install below still fails clearly if a package cannot be had).
updated=0
for attempt in 1 2 3; do
  if "${sudo[@]}" apt-get update -qq >"$log" 2>&1; then updated=1; break; fi
  sleep $((attempt * 5))
done
if [ "$updated" = 0 ]; then
  grep -E '^(E|W):' "$log" | head -n 5 >&2 || true
  echo "install-deps: warning: 'apt-get update' reported errors; trying the install with the package lists apt has" >&2
fi
if [ "${#missing[@]}" -gt 0 ] &&
   ! "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >"$log" 2>&1; then
  tail -n 30 "$log" >&2
  echo "install-deps: could not install: ${missing[*]}" >&2
  exit 1
fi

if [ "$need_kernel" = 1 ]; then
  # The kernel the linux-image-amd64 dependency names now (e.g. linux-image-6.1.0-57-amd64),
  # the source package of the same version and that ABI's headers: all three move together
  # when Debian's kernel ABI number changes.
  image=$(apt-cache depends linux-image-amd64 2>/dev/null |
          sed -n 's/^ *Depends: \(linux-image-[0-9].*-amd64\)$/\1/p' | head -n1)
  [ -n "$image" ] || { echo "install-deps: apt does not know linux-image-amd64's kernel" >&2; exit 1; }
  abi=${image#linux-image-}
  ver=$(apt-cache show "$image" | sed -n 's/^Version: //p' | head -n1)
  series=${abi%%.0-*}  # 6.1.0-57 -> 6.1
  echo "install-deps: fetching $image $ver and linux-source-$series into $kernel_cache"
  if ! "${sudo[@]}" apt-get install -y -qq --no-install-recommends "linux-headers-$abi=$ver" >"$log" 2>&1; then
    tail -n 30 "$log" >&2
    echo "install-deps: could not install linux-headers-$abi" >&2
    exit 1
  fi
  mkdir -p "$kernel_cache"
  rm -f "$kernel_cache"/linux-image-*.deb "$kernel_cache"/linux-source-*.deb
  # apt-get download writes into the current directory; as root it warns about the sandbox.
  if ! (cd "$kernel_cache" && apt-get download -qq "$image=$ver" "linux-source-$series=$ver") >"$log" 2>&1; then
    tail -n 30 "$log" >&2
    echo "install-deps: could not download $image and linux-source-$series $ver" >&2
    exit 1
  fi
fi
build_box
echo "install-deps: done"
