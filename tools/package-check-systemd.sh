# Sourced by tools/package-check.sh once the package is installed in $root: the same root booted with systemd
# (systemd-nspawn --boot), the unit driven with systemctl. Uses package-check's step, fail, in_root, mount_root and
# stop_box and box_pid; sets security_score. Skips with a message when the root does not boot (nspawn
# needs a kernel and privileges that some containers do not give; systemd as init under qemu-user may not start).

boot_timeout_s=300
in_box() { nsenter -t "$box_init" -a env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin "$@"; }

boot_root() {  # sets box_pid (systemd-nspawn) and box_init (the root's systemd); false when it does not boot
  systemd-nspawn -q --register=no --keep-unit -D "$root" -M mcslam-check -b </dev/null >"$root.boot.log" 2>&1 &
  box_pid=$!
  box_init=""
  local waited=0 state
  while [ "$waited" -lt "$boot_timeout_s" ] && kill -0 "$box_pid" 2>/dev/null; do
    [ -n "$box_init" ] || box_init="$(pgrep -P "$box_pid" -x systemd || true)"  # the root's init: nspawn's child
    if [ -n "$box_init" ]; then
      state="$(in_box systemctl is-system-running 2>/dev/null || true)"
      case "$state" in running | degraded) step "the root booted with systemd ($state)"; return 0 ;; esac
    fi
    sleep 2
    waited=$((waited + 2))
  done
  return 1
}

power_off_root() {  # then the chroot's mounts again, for the steps that follow
  stop_box 60
  mount_root
}

unit_value() { in_box systemctl show -p "$1" --value mcslamd || true; }
journal() { in_box journalctl -u mcslamd --no-pager -o cat || true; }

check_under_systemd() {
  step "under systemd: boot the root (systemd-nspawn --boot)"
  in_root apt-get install -y -q --no-install-recommends systemd systemd-sysv dbus >/dev/null ||
    fail "installing systemd in the root"
  umount -R "$root/proc" "$root/dev" || fail "unmounting the root's /proc and /dev (nspawn mounts its own)"
  if ! boot_root; then
    cp "$root.boot.log" /tmp/mcslam-package-check-boot.log 2>/dev/null || true  # the cleanup deletes the original
    # MCSLAM_REQUIRE_SYSTEMD=1: a root that does not boot is a failure, not a skip.
    [ "${MCSLAM_REQUIRE_SYSTEMD:-0}" = 1 ] &&
      fail "the root did not boot under systemd-nspawn (console: /tmp/mcslam-package-check-boot.log)"
    echo "package-check: SKIPPED the systemd checks: the root did not boot under systemd-nspawn within" \
      "${boot_timeout_s}s (its console: /tmp/mcslam-package-check-boot.log)"
    tail -n 5 "$root.boot.log" || true
    power_off_root
    return 0
  fi
  step "systemctl start mcslamd (Type=notify: returns once the daemon said READY=1)"
  in_box systemctl start mcslamd || { journal | tail -n 30; fail "systemctl start mcslamd"; }
  [ "$(in_box systemctl is-active mcslamd)" = active ] || fail "mcslamd is not active"
  in_box timeout 180 mcslam-udp-echo --count 5 >"$root/tmp/udp-systemd.txt" || fail "no UDP poses under systemd"
  step "UDP: $(tail -n 1 "$root/tmp/udp-systemd.txt")"
  in_box timeout 60 mcslam-shm-echo --count 5 --wait 30 >"$root/tmp/shm-systemd.txt" ||
    fail "no shared-memory poses under systemd"
  step "shared memory: $(tail -n 1 "$root/tmp/shm-systemd.txt")"
  step "systemctl status: $(in_box systemctl status mcslamd --no-pager | sed -n 's/^ *Status: //p')"

  local first_pid restarts=0 waited=0 log
  first_pid="$(unit_value MainPID)"
  step "the watchdog: mcslamd (pid $first_pid in the root) stopped dead with SIGSTOP"
  in_box kill -STOP "$first_pid"
  while [ "$waited" -lt 120 ]; do
    restarts="$(unit_value NRestarts)"
    [[ "$restarts" =~ ^[0-9]+$ ]] || restarts=0
    if [ "$restarts" -ge 1 ] && [ "$(in_box systemctl is-active mcslamd)" = active ] &&
      [ "$(unit_value MainPID)" != "$first_pid" ]; then
      break
    fi
    sleep 1
    waited=$((waited + 1))
  done
  log="$(journal)"
  [ "$restarts" -ge 1 ] || { tail -n 20 <<<"$log"; fail "the watchdog did not restart mcslamd"; }
  step "restarted by systemd after ${waited}s (NRestarts=$restarts, new pid $(unit_value MainPID)):"
  grep -i -m 3 "watchdog" <<<"$log" || true
  in_box timeout 180 mcslam-udp-echo --count 3 >/dev/null || fail "no poses after the restart"

  security_score="$(in_box systemd-analyze security mcslamd 2>/dev/null | tail -n 1)"
  step "the running unit's sandboxing (systemd-analyze security): $security_score"
  step "systemctl stop mcslamd"
  in_box systemctl stop mcslamd
  [ "$(in_box systemctl is-active mcslamd)" != active ] || fail "mcslamd still active after systemctl stop"
  [ "$(unit_value ExecMainStatus)" = 0 ] || fail "mcslamd exited with $(unit_value ExecMainStatus) on stop"
  log="$(journal)"
  grep -m 1 "stopped:" <<<"$log" || fail "no stop summary in the journal"
  power_off_root
}
