# Sourced by the scripts that set up this machine (tools/setup.sh, tools/build-arm64.sh, tools/check-format.sh).
# install_missing TAG PACKAGE...: installs with apt-get those Debian packages that are not installed yet (through
# sudo when not root), saying which under TAG; nothing when all are there.
install_missing() {
  local tag="$1"
  shift
  local missing=() p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  ((${#missing[@]})) || return 0
  echo "$tag: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get update -q
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
}
