library(testthat)
library(allanvar)

test_check("allanvar")
