# Sourced by the scripts that set up this machine and configure build trees (tools/setup.sh, tools/build-arm64.sh,
# tools/run-sanitizers.sh, tools/fuzz.sh, tools/package.sh, tools/check-format.sh).
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

# default_to_ninja: new build trees made by this script use Ninja when it is installed (tools/setup.sh installs
# ninja-build). It compiles a target's files while the libraries it links are still being built, where the Makefile
# generator waits for them, so a cold build on two cores takes a fifth less time (BENCHMARKS.md, "CI's time"). A
# build tree keeps the generator it was made with; a CMAKE_GENERATOR set by the caller wins.
default_to_ninja() {
  if [ -z "${CMAKE_GENERATOR:-}" ] && command -v ninja >/dev/null; then
    export CMAKE_GENERATOR=Ninja
  fi
}
