# processx (callr) calls parallel's SIGCHLD handler too, so the forked
# workers of analyze_imu() are reaped (tools/run-tests.R says why)
Sys.setenv(PROCESSX_NOTIFY_OLD_SIGCHLD = "true")
library(testthat)
library(allanvar)

test_check("allanvar")
