#!/usr/bin/env bash
# Runs a ctest command that needs the shared test data (../shared: not part of the repository).
#
#   with_shared.sh CONFIGURED_DIR NEEDED -- COMMAND [ARGS...]
#
# The data folder is $VBRDF_SHARED_DIR when set and non-empty, else CONFIGURED_DIR (the CMake
# cache variable VBRDF_SHARED_DIR), as in tests/support/test_paths.cpp. When DIR/NEEDED does not
# exist, prints the reason and exits 77 (the tests' SKIP_RETURN_CODE: ctest reports "Skipped").
# Otherwise every "@VBRDF_SHARED_DIR@" in COMMAND and ARGS is replaced by the folder and the
# command runs (its exit status is the test's).
set -euo pipefail
if [ $# -lt 4 ] || [ "$3" != "--" ]; then
  echo "usage: with_shared.sh CONFIGURED_DIR NEEDED -- COMMAND [ARGS...]" >&2
  exit 2
fi
dir=${VBRDF_SHARED_DIR:-$1}
needed=$2
shift 3
if [ ! -e "$dir/$needed" ]; then
  echo "SKIP: shared test data not found: $dir/$needed (not part of the repository;" \
       "set VBRDF_SHARED_DIR to the folder holding scenes/ and real/)"
  exit 77
fi
token=@VBRDF_SHARED_DIR@
exec "${@//"$token"/$dir}"
