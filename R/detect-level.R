# A detection level whose count does not hinge on the level's own noise.
#
# A detector compares each candidate's statistic with a level (a Bonferroni
# quantile, at least min_z, or the series' own tail). The statistics share a
# scale estimated from the record, and an effect added to the series moves
# that scale, so every statistic, by about 2%: a candidate within that of
# the level falls in or out (spike counts of measured axes flipped in 26 of
# 188 battery cases with a line, band, square wave or GM added). The level
# is raised from `zc` to the least value with no candidate within a factor
# 1 + `margin` on either side (where the candidates above are many, fewer
# there than `crowd` of them), looked for up to zc (1 + `reach`). Where the
# candidates are a continuum through that range no level is clear, and zc
# stays: there a 2% move changes the count by a few percent, as a
# continuum's count does. Raised only, never lowered: the false-alarm rate
# of the level `zc` is kept or lowered.
#
# (Tried on the bias-step search, which stops at its first candidate below
# the level: on the measured accelerometers its candidates run from 6 to 10
# in no order, a clear level lay 6-18% up and took 2-5 of an axis's 4-7
# transients away; not kept.)
#
# `v`: the candidates' statistics (down to zc / (1 + margin) at least).
# Returns the level.
stable_level <- function(v, zc, margin = 0.03, reach = 0.25, crowd = 0.03) {
  v <- abs(v[is.finite(v)])
  if (!length(v) || !is.finite(zc)) return(zc)
  # the band count changes only where a candidate leaves it from below
  # (t = v (1 + margin)): those points and zc are the levels to try
  ts <- sort(unique(c(zc, v * (1 + margin))))
  ts <- ts[ts >= zc & ts <= zc * (1 + reach)]
  for (t in ts) {
    near <- sum(v > t / (1 + margin) & v < t * (1 + margin))
    if (near <= floor(crowd * sum(v >= t))) return(t)
  }
  zc
}
