#!/usr/bin/env bash
# Builds allanvar with AddressSanitizer + UndefinedBehaviorSanitizer and runs
# the testthat suite against that build. For developers; CI does not run it
# (it takes several times as long as tools/test.sh).
#
#   bash tools/sanitize.sh            # prints the suite's summary, then the
#                                     # sanitizer findings (none: "clean")
#   ALLANVAR_SANITIZE_FILTER='^(allan|types|edf)$' bash tools/sanitize.sh
#                                     # only those test files
#
# How: a private Makevars (R_MAKEVARS_USER) adds
# -fsanitize=address,undefined -fno-omit-frame-pointer to the C/C++ flags
# and the link; the package is installed into a temporary library; R itself
# is not instrumented, so libasan is preloaded (LD_PRELOAD) into every R
# process, test children included. Leak detection is off (R frees little at
# exit). The out-of-memory test skips itself (ASan reserves terabytes of
# address space, so `ulimit -v` cannot be used). Findings in R or in other
# packages are listed too, but only those in src/ are the package's.
set -uo pipefail
cd "$(dirname "$0")/.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
flags="-g -O1 -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
cat >"$work/Makevars" <<MK
CFLAGS = $flags
CXXFLAGS = $flags
CXX11FLAGS = $flags
CXX14FLAGS = $flags
CXX17FLAGS = $flags
LDFLAGS = -fsanitize=address,undefined
MK
mkdir -p "$work/lib" "$work/src"
# build from a copy: instrumented objects must not land in the source tree
git ls-files -z | xargs -0 -I{} cp --parents {} "$work/src/" 2>/dev/null || cp -r . "$work/src/"
rm -f "$work"/src/src/*.o "$work"/src/src/*.so
echo "sanitize: building with $flags"
R_MAKEVARS_USER="$work/Makevars" R CMD INSTALL --preclean --no-test-load \
  --library="$work/lib" "$work/src" >"$work/install.log" 2>&1 || { cat "$work/install.log"; exit 1; }
asan=$(gcc -print-file-name=libasan.so)
ubsan=$(gcc -print-file-name=libubsan.so)
log="$work/tests.log"
# the whole suite, or only the test files matching ALLANVAR_SANITIZE_FILTER
runner=(tools/run-tests.R)
if [ -n "${ALLANVAR_SANITIZE_FILTER:-}" ]; then
  runner=(-e "Sys.setenv(NOT_CRAN = 'true'); options(allanvar.threads = 2L)
r <- as.data.frame(testthat::test_dir('tests/testthat', filter = Sys.getenv('ALLANVAR_SANITIZE_FILTER'), package = 'allanvar', load_package = 'installed', stop_on_failure = FALSE))
cat(sprintf('%d passed, %d failed, %d skipped\\n', sum(r\$nb) - sum(r\$failed) - sum(r\$skipped), sum(r\$failed) + sum(r\$error), sum(r\$skipped)))")
fi
echo "sanitize: running the test suite (log: ${ALLANVAR_SANITIZE_LOG:-not kept})"
LD_PRELOAD="$asan $ubsan" \
ASAN_OPTIONS="detect_leaks=0:halt_on_error=0:abort_on_error=0" \
UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=0" \
ALLANVAR_SANITIZE=1 R_LIBS="$work/lib${R_LIBS:+:$R_LIBS}" \
  Rscript --vanilla "${runner[@]}" >"$log" 2>&1
status=$?
tail -n 1 "$log"
if [ -n "${ALLANVAR_SANITIZE_LOG:-}" ]; then cp "$log" "$ALLANVAR_SANITIZE_LOG"; fi
findings=$(grep -E "runtime error|ERROR: AddressSanitizer" "$log" | sort | uniq -c)
if [ -z "$findings" ]; then
  echo "sanitize: clean (no AddressSanitizer or UBSan report)"
else
  echo "sanitize: findings:"
  echo "$findings"
  status=1
fi
exit $status
