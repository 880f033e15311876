#!/usr/bin/env bash
# The main job: install what is missing, install the package, run
# demo(allanvar) and write its plots to output/demo-allanvar.pdf.
set -euo pipefail
cd "$(dirname "$0")/.."
ALLANVAR_NEED_PANDOC=1 bash tools/setup.sh
mkdir -p output
R CMD INSTALL --preclean . >output/install.log 2>&1 || { cat output/install.log; exit 1; }
Rscript --vanilla -e '
  library(allanvar)
  grDevices::pdf("output/demo-allanvar.pdf", width = 8, height = 6)
  demo("allanvar", package = "allanvar", ask = FALSE, echo = FALSE)
  invisible(grDevices::dev.off())
  cat("demo(allanvar) ran; plots written to output/demo-allanvar.pdf\n")
'
