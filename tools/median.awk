# median(list): the median of the numbers in a space-separated list (the mean of the middle
# two for an even count). For awk -f tools/median.awk -f PROGRAM.
function median(list,   v, n, i, j, x) {
  n = split(list, v, " ")
  for (i = 2; i <= n; ++i) for (j = i; j > 1 && v[j - 1] + 0 > v[j] + 0; --j) {
    x = v[j]; v[j] = v[j - 1]; v[j - 1] = x
  }
  return n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
}
