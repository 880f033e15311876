# allanvar 1.1 compatibility: data(gyroz_complete) defines `gyroz`, the
# 65,536-sample series stored in gyroz_long.rda (this runs in data/).
gyroz <- local({
  env <- new.env()
  load("gyroz_long.rda", envir = env)
  env$gyroz_long
})
