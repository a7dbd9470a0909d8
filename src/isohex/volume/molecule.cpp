// The blobby Gaussian density of a molecule on a regular grid.
#include "isohex/volume/molecule.hpp"

#include "isohex/error.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace isohex {

namespace {

// The grid-point box an atom's cut-off sphere covers, and where its 1-D factors live.
struct Footprint {
  std::array<Index, 3> lo{}, hi{};  // inclusive grid ranges; empty when lo > hi on an axis
  std::size_t x_at = 0, yz_at = 0;  // offsets of its x factors (float) and y, z factors (double)
};

void check_options(const DensityOptions& o) {
  if (!(o.spacing > 0) || !std::isfinite(o.spacing)) throw Error(fmt::format("grid spacing {} is not positive", o.spacing));
  if (!(o.padding >= 0) || !std::isfinite(o.padding)) throw Error(fmt::format("padding {} is negative", o.padding));
  if (!(o.blobbiness > 0) || !std::isfinite(o.blobbiness))
    throw Error(fmt::format("blobbiness {} is not positive", o.blobbiness));
  if (!(o.epsilon > 0 && o.epsilon < 1)) throw Error(fmt::format("epsilon {} is not in (0, 1)", o.epsilon));
}

void check_atoms(std::span<const Atom> atoms) {
  if (atoms.empty()) throw Error("no atoms to build a density map from (all filtered out?)");
  for (const Atom& a : atoms) {
    if (!a.center.allFinite()) throw Error(fmt::format("atom of line {}: its position is not finite", a.line));
    if (!(a.radius > 0) || !std::isfinite(a.radius))
      throw Error(fmt::format("atom of line {}: radius {} is not positive", a.line, a.radius));
  }
}

// Grid dims and origin covering every atom's sphere plus the padding.
void set_grid(std::span<const Atom> atoms, const DensityOptions& o, Volume& v) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Atom& a : atoms) {
    lo = lo.cwiseMin(a.center - Vec3::Constant(a.radius));
    hi = hi.cwiseMax(a.center + Vec3::Constant(a.radius));
  }
  lo -= Vec3::Constant(o.padding);
  hi += Vec3::Constant(o.padding);
  double points = 1;
  for (int d = 0; d < 3; ++d) {
    const double n = std::ceil((hi[d] - lo[d]) / o.spacing) + 1;
    points *= n;
    if (points > double(std::numeric_limits<Index>::max()))
      throw Error(fmt::format("the density grid would exceed 2^31 points at spacing {} Å; use a coarser spacing",
                              o.spacing));
    v.dims[d] = static_cast<Index>(n);
  }
  v.spacing = Vec3::Constant(o.spacing);
  v.origin = lo;
}

double boundary_max(const Volume& v) {
  const auto [nx, ny, nz] = v.dims;
  float m = -std::numeric_limits<float>::infinity();
  for (Index k = 0; k < nz; ++k)
    for (Index j = 0; j < ny; ++j) {
      const bool face = k == 0 || k == nz - 1 || j == 0 || j == ny - 1;
      for (Index i = 0; i < nx; i += face ? 1 : std::max<Index>(1, nx - 1)) m = std::max(m, v.at(i, j, k));
    }
  return m;
}

}  // namespace

double gaussian_cutoff_factor(double blobbiness, double threshold) {
  // exp(-B·(s² - 1)) = t  <=>  s² = 1 + ln(1/t) / B
  return std::sqrt(1.0 + std::log(1.0 / threshold) / blobbiness);
}

double gaussian_density_at(std::span<const Atom> atoms, double blobbiness, const Vec3& p) {
  double sum = 0;
  for (const Atom& a : atoms) sum += std::exp(-blobbiness * ((p - a.center).squaredNorm() / (a.radius * a.radius) - 1.0));
  return sum;
}

Volume gaussian_density(std::span<const Atom> atoms, const DensityOptions& o, DensityReport* report) {
  check_options(o);
  check_atoms(atoms);
  Volume v;
  set_grid(atoms, o, v);
  v.values.assign(v.size(), 0.0f);
  const double B = o.blobbiness, h = o.spacing;
  const double factor = gaussian_cutoff_factor(B, o.epsilon * kAtomTailShare);

  // Each atom's cut-off box, then its 1-D Gaussians along x (float: the innermost loop),
  // y and z (double: multiplied once per row). exp(-a·d²) = exp(-a·dx²)·exp(-a·dy²)·exp(-a·dz²),
  // and the exp(B) factor goes into z.
  std::vector<Footprint> fp(atoms.size());
  std::size_t x_total = 0, yz_total = 0;
  for (std::size_t n = 0; n < atoms.size(); ++n) {
    const double cut = factor * atoms[n].radius;
    for (int d = 0; d < 3; ++d) {
      const double c = (atoms[n].center[d] - v.origin[d]) / h, r = cut / h;
      fp[n].lo[d] = static_cast<Index>(std::max(0.0, std::ceil(c - r)));
      fp[n].hi[d] = static_cast<Index>(std::min(double(v.dims[d] - 1), std::floor(c + r)));
    }
    fp[n].x_at = x_total;
    fp[n].yz_at = yz_total;
    x_total += static_cast<std::size_t>(fp[n].hi[0] - fp[n].lo[0] + 1);
    yz_total += static_cast<std::size_t>(fp[n].hi[1] - fp[n].lo[1] + 1 + fp[n].hi[2] - fp[n].lo[2] + 1);
  }
  std::vector<float> fx(x_total);
  std::vector<double> fyz(yz_total);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, atoms.size()), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t n = r.begin(); n != r.end(); ++n) {
      const Atom& a = atoms[n];
      const double alpha = B / (a.radius * a.radius);
      const Footprint& f = fp[n];
      auto g = [&](int d, Index i) {
        const double t = v.origin[d] + i * h - a.center[d];
        return std::exp(-alpha * t * t);
      };
      for (Index i = f.lo[0]; i <= f.hi[0]; ++i) fx[f.x_at + (i - f.lo[0])] = static_cast<float>(g(0, i));
      double* y = fyz.data() + f.yz_at;
      for (Index j = f.lo[1]; j <= f.hi[1]; ++j) y[j - f.lo[1]] = g(1, j);
      double* z = y + (f.hi[1] - f.lo[1] + 1);
      const double peak = std::exp(B);
      for (Index k = f.lo[2]; k <= f.hi[2]; ++k) z[k - f.lo[2]] = peak * g(2, k);
    }
  });

  // z-slabs in parallel; inside a slab atoms go in file order, so each grid point sums its
  // atoms in that order whatever the slab boundaries are.
  std::atomic<std::size_t> touched{0};
  tbb::parallel_for(tbb::blocked_range<Index>(0, v.dims[2]), [&](const tbb::blocked_range<Index>& slab) {
    std::size_t count = 0;
    for (std::size_t n = 0; n < atoms.size(); ++n) {
      const Footprint& f = fp[n];
      const Index k0 = std::max(f.lo[2], slab.begin()), k1 = std::min(f.hi[2], slab.end() - 1);
      if (k0 > k1 || f.lo[0] > f.hi[0] || f.lo[1] > f.hi[1]) continue;
      const Atom& a = atoms[n];
      const double cut = factor * a.radius, cut2 = cut * cut;
      const float* x = fx.data() + f.x_at;
      const double* y = fyz.data() + f.yz_at;
      const double* z = y + (f.hi[1] - f.lo[1] + 1);
      for (Index k = k0; k <= k1; ++k) {
        const double dz = v.origin[2] + k * h - a.center[2];
        for (Index j = f.lo[1]; j <= f.hi[1]; ++j) {
          const double dy = v.origin[1] + j * h - a.center[1];
          const double rest = cut2 - dz * dz - dy * dy;
          if (rest < 0) continue;
          // The row's points inside the cut-off sphere.
          const double half = std::sqrt(rest), c = (a.center[0] - v.origin[0]) / h;
          const Index i0 = std::max(f.lo[0], static_cast<Index>(std::ceil(c - half / h)));
          const Index i1 = std::min(f.hi[0], static_cast<Index>(std::floor(c + half / h)));
          if (i0 > i1) continue;
          const auto w = static_cast<float>(z[k - f.lo[2]] * y[j - f.lo[1]]);
          float* row = &v.values[v.index(0, j, k)];
          const float* xs = x - f.lo[0];
          for (Index i = i0; i <= i1; ++i) row[i] += w * xs[i];
          count += static_cast<std::size_t>(i1 - i0 + 1);
        }
      }
    }
    touched += count;
  });

  if (report) {
    report->cutoff_factor = factor;
    report->voxels_touched = touched;
    report->boundary_max = boundary_max(v);
  }
  return v;
}

}  // namespace isohex
