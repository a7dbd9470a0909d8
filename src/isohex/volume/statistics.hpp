#pragma once
/// \file statistics.hpp
/// \brief What a volume's values look like: range, mean, a histogram, and an isovalue
/// suggested by Otsu's method (the threshold that best separates two classes of values).

#include "isohex/volume/volume.hpp"

#include <cstddef>
#include <vector>

namespace isohex {

/// Summary of the finite values of a volume (NaN and infinities are only counted).
struct ValueStatistics {
  double min = 0, max = 0, mean = 0;
  std::size_t count = 0;       ///< finite values
  std::size_t non_finite = 0;  ///< NaN or infinite values, left out of everything else
};

/// Value counts in `counts.size()` equal bins over [lo, hi]; bin i covers
/// [lo + i·w, lo + (i+1)·w) with w = (hi - lo) / bins, the last bin also holds hi.
struct ValueHistogram {
  double lo = 0, hi = 0;
  std::vector<std::size_t> counts;

  [[nodiscard]] double bin_width() const { return counts.empty() ? 0 : (hi - lo) / static_cast<double>(counts.size()); }
  /// Lower edge of bin i (i = counts.size() gives hi).
  [[nodiscard]] double edge(std::size_t i) const {
    return i == counts.size() ? hi : lo + bin_width() * static_cast<double>(i);
  }
};

/// Min, max and mean (accumulated in double) of the finite values.
ValueStatistics value_statistics(const Volume& volume);

/// Histogram of the finite values over [stats.min, stats.max] in `bins` bins (at least 1).
/// A constant volume gives one full bin whatever `bins` is.
ValueHistogram value_histogram(const Volume& volume, const ValueStatistics& stats, std::size_t bins);

/// Otsu's threshold of a histogram: the bin edge that maximises the between-class variance
/// of the values below and above it (bins represented by their centres). When several
/// edges tie, as between the two levels of a two-level volume, the middle one is taken.
/// A histogram with one non-empty bin gives that bin's centre.
double otsu_threshold(const ValueHistogram& histogram);

/// Otsu's threshold of the volume's values over a `bins`-bin histogram: an isovalue that
/// separates the dominant two classes (for example tissue and background).
double otsu_isovalue(const Volume& volume, std::size_t bins = 256);

}  // namespace isohex
