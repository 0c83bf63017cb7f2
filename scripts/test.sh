#!/usr/bin/env bash
# Runs every test tier after scripts/setup.sh: ruff over all Python (lint and format; the C++
# build in setup.sh already failed on any warning, -Werror), the C++ core tests (gtest, through
# catkin's run_tests), then the Python tests (core, wiring, end-to-end) with pytest.
#   scripts/test.sh [pytest args...]
set -eo pipefail
cd "$(dirname "$0")/.."
# shellcheck disable=SC1091
source devel/setup.bash
export PYTHONDONTWRITEBYTECODE=1

if ! .venv/bin/ruff check --quiet .; then
  echo "ruff check failed; fix the lines above (.venv/bin/ruff check --fix . does the simple ones)"
  exit 1
fi
if ! .venv/bin/ruff format --check --quiet .; then
  echo "ruff format: the files above are not formatted; run .venv/bin/ruff format ."
  exit 1
fi

rm -rf build/test_results
make -C build --no-print-directory -s run_tests >build/run_tests.log 2>&1 || true
if [ -d build/test_results ]; then
  if ! catkin_test_results build/test_results; then
    grep -E '^\[  FAILED|Failure|error' build/run_tests.log | head -40
    echo "C++ tests failed (full log: build/run_tests.log)"; exit 1
  fi
fi

exec .venv/bin/python -m pytest "$@"
