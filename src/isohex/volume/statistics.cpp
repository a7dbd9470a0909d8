#include "isohex/volume/statistics.hpp"

#include <algorithm>
#include <cmath>

namespace isohex {

ValueStatistics value_statistics(const Volume& volume) {
  ValueStatistics s;
  double lo = INFINITY, hi = -INFINITY, sum = 0;
  for (float v : volume.values) {
    if (!std::isfinite(v)) {
      ++s.non_finite;
      continue;
    }
    lo = std::min<double>(lo, v);
    hi = std::max<double>(hi, v);
    sum += v;
    ++s.count;
  }
  if (s.count > 0) {
    s.min = lo;
    s.max = hi;
    s.mean = sum / static_cast<double>(s.count);
  }
  return s;
}

ValueHistogram value_histogram(const Volume& volume, const ValueStatistics& stats, std::size_t bins) {
  ValueHistogram h;
  h.lo = stats.min;
  h.hi = stats.max;
  const std::size_t n = stats.max > stats.min ? std::max<std::size_t>(bins, 1) : 1;
  h.counts.assign(n, 0);
  const double scale = stats.max > stats.min ? static_cast<double>(n) / (stats.max - stats.min) : 0;
  for (float v : volume.values) {
    if (!std::isfinite(v)) continue;
    const double b = (v - stats.min) * scale;
    h.counts[std::min(n - 1, static_cast<std::size_t>(std::max(0.0, b)))]++;
  }
  return h;
}

double otsu_threshold(const ValueHistogram& h) {
  const std::size_t n = h.counts.size();
  double total = 0, total_sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double centre = h.lo + h.bin_width() * (static_cast<double>(i) + 0.5);
    total += static_cast<double>(h.counts[i]);
    total_sum += static_cast<double>(h.counts[i]) * centre;
  }
  if (n == 0 || total == 0) return h.lo;
  // Threshold after bin k: classes [0, k] and [k+1, n). Between-class variance
  // w0 w1 (mu0 - mu1)^2 = (mu_T w0 - m0)^2 / (w0 w1) with weights as fractions.
  double best = -1, m0 = 0;
  std::size_t first = 0, last = 0, below = 0;
  const double mu_t = total_sum / total;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const double centre = h.lo + h.bin_width() * (static_cast<double>(k) + 0.5);
    below += h.counts[k];
    m0 += static_cast<double>(h.counts[k]) / total * centre;
    if (below == 0 || static_cast<double>(below) == total) continue;  // one class is empty
    const double w0 = static_cast<double>(below) / total, w1 = 1 - w0;
    const double d = mu_t * w0 - m0;
    const double var = d * d / (w0 * w1);
    if (var > best * (1 + 1e-12)) {
      best = var;
      first = last = k;
    } else if (var >= best * (1 - 1e-12) && last + 1 == k) {  // extend a run of ties only
      last = k;
    }
  }
  if (best < 0) {  // a single non-empty bin: no split
    for (std::size_t i = 0; i < n; ++i)
      if (h.counts[i]) return h.lo + h.bin_width() * (static_cast<double>(i) + 0.5);
  }
  return h.edge((first + last) / 2 + 1);
}

double otsu_isovalue(const Volume& volume, std::size_t bins) {
  const ValueStatistics s = value_statistics(volume);
  return otsu_threshold(value_histogram(volume, s, bins));
}

}  // namespace isohex
