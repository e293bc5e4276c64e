#pragma once
// Whether the daemon the process tests start runs under an emulator (a cross build's tests under qemu-user): the
// process then has the emulator's own threads, and the emulator reads the target's libraries from a root that other
// users may not reach.

namespace mcslam::test {

constexpr bool underEmulator() {
#ifdef MCSLAM_TEST_UNDER_EMULATOR
  return true;
#else
  return false;
#endif
}

}  // namespace mcslam::test
