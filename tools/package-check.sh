#!/usr/bin/env bash
# Checks the Debian package the way a robot builder meets it, in a clean Debian 12 root of the package's architecture
# (made once with mmdebstrap, kept in ~/.cache/mcslam/; unpacked afresh for every check): install with apt (its
# dependencies from Debian), the files (manual pages included) and the system user in place, mcslamd started as
# systemd starts it (the unit's ExecStart, as the unit's user, with $STATE_DIRECTORY) with the packaged configuration
# (a simulated rig) becomes ready and publishes poses over shared memory and UDP, a consumer built with
# find_package(mcslam) against the installed headers reads them, SIGTERM stops it cleanly. Then the root boots with
# systemd (systemd-nspawn --boot; skipped with a message where nspawn cannot boot it): `systemctl start` brings the
# daemon up under the unit's sandbox and system-call filter, poses arrive over both transports, a daemon stopped dead
# is restarted by the watchdog, `systemctl stop` stops it, and `systemd-analyze security` scores the running unit.
# Last, an upgrade keeps a changed configuration and the state; remove keeps both, purge removes them.
# An arm64 package runs in an arm64 root under qemu-user, which this script registers with binfmt_misc when missing.
# Needs root (chroot, mounts, nspawn).
#
# Usage: tools/package-check.sh [DEB]      (default: the newest dist/mcslam_*_<this machine's arch>.deb;
#                                          tools/package.sh makes it)
set -euo pipefail
cd "$(dirname "$0")/.."
[ "$(id -u)" -eq 0 ] || { echo "package-check: needs root (chroot and mounts)" >&2; exit 2; }
deb="${1:-$(ls -t dist/mcslam_*_"$(dpkg --print-architecture)".deb 2>/dev/null | head -n 1)}"
[ -f "$deb" ] || { echo "package-check: no package (run tools/package.sh first)" >&2; exit 2; }
deb="$(realpath "$deb")"

arch="$(dpkg-deb -f "$deb" Architecture)"

source tools/install-packages.sh
install_missing package-check mmdebstrap systemd systemd-container arch-test
if [ "$arch" != "$(dpkg --print-architecture)" ]; then
  install_missing package-check qemu-user-static
  tools/register-qemu-binfmt.sh "$arch"
fi
cache="${HOME}/.cache/mcslam"
clean="$cache/debian12-$arch-apt.tar"
if [ ! -f "$clean" ]; then
  mkdir -p "$cache"
  mmdebstrap --arch="$arch" --variant=apt --format=tar bookworm "$clean.tmp" "deb http://deb.debian.org/debian bookworm main" \
    "deb http://deb.debian.org/debian-security bookworm-security main"
  mv "$clean.tmp" "$clean"
fi
root="$(mktemp -d /tmp/mcslam-package-check.XXXXXX)"
box_pid=""
daemon_pid=""
# The root holds the host's /dev (bound): nothing may be deleted while anything is still mounted below it. A check
# that failed leaves its daemon running (under qemu for arm64), which keeps the mounts busy: it is stopped first,
# the mounts are detached lazily if need be, and the root's files are deleted on its own file system only.
stop_box() {  # systemd-nspawn, if running: SIGTERM shuts the root down in order; killed after $1 s (30)
  [ -n "$box_pid" ] || return 0
  kill "$box_pid" 2>/dev/null || true
  local waited=0
  while kill -0 "$box_pid" 2>/dev/null && [ "$waited" -lt "${1:-30}" ]; do sleep 1; waited=$((waited + 1)); done
  kill -KILL "$box_pid" 2>/dev/null || true
  wait "$box_pid" 2>/dev/null || true
  box_pid=""
}
cleanup() {
  set +e
  stop_box
  if [ -n "$daemon_pid" ]; then
    kill -KILL "$daemon_pid" 2>/dev/null
    wait "$daemon_pid" 2>/dev/null
  fi
  local m mounts
  for m in "$root/dev" "$root/proc"; do
    mountpoint -q "$m" && { umount -R "$m" 2>/dev/null || umount -R -l "$m"; }
  done
  mounts="$(findmnt -rn -o TARGET)"
  if awk -v r="$root/" 'index($0, r) == 1 { found = 1 } END { exit !found }' <<<"$mounts"; then
    echo "package-check: $root still has mounts below it: left in place (umount -R -l, then delete it)" >&2
    return
  fi
  rm -rf --one-file-system "$root"
  rm -f "$root.boot.log"
}
trap cleanup EXIT
tar -C "$root" -xf "$clean"
cp /etc/resolv.conf "$root/etc/resolv.conf"
mount_root() {
  mount -t proc proc "$root/proc"
  mount --rbind /dev "$root/dev"
}
mount_root
in_root() { chroot "$root" env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin DEBIAN_FRONTEND=noninteractive "$@"; }
step() { echo "package-check: $*"; }
fail() { echo "package-check: FAILED: $*" >&2; exit 1; }

step "install $(basename "$deb")"
cp "$deb" "$root/tmp/mcslam.deb"
in_root apt-get update -q >/dev/null
in_root apt-get install -y -q --no-install-recommends /tmp/mcslam.deb >/dev/null
for f in /usr/bin/mcslamd /usr/bin/mcslam-run /usr/bin/mcslam-shm-echo /usr/bin/mcslam-udp-echo \
  /usr/lib/*/mcslam/mcslam_image_codec.so /usr/lib/systemd/system/mcslamd.service /etc/mcslamd/mcslamd.yaml \
  /usr/include/mcslam/pose_shm.hpp /usr/lib/*/cmake/mcslam/mcslamConfig.cmake \
  /usr/share/mcslam/places/orb_vocabulary.mcvoc /usr/share/doc/mcslam/daemon.md /usr/share/man/man8/mcslamd.8.gz \
  /usr/share/man/man1/mcslam-run.1.gz /usr/share/man/man1/mcslam-shm-echo.1.gz; do
  compgen -G "$root$f" >/dev/null || fail "$f is not installed"
done
in_root getent passwd mcslamd >/dev/null || fail "no system user mcslamd"
exec_start="$(sed -n 's/^ExecStart=//p' "$root/usr/lib/systemd/system/mcslamd.service")"
step "the unit runs: $exec_start"

run_daemon() {  # starts the unit's command in the background as systemd would; sets daemon_pid
  mkdir -p "$root/var/lib/mcslamd"
  in_root chown mcslamd:mcslamd /var/lib/mcslamd
  chroot "$root" setpriv --reuid=mcslamd --regid=mcslamd --init-groups \
    env -i PATH=/usr/bin:/bin STATE_DIRECTORY=/var/lib/mcslamd CONFIGURATION_DIRECTORY=/etc/mcslamd \
    $exec_start >"$root/tmp/mcslamd.log" 2>&1 &
  daemon_pid=$!
}
stop_daemon() {
  kill -TERM "$daemon_pid"
  local status=0
  wait "$daemon_pid" || status=$?
  [ "$status" -eq 0 ] || { cat "$root/tmp/mcslamd.log"; fail "mcslamd exited with $status after SIGTERM"; }
  daemon_pid=""
}

run_daemon
step "poses over UDP (127.0.0.1:9870, the packaged configuration's destination)"
in_root timeout 180 mcslam-udp-echo --count 5 >"$root/tmp/udp.txt" || { cat "$root/tmp/mcslamd.log"; fail "no UDP poses"; }
tail -n 1 "$root/tmp/udp.txt"
step "poses over shared memory (/mcslam_pose)"
in_root timeout 60 mcslam-shm-echo --count 5 --wait 30 >"$root/tmp/shm.txt" || fail "no poses in shared memory"
tail -n 1 "$root/tmp/shm.txt"

step "a C++ consumer built with find_package(mcslam) against the installed package"
in_root apt-get install -y -q --no-install-recommends cmake g++ make >/dev/null
mkdir -p "$root/tmp/consumer"
cp tests/install/consumer/CMakeLists.txt tests/install/consumer/consumer.cpp "$root/tmp/consumer/"
in_root cmake -S /tmp/consumer -B /tmp/consumer/build >/dev/null
in_root cmake --build /tmp/consumer/build >/dev/null
in_root /tmp/consumer/build/consumer /mcslam_pose 10 || fail "the consumer read no poses"
stop_daemon
grep -q "stopped:" "$root/tmp/mcslamd.log" || fail "no stop summary in the log"
[ -s "$root/var/lib/mcslamd/trajectory.tum" ] || fail "no trajectory in the state directory"
step "stopped cleanly; trajectory $(grep -vc '^#' "$root/var/lib/mcslamd/trajectory.tum") poses in /var/lib/mcslamd"

source tools/package-check-systemd.sh
check_under_systemd

step "upgrade keeps a changed configuration and the state"
echo "# changed by the robot builder" >>"$root/etc/mcslamd/mcslamd.yaml"
echo "saved map stand-in" >"$root/var/lib/mcslamd/map.mcmap"
next="$root/tmp/next"
dpkg-deb -R "$deb" "$next"
version="$(sed -n 's/^Version: //p' "$next/DEBIAN/control")"
sed -i "s/^Version: .*/Version: ${version}+check1/" "$next/DEBIAN/control"
dpkg-deb -b "$next" "$root/tmp/mcslam-next.deb" >/dev/null
in_root apt-get install -y -q /tmp/mcslam-next.deb >/dev/null
[ "$(in_root dpkg-query -W -f='${Version}' mcslam)" = "${version}+check1" ] || fail "the upgrade did not install"
grep -q "changed by the robot builder" "$root/etc/mcslamd/mcslamd.yaml" || fail "the upgrade replaced the configuration"
[ -f "$root/var/lib/mcslamd/map.mcmap" ] || fail "the upgrade lost the state"

step "remove keeps the configuration and the state; purge removes them"
in_root apt-get remove -y -q mcslam >/dev/null
[ ! -e "$root/usr/bin/mcslamd" ] || fail "remove left /usr/bin/mcslamd"
[ -f "$root/etc/mcslamd/mcslamd.yaml" ] && [ -f "$root/var/lib/mcslamd/map.mcmap" ] || fail "remove lost the configuration or the state"
in_root apt-get purge -y -q mcslam >/dev/null
[ ! -e "$root/etc/mcslamd/mcslamd.yaml" ] && [ ! -e "$root/var/lib/mcslamd" ] && [ ! -e "$root/var/lib/private/mcslamd" ] ||
  fail "purge left the configuration or the state"

if [ -z "${security_score:-}" ]; then
  step "the unit's sandboxing (systemd-analyze security, offline)"
  dpkg-deb -x "$deb" "$root/unpacked"
  systemd-analyze security --offline=true "$root/unpacked/usr/lib/systemd/system/mcslamd.service" 2>/dev/null | tail -n 1
fi
echo "package-check: all checks passed"
