#include "isohex/mesh/generate.hpp"

#include "isohex/error.hpp"

#include <fmt/format.h>

#include <random>

namespace isohex {

HexMesh box_mesh(int nx, int ny, int nz, const Vec3& lo, const Vec3& hi) {
  if (nx < 1 || ny < 1 || nz < 1)
    throw Error(fmt::format("box mesh: cell counts must be at least 1, got {} x {} x {}", nx, ny, nz));
  HexMesh m;
  m.points.reserve(static_cast<std::size_t>(nx + 1) * (ny + 1) * (nz + 1));
  m.hexes.reserve(static_cast<std::size_t>(nx) * ny * nz);
  auto id = [&](int i, int j, int k) { return static_cast<Index>(i + (nx + 1) * (j + (ny + 1) * k)); };
  const Vec3 d = (hi - lo).cwiseQuotient(Vec3(nx, ny, nz));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        // Exact end points, whatever the rounding of lo + i*d.
        m.points.emplace_back(i == nx ? hi.x() : lo.x() + i * d.x(), j == ny ? hi.y() : lo.y() + j * d.y(),
                              k == nz ? hi.z() : lo.z() + k * d.z());
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        m.hexes.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1),
                           id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)});
  return m;
}

HexMesh ball_mesh(int n, double radius) {
  HexMesh m = box_mesh(n, n, n, Vec3::Constant(-1), Vec3::Constant(1));
  for (Vec3& p : m.points) {
    const double r2 = p.norm();
    if (r2 > 0) p *= radius * p.cwiseAbs().maxCoeff() / r2;
  }
  return m;
}

void jitter(HexMesh& mesh, double amplitude, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  for (std::size_t i = 0; i < mesh.points.size(); ++i) {
    const Vec3 d(u(rng), u(rng), u(rng));  // drawn for every vertex so results don't depend on flags
    if (!mesh.has_fixed() || !mesh.fixed[i]) mesh.points[i] += d;
  }
}

}  // namespace isohex
