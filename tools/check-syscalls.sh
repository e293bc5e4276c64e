#!/usr/bin/env bash
# Checks that the system-call filter of the systemd unit lets mcslamd do its work, without systemd: runs mcslamd
# under strace with every call outside the unit's SystemCallFilter= failed as the filter fails it (strace's
# -e inject with the unit's SystemCallErrorNumber=; the groups expanded with `systemd-analyze syscall-filter`, in
# order: allow lines add, ~ lines remove) and, as root, /proc mounted as ProtectProc=/ProcSubset= mount it and the
# daemon running as `nobody` with the unit's LimitRTPRIO/LimitMEMLOCK when they can be raised. Through its modes: a
# live simulated rig publishing over shared memory and UDP with the realtime: section on, a periodic map save,
# SIGUSR1/SIGHUP/SIGUSR2 and the SIGTERM stop, a second daemon refused the held segment, a PNG replay loading the
# saved map and ending by itself, a PGM replay, --check-config, a GigE camera through Aravis (when aravis-tools' fake
# camera is installed) and a GPIO chip that does not exist. Lists every call made after mcslamd's execve, the refused
# ones, and the /proc files outside the process directories that the daemon's libraries tried.
# What it cannot see is a path no scenario takes (USB3 cameras, a GPIO chip that exists): docs/package.md.
#
# Usage: tools/check-syscalls.sh [--bin DIR] [--unit FILE] [--keep DIR]
#   --bin DIR    the built programs (default build/bin)
#   --unit FILE  the unit whose filter is checked (default systemd/mcslamd.service)
#   --keep DIR   keep the traces, logs and the lists of calls there
# Exit status: 0 every scenario ended as expected and every refused call is one known to be harmless (listed below
# with the reason), 1 otherwise, 2 bad usage, 77 skipped (strace, systemd-analyze or python3 missing, or tracing not
# permitted here).
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
bin="$repo/build/bin"
unit="$repo/systemd/mcslamd.service"
keep=""
while (($#)); do
  case "$1" in
    --bin) bin="$(realpath -m "$2")"; shift 2 ;;
    --unit) unit="$(realpath -m "$2")"; shift 2 ;;
    --keep) keep="$(realpath -m "$2")"; shift 2 ;;
    *) echo "check-syscalls: unknown argument '$1' (see the header of $0)" >&2; exit 2 ;;
  esac
done
cd "$repo"
say() { echo "check-syscalls: $*"; }
skip() { say "SKIPPED: $*"; exit 77; }
for tool in strace systemd-analyze python3; do
  command -v "$tool" >/dev/null || skip "$tool is not installed (Debian packages strace, systemd, python3)"
done
strace -f -qq -o /dev/null true 2>/dev/null || skip "strace cannot trace here (ptrace not permitted)"
for program in mcslamd mcslam-sim mcslam-dataset; do
  [ -x "$bin/$program" ] || { echo "check-syscalls: no $bin/$program (build first)" >&2; exit 2; }
done
[ -f "$unit" ] || { echo "check-syscalls: no unit $unit" >&2; exit 2; }

work="$(mktemp -d /tmp/mcslam-syscalls.XXXXXX)"
chmod 755 "$work"
helpers=()  # the fake camera, the notify listener
tracers=()  # strace, each with mcslamd as its child
cleanup() {
  local pid
  for pid in "${tracers[@]}"; do pkill -KILL -P "$pid" 2>/dev/null || true; done
  for pid in "${helpers[@]}"; do kill "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  if [ -n "$keep" ]; then
    mkdir -p "$keep" && cp -r "$work"/. "$keep"/
  fi
  rm -rf "$work"
}
trap cleanup EXIT
fail() {
  echo "check-syscalls: FAILED: $*" >&2
  exit 1
}

# The set the unit allows. Groups nest (@system-service holds @basic-io, ...), so they are expanded recursively.
expand() {
  local name
  for name in "$@"; do
    if [[ $name == @* ]]; then
      systemd-analyze syscall-filter "$name" | sed 1d | grep -v '^ *#' | awk 'NF {print $1}' |
        while read -r member; do expand "$member"; done
    else
      echo "$name"
    fi
  done
}
allowed="$work/allowed.txt"
: >"$allowed"
lines=0
while read -r value; do
  lines=$((lines + 1))
  if [ -z "$value" ]; then
    : >"$allowed"
  elif [[ $value == ~* ]]; then
    ((lines > 1)) || fail "$unit: the first SystemCallFilter= is a deny list; this check needs an allow list"
    # shellcheck disable=SC2086
    expand ${value#\~} | sort -u >"$work/deny.txt"
    comm -23 "$allowed" "$work/deny.txt" >"$work/tmp.txt" && mv "$work/tmp.txt" "$allowed"
  else
    # shellcheck disable=SC2086
    { cat "$allowed"; expand $value; } | sort -u >"$work/tmp.txt" && mv "$work/tmp.txt" "$allowed"
  fi
done < <(sed -n 's/^SystemCallFilter=//p' "$unit")
((lines > 0)) || fail "$unit has no SystemCallFilter="
say "$unit allows $(wc -l <"$allowed") system calls ($(sed -n 's/^SystemCallFilter=//p' "$unit" | paste -sd '|'))"

# What the filter does to any other call, strace does too: fails it with the unit's SystemCallErrorNumber= (without
# one systemd kills the process with SIGSYS; strace cannot, so a refused call is then a failure of the check).
errno="$(sed -n 's/^SystemCallErrorNumber=//p' "$unit")"
errno="${errno:-ENOSYS}"
# strace's set: every call but the allowed ones ('?': names of other architectures in the groups are no error).
refuse="!$(sed 's/^/?/' "$allowed" | paste -sd ,)"

# The unit's /proc, when it sets ProtectProc=/ProcSubset=: a procfs of its own with those mount options, in a mount
# namespace of the daemon's (as systemd mounts it; needs root).
proc_options=()
grep -q '^ProtectProc=invisible' "$unit" && proc_options+=(hidepid=invisible)
grep -q '^ProcSubset=pid' "$unit" && proc_options+=(subset=pid)
in_proc=()
if ((${#proc_options[@]})); then
  options="$(IFS=,; echo "${proc_options[*]}")"
  if unshare -m --propagation private mount -t proc -o "$options" proc /proc 2>/dev/null; then
    in_proc=(unshare -m --propagation private sh -c "mount -t proc -o $options proc /proc && exec \"\$@\"" sh)
    say "/proc as the unit has it: $options"
  else
    say "cannot mount a procfs with $options here (needs root): /proc is the machine's"
  fi
fi

# As the unit runs it: unprivileged, with its realtime limits (as root: the user nobody; else this user).
rtprio="$(sed -n 's/^LimitRTPRIO=//p' "$unit")"
as_user=()
[ "$(id -u)" -ne 0 ] || as_user=(-u nobody)
limits=(prlimit --rtprio="${rtprio:-0}" --memlock=unlimited --)
if ! "${limits[@]}" true 2>/dev/null; then
  # The realtime calls are made all the same; they fail with EPERM, which the daemon logs and goes on.
  say "cannot raise RLIMIT_RTPRIO/RLIMIT_MEMLOCK here (no CAP_SYS_RESOURCE): the realtime settings will be refused"
  limits=()
fi
state="$work/state"
mkdir -p "$state"
[ "$(id -u)" -ne 0 ] || chown nobody "$state"

# systemd's notify socket: the daemon's READY=1, WATCHDOG=1 and STATUS= arrive here.
python3 - "$work/notify" "$work/notify.log" <<'EOF' &
import os, socket, sys
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
s.bind(sys.argv[1])
os.chmod(sys.argv[1], 0o666)
with open(sys.argv[2], "a", buffering=1) as out:
    while True:
        out.write(s.recv(4096).decode(errors="replace").replace("\n", " ") + "\n")
EOF
helpers+=($!)

# traced NAME ARGS...: mcslamd ARGS under strace (trace NAME.trace, output NAME.log), in the background: $daemon.
traced() {
  local name="$1"
  shift
  : >"$work/notify.log"
  env NOTIFY_SOCKET="$work/notify" WATCHDOG_USEC=2000000 STATE_DIRECTORY="$state" "${limits[@]}" "${in_proc[@]}" \
    strace -f -qq -o "$work/$name.trace" -e trace=all -e "inject=$refuse:error=$errno" "${as_user[@]}" \
    "$bin/mcslamd" "$@" >"$work/$name.log" 2>&1 &
  daemon=$!
  tracers+=("$daemon")
}
# The mcslamd process of $daemon (strace's child): signals go to it, not to the tracer.
tracee() { pgrep -P "$daemon"; }
# wait_for WHAT FILE PATTERN: until FILE holds PATTERN; the deadline is only there so that a hang ends the check.
wait_for() {
  local deadline=$((SECONDS + 180))
  until grep -qE "$3" "$2" 2>/dev/null; do
    ((SECONDS < deadline)) || fail "$1: no '$3' in $2 within 180 s: $(tail -n 20 "$work"/*.log)"
    kill -0 "$daemon" 2>/dev/null || { wait "$daemon" || true; fail "$1: mcslamd ended early: $(tail -n 20 "$work/$1.log")"; }
    sleep 0.2
  done
}
# finish NAME STATUS: waits for the daemon; its exit status must be STATUS.
finish() {
  local status=0
  wait "$daemon" || status=$?
  [ "$status" -eq "$2" ] || fail "$1: mcslamd exited with $status, expected $2: $(tail -n 20 "$work/$1.log")"
  say "$1: exit status $status as expected"
}

shm="/mcslam-syscalls-$$"
common="status_interval_s: 0.5
capacities: {max_cameras: 8}
publish:
  shm: {name: $shm, mode: \"0644\"}
  udp: {destinations: [\"127.0.0.1:9871\", \"[::1]:9871\"]}
output: {directory: \"\"}
realtime:
  trigger_priority: 80
  acquisition_priority: 70
  processing_priority: 60
  lock_memory: true
  cpus: [0]"

# 1. The live simulated rig, realtime on, a periodic map save; the signals; the stop.
cat >"$work/sim.yaml" <<EOF
source:
  type: sim
  sim: {rig: stereo, world: indoor, pace: fastest, at_end: loop, anti_aliasing: false, render_threads: 1}
map: {save: map.mcmap, save_interval_s: 1}
$common
EOF
traced sim --config "$work/sim.yaml"
sim_daemon=$daemon
wait_for sim "$work/notify.log" '^READY=1'
wait_for sim "$work/notify.log" '^WATCHDOG=1'
wait_for sim "$work/notify.log" 'map saves [1-9]'
say "sim: ready, processing frames, map saved"
# A second daemon on the same segment name is refused (exit status 3) while the first runs.
traced held --config "$work/sim.yaml"
finish held 3
daemon=$sim_daemon
# sigtimedwait takes the lowest pending signal first (HUP 1, USR1 10, USR2 12): once SIGUSR2 is logged, SIGUSR1's
# status line (no mark of its own) has been written too.
for sig in USR1 HUP USR2; do kill -s "$sig" "$(tracee)"; done
wait_for sim "$work/sim.log" 'SIGHUP ignored'
wait_for sim "$work/sim.log" 'SIGUSR2 ignored'
kill -TERM "$(tracee)"
finish sim 0

# 2. A replay of a rendered PNG dataset at its recorded rate, loading the map saved above; it ends by itself.
"$bin/mcslam-sim" --rig stereo --frames 20 --no-depth --no-antialiasing --quiet --out "$work/dataset" >/dev/null
cat >"$work/replay.yaml" <<EOF
source:
  type: dataset
  dataset: {path: $work/dataset, rate: recorded, at_end: exit}
map: {load: map.mcmap, save: map.mcmap, on_unreadable: start_empty}
$common
EOF
traced replay --config "$work/replay.yaml"
finish replay 0

# 3. The same as binary PGM (read by mcslamd itself, no codec module), preloaded, as fast as it goes.
"$bin/mcslam-dataset" convert "$work/dataset" --layout asl --images pgm --out "$work/dataset_pgm" >/dev/null
cat >"$work/pgm.yaml" <<EOF
source:
  type: dataset
  dataset: {path: $work/dataset_pgm, rate: fastest, preload: true, at_end: exit}
$common
EOF
traced pgm --config "$work/pgm.yaml"
finish pgm 0

# 4. --check-config, and a GPIO trigger whose chip does not exist (exit status 2, the key named).
traced check --check-config "$work/sim.yaml"
finish check 0
cat >"$work/calib.yaml" <<'EOF'
cam0:
  camera_model: pinhole
  intrinsics: [300.0, 300.0, 160.0, 120.0]
  distortion_model: radtan
  distortion_coeffs: [0.0, 0.0, 0.0, 0.0]
  resolution: [320, 240]
EOF
aravis_config() {  # aravis_config TRIGGER-SECTION
  cat <<EOF
calibration: $work/calib.yaml
source:
  type: aravis
  aravis:
    frame_timeout_ms: 1000
    cameras:
      - {id: "127.0.0.1", exposure_us: 2000, gain_db: 1, pixel_format: Mono8, trigger_line: Line0}
$1
$common
EOF
}
aravis_config "trigger: {mode: gpio, rate_hz: 20, gpio_chip: gpiochip-mcslam-missing, gpio_line: 4}" >"$work/gpio.yaml"

# 5. A GigE Vision camera through Aravis: aravis-tools' fake camera on 127.0.0.1, software trigger.
fake=/usr/bin/arv-fake-gv-camera-0.8
if [ -x "$fake" ]; then
  "$fake" -i 127.0.0.1 >/dev/null 2>&1 &
  helpers+=($!)
  # Ready once its GVCP port is bound (127.0.0.1:3956 in /proc/net/udp's hex).
  deadline=$((SECONDS + 30))
  until grep -q ' 0100007F:0F74 ' /proc/net/udp; do
    ((SECONDS < deadline)) || fail "the fake camera did not bind 127.0.0.1:3956"
    sleep 0.1
  done
  aravis_config "trigger: {mode: software, rate_hz: 20}" >"$work/aravis.yaml"
  traced aravis --config "$work/aravis.yaml"
  wait_for aravis "$work/notify.log" '^READY=1'
  wait_for aravis "$work/notify.log" '^WATCHDOG=1'
  kill -TERM "$(tracee)"
  finish aravis 0
  # With the camera there, the GPIO chip is what fails.
  traced gpio --config "$work/gpio.yaml"
  finish gpio 2
  grep -q 'trigger.gpio_chip' "$work/gpio.log" || fail "gpio: the message does not name trigger.gpio_chip"
else
  say "aravis: $fake not installed (Debian package aravis-tools): the GigE and GPIO scenarios are not run"
fi

# Every call made after mcslamd's execve (the tracer's own set-up before it is not the service's).
for trace in "$work"/*.trace; do
  awk '!started && /execve\(/ && / = 0$/ {started = 1} started' "$trace" |
    sed -E -n 's/^[0-9]+ +([a-z_0-9]+)\(.*/\1/p'
done | sort | uniq -c | sort -k2 >"$work/used-counts.txt"
awk '{print $2}' "$work/used-counts.txt" >"$work/used.txt"
grep -h '(INJECTED)$' "$work"/*.trace | sed -E -n 's/^[0-9]+ +([a-z_0-9]+)\(.*/\1/p' | sort -u >"$work/refused.txt"
say "mcslamd made $(wc -l <"$work/used.txt") distinct system calls over $(ls "$work"/*.trace | wc -l) runs:"
awk '{printf "%s(%s) ", $2, $1} END {print ""}' "$work/used-counts.txt" | fold -s -w 118 | sed 's/^/  /'

# Refusals seen and known to be harmless, each with the reason; any other refusal fails the check, even when the
# scenarios passed, since a path no scenario takes may depend on it.
#   set_mempolicy: libnuma (mapped with the image codec module's libraries, PNG replay) probes MPOL_PREFERRED_MANY
#                  when loaded and takes a failure as "not supported"; mcslamd sets no memory policy.
known_refusals="set_mempolicy"
status=0
if [ -s "$work/refused.txt" ]; then
  unknown="$(comm -23 "$work/refused.txt" <(tr ' ' '\n' <<<"$known_refusals" | sort))"
  if [ "$errno" = ENOSYS ] && ! grep -q '^SystemCallErrorNumber=' "$unit"; then
    say "FAILED: calls the filter refuses, which would end mcslamd with SIGSYS: $(paste -sd ' ' "$work/refused.txt")"
    status=1
  elif [ -n "$unknown" ]; then
    say "FAILED: calls the filter refuses ($errno) that no one has found harmless: $(paste -sd ' ' <<<"$unknown")"
    status=1
  else
    say "refused with $errno, known to be harmless, and every scenario passed: $(paste -sd ' ' "$work/refused.txt")"
  fi
fi
((status)) || say "every other call is allowed by the unit's SystemCallFilter="
# What the daemon opened in /proc outside the process directories (ProcSubset=pid hides them).
grep -ohE '"/proc/[^"]*"' "$work"/*.trace | tr -d '"' | sort -u | grep -vE '^/proc/(self|thread-self|[0-9]+)(/|$)' \
  >"$work/proc-hidden.txt" || true
[ ! -s "$work/proc-hidden.txt" ] ||
  say "/proc files outside the process directories it tried (hidden by ProcSubset=pid): $(paste -sd ' ' "$work/proc-hidden.txt")"
exit "$status"
