#!/usr/bin/env bash
# Sets up (packages + build) and runs the whole test suite through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
ctest --test-dir build --output-on-failure --timeout 900 -j"$(nproc)"
