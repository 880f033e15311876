#!/usr/bin/env bash
# Installs what the package needs and is missing: Debian's prebuilt r-cran-*
# packages first (seconds), CRAN for anything Debian lacks.
set -euo pipefail
pkgs="Rcpp RcppEigen gplots future future.apply knitr rmarkdown yaml testthat callr vdiffr data.table bit64 DBI RSQLite progressr cli htmltools svglite png CompQuadForm"
missing=$(Rscript --vanilla -e "p <- strsplit('$pkgs', ' ')[[1]]; cat(p[!vapply(p, requireNamespace, logical(1), quietly = TRUE)])")
if [ -n "$missing" ]; then
  echo "setup: installing $missing"
  debs=""
  if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >/dev/null || true
    # only the packages Debian has: one unknown name fails the whole install
    for p in $missing; do
      d="r-cran-$(echo "$p" | tr 'A-Z' 'a-z')"
      if apt-cache show "$d" >/dev/null 2>&1; then debs="$debs $d"; fi
    done
    apt-get install -y -qq --no-install-recommends $debs >/dev/null || true
  fi
  still=$(Rscript --vanilla -e "p <- strsplit('$missing', ' ')[[1]]; cat(p[!vapply(p, requireNamespace, logical(1), quietly = TRUE)])")
  if [ -n "$still" ]; then
    echo "setup: installing from CRAN: $still"
    Rscript --vanilla -e "install.packages(strsplit('$still', ' ')[[1]], repos = 'https://cloud.r-project.org')"
  fi
fi
# Headless Chromium opens the HTML reports in the tests (test-report.R skips
# without it).
if ! command -v chromium >/dev/null 2>&1 && ! command -v chromium-browser >/dev/null 2>&1 \
   && command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
  apt-get update -qq >/dev/null || true
  apt-get install -y -qq --no-install-recommends chromium >/dev/null || true
fi
# pandoc builds the vignettes (main job only; the tests do not need it).
if [ "${ALLANVAR_NEED_PANDOC:-0}" = 1 ] && ! command -v pandoc >/dev/null 2>&1 \
   && command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
  apt-get install -y -qq --no-install-recommends pandoc >/dev/null || true
fi
