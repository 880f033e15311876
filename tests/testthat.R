# processx (the callr tests) otherwise replaces parallel's SIGCHLD handler:
# analyze_imu()'s forked workers then go unreaped and R waits 10 s at exit
Sys.setenv(PROCESSX_NOTIFY_OLD_SIGCHLD = "true")
library(testthat)
library(allanvar)

test_check("allanvar")
