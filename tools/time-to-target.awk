# For the accuracy scripts' tables, with awk -f tools/time-to-target.awk -f PROGRAM: the time a
# curve of n[k] levels (times t[k, i], relMSE r[k, i], in increasing order) takes to reach the
# relMSE `target`, interpolated linearly between levels on the log-log curve.
function g(x) { return sprintf("%.3g", x) }
function lerp(x, x0, x1, y0, y1) { return y0 + (x - x0) / (x1 - x0) * (y1 - y0) }
function timeTo(k,   i) {
  if (r[k, 1] <= target) return "≤ " g(t[k, 1])
  for (i = 2; i <= n[k]; ++i) if (r[k, i] <= target)
    return g(exp(lerp(log(target), log(r[k, i - 1]), log(r[k, i]), log(t[k, i - 1]), log(t[k, i]))))
  return "not reached"
}
