#!/usr/bin/env bash
# Lets this machine run programs of another architecture (arm64) directly, also inside a chroot: registers Debian's
# qemu-user-static with binfmt_misc, with the F flag (the emulator is opened now, so a chroot need not contain it).
# Nothing to do when the architecture is already registered. Needs root. Used by tools/package-check.sh for an
# arm64 package; the arm64 test suite does not need it (tools/test-arm64.sh runs qemu itself).
#
# Usage: tools/register-qemu-binfmt.sh arm64
set -euo pipefail
case "${1:-}" in
  arm64) name=qemu-aarch64 ;;
  *) echo "register-qemu-binfmt: architecture '${1:-}': only arm64 is known" >&2; exit 2 ;;
esac
dir=/proc/sys/fs/binfmt_misc
[ -e "$dir/register" ] || mount -t binfmt_misc binfmt_misc "$dir" ||
  { echo "register-qemu-binfmt: cannot mount binfmt_misc at $dir" >&2; exit 1; }
if [ -e "$dir/$name" ]; then
  grep -q '^enabled' "$dir/$name" && grep -q '^flags:.*F' "$dir/$name" && exit 0
  # Disabled, or registered without F (the emulator would then have to be inside the chroot): replaced, for the
  # whole machine until it reboots.
  echo "register-qemu-binfmt: replacing this machine's $name entry ($(head -n 1 "$dir/$name"), $(grep '^flags' "$dir/$name"))"
  echo -1 >"$dir/$name"
fi
emulator=/usr/bin/qemu-aarch64-static
[ -x "$emulator" ] || { echo "register-qemu-binfmt: $emulator missing (apt-get install qemu-user-static)" >&2; exit 1; }
# Debian's own magic and mask for AArch64 ELF executables (/usr/lib/binfmt.d/qemu-aarch64.conf).
magic='\x7f\x45\x4c\x46\x02\x01\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00\x02\x00\xb7\x00'
mask='\xff\xff\xff\xff\xff\xff\xff\x00\xff\xff\xff\xff\xff\xff\xff\xff\xfe\xff\xff\xff'
printf '%s' ":$name:M::$magic:$mask:$emulator:F" >"$dir/register"
echo "register-qemu-binfmt: $name registered ($emulator)"
