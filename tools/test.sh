#!/usr/bin/env bash
# The test command: install missing dependencies, install the package into a
# temporary library, run the testthat suite, print "N passed, N failed".
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
lib=$(mktemp -d)
trap 'rm -rf "$lib"' EXIT
R CMD INSTALL --preclean --no-test-load --library="$lib" . >"$lib/install.log" 2>&1 || {
  cat "$lib/install.log"; exit 1; }
R_LIBS="$lib${R_LIBS:+:$R_LIBS}" Rscript --vanilla tools/run-tests.R
