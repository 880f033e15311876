# Catalogue entries of the non-stationary effects read from the raw series
# (component "series"): isolated spikes, bias steps, transients (a pulse
# that returns) and an exponential warm-up. They are not terms of the Allan
# variance: each entry's `detect(x, freq)` finds its instances in the
# series and `remove(x, freq, par)` takes them out; detect_series_effects()
# (R/series.R) runs them in catalogue order. The detectors themselves are
# in R/nonstationary.R.
#
# detect() returns one row per instance: the entry's parameters (every
# entry has `size`, in the rate unit) plus `index` (first sample
# affected), `z` (detection statistic, in noise standard deviations) and
# `evidence` (what the series shows, in words). remove() takes such rows.

series_rows <- function(..., evidence = character()) {
  data.frame(..., evidence = evidence, stringsAsFactors = FALSE)
}

# Sample index of a time (s from the first sample), within 1..n.
time_index <- function(time, tau0, n) {
  pmin(pmax(as.integer(round(time / tau0)) + 1L, 1L), n)
}

row_index <- function(par, freq, n) {
  if (!is.null(par$index)) as.integer(par$index) else time_index(par$time, 1 / freq, n)
}

effect_spike <- function() {
  new_effect(
    name = "spikes", title = "isolated spike (outlier)", component = "series",
    params = rbind(
      effect_param("size", "amp", "u", "rate unit (excess over the running median)"),
      effect_param("time", "nonlinear", "s", "second (when)")),
    repeatable = TRUE,
    signature = paste("single samples far from their neighbours (robust",
                      "scale of the residual from a running median); raise",
                      "the Allan variance at the shortest tau"),
    sim = function(n, tau0, amp, nl) {
      y <- numeric(n)
      y[time_index(nl[["time"]], tau0, n)] <- amp[[1L]]
      y
    },
    detect = function(x, freq) {
      sp <- detect_spikes(x, freq)
      series_rows(size = sp$size, time = sp$time, index = sp$index, z = sp$z,
                  evidence = sprintf("%s robust sd from the running median",
                                     format_num(abs(sp$z))))
    },
    remove = function(x, freq, par) {
      if (!nrow(par)) return(x)
      i <- row_index(par, freq, length(x))
      x[i] <- x[i] - par$size
      x
    },
    # a step's or a transient's edge is an outlier of the AR model until
    # they are out (a step of 10 white sd drew a "spike" at its first
    # sample in 5 of 12 seeds)
    detect_again = TRUE,
    describe = function(values) {
      sprintf("%d spike%s (largest %s)", nrow(values),
              if (nrow(values) == 1L) "" else "s",
              format_num(values$size[which.max(abs(values$size))]))
    }
  )
}

effect_bias_step <- function() {
  new_effect(
    name = "steps", title = "bias step", component = "series",
    params = rbind(
      effect_param("size", "amp", "u", "rate unit (level after minus before)"),
      effect_param("time", "nonlinear", "s", "second (when)")),
    repeatable = TRUE,
    signature = paste("a sharp change of level that stays (changepoint of the",
                      "Allan differences, standardised by the series' own",
                      "Allan variance); raises the long-tau Allan variance",
                      "like a rate random walk"),
    sim = function(n, tau0, amp, nl) {
      amp[[1L]] * (seq_len(n) >= time_index(nl[["time"]], tau0, n))
    },
    detect = function(x, freq) {
      st <- pass_steps(x, freq)
      series_rows(size = st$size, time = st$time, index = st$index, z = st$z,
                  evidence = sprintf(
                    "Allan difference over %s s on each side at z = %s (size %s +- %s)",
                    format_num(st$window), format_num(st$z, 2),
                    format_num(st$size), format_num(st$se, 2)))
    },
    remove = function(x, freq, par) {
      if (!nrow(par)) return(x)
      remove_steps(x, data.frame(index = row_index(par, freq, length(x)),
                                 size = par$size))
    },
    # a step within a warm-up's reach is judged with it by the warm-up's
    # likelihood (steps_beside_warmup_z()), at the warm-up's own level: the
    # Allan differences read the exponential's misfit as a step
    judge = function(x, freq, table) {
      own <- table[table$kind == "steps", , drop = FALSE]
      wu <- table[table$kind == "warmup", , drop = FALSE]
      if (!nrow(own) || !nrow(wu)) return(own)
      x <- remove_series(x, freq, table[!table$kind %in% c("steps", "warmup"), , drop = FALSE])
      z <- steps_beside_warmup_z(x, freq, own$time, wu$tc)
      read <- !is.na(z)
      own$evidence[read] <- sprintf("%s; beside the warm-up, likelihood ratio z = %s",
                                    own$evidence[read], format_num(z[read], 2))
      own[!read | z > warmup_z_level, , drop = FALSE]
    },
    describe = function(values) {
      sprintf("bias step%s of %s at %s s", if (nrow(values) == 1L) "" else "s",
              paste(format_num(values$size), collapse = ", "),
              paste(format_num(values$time), collapse = ", "))
    }
  )
}

effect_transient <- function() {
  new_effect(
    name = "transients", title = "transient (a pulse that returns)",
    component = "series",
    # a Gauss-Markov term's own slow swings are transients to the detector
    noise_lookalike = TRUE,
    params = rbind(
      effect_param("size", "amp", "u", "rate unit (offset while it lasts)"),
      effect_param("time", "nonlinear", "s", "second (start)"),
      effect_param("duration", "nonlinear", "s", "second (how long)")),
    repeatable = TRUE,
    signature = paste("two bias steps of opposite sign and similar size close",
                      "together (a knock, a tilt that returns); raises the",
                      "Allan variance around tau of its duration"),
    sim = function(n, tau0, amp, nl) {
      i <- seq_len(n)
      a <- time_index(nl[["time"]], tau0, n)
      b <- time_index(nl[["time"]] + nl[["duration"]], tau0, n)
      amp[[1L]] * (i >= a & i < b)
    },
    detect = function(x, freq) {
      pu <- attr(pass_steps(x, freq), "pulses")
      series_rows(size = pu$size, time = pu$start, duration = pu$end - pu$start,
                  index = time_index(pu$start, 1 / freq, length(x)),
                  z = rep(NA_real_, nrow(pu)),
                  evidence = sprintf("steps of %s and back %s s later",
                                     format_num(pu$size),
                                     format_num(pu$end - pu$start)))
    },
    remove = function(x, freq, par) {
      if (!nrow(par)) return(x)
      n <- length(x)
      for (k in seq_len(nrow(par))) {
        a <- time_index(par$time[k], 1 / freq, n)
        b <- time_index(par$time[k] + par$duration[k], 1 / freq, n)
        if (b > a) x[a:(b - 1L)] <- x[a:(b - 1L)] - par$size[k]
      }
      x
    },
    describe = function(values) {
      sprintf("%d transient%s (largest %s, %s s)", nrow(values),
              if (nrow(values) == 1L) "" else "s",
              format_num(values$size[which.max(abs(values$size))]),
              format_num(values$duration[which.max(abs(values$size))]))
    }
  )
}

effect_warmup <- function() {
  new_effect(
    name = "warmup", title = "exponential warm-up", component = "series",
    params = rbind(
      effect_param("size", "amp", "u", "rate unit (offset at the first sample)"),
      effect_param("tc", "nonlinear", "s", "second (time constant)")),
    repeatable = TRUE,
    # a step near the start bends the exponential (its time constant read
    # 163 s for 120 s beside a step at 40 s): read again with the steps,
    # transients and spikes out
    detect_again = TRUE,
    signature = paste("a decaying offset at the start, size exp(-t / tc);",
                      "raises the Allan variance around tau = tc"),
    sim = function(n, tau0, amp, nl) {
      amp[[1L]] * exp(-(seq_len(n) - 1) * tau0 / nl[["tc"]])
    },
    detect = function(x, freq) {
      w <- detect_warmup(x, freq)$all
      series_rows(size = w$amplitude, tc = w$tc, time = rep(0, nrow(w)),
                  index = rep(1L, nrow(w)), z = w$z,
                  evidence = sprintf(paste(
                    "GLS fit of exp(-t / tc) on block means under the series' own noise model",
                    "(white, random walk, Gauss-Markov from its Allan variance) at z = %s;",
                    "tc 95%% interval %s"), format_num(w$z, 2),
                    ifelse(is.na(w$tc_lower), "not determined (flat likelihood)",
                           sprintf("%s-%s s (profile likelihood)", format_num(w$tc_lower, 2),
                                   format_num(w$tc_upper, 2)))))
    },
    remove = function(x, freq, par) {
      if (!nrow(par)) return(x)
      t <- (seq_along(x) - 1) / freq
      for (k in seq_len(nrow(par))) x <- x - par$size[k] * exp(-t / par$tc[k])
      x
    },
    describe = function(values) {
      sprintf("warm-up of %s (time constant %s s)",
              paste(format_num(values$size), collapse = ", "),
              paste(format_num(values$tc), collapse = ", "))
    }
  )
}
