// The data behind the report's 3D view: which quads and hexes to embed, and their packing.
//
// The viewer shows the surface of the set of "kept" cells (hexes on one side of a cut plane,
// optionally only the bad ones): a quad is drawn when exactly one of its two cells is kept,
// facing away from that cell and coloured by its scaled Jacobian. So the page needs, per
// unique quad, its corners and the cells on its two sides, and per cell a centroid and a
// scaled Jacobian. Small meshes embed every quad. Large ones embed the boundary (a shell,
// seen from inside where it is cut) and the worst hexes as solid blocks within it.
#include "isohex/error.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/quality/report_detail.hpp"

#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <limits>

namespace isohex {

ViewerMesh viewer_mesh(const HexMesh& mesh, const std::vector<double>& sj, const ReportViewerLimits& limits) {
  if (sj.size() != mesh.hexes.size())
    throw Error("report: the final stage has " + std::to_string(sj.size()) + " values for a mesh of " +
                std::to_string(mesh.hexes.size()) + " hexes");
  ViewerMesh v;
  v.mesh_hexes = mesh.hexes.size();
  v.complete = mesh.hexes.size() <= limits.max_hexes;
  const std::vector<QuadFace> all = build_quads(mesh);

  // Cells: every hex, or the worst ones (degenerate first, then ascending SJ, ties by id).
  std::vector<std::uint8_t> worst(mesh.hexes.size(), 0);
  if (!v.complete) {
    std::vector<Index> bad;
    for (Index h = 0; h < mesh.num_hexes(); ++h)
      if (is_degenerate(sj[h]) || sj[h] < kQuestionableSJ) bad.push_back(h);
    auto key = [&](Index h) { return is_degenerate(sj[h]) ? -2.0 : sj[h]; };
    const std::size_t keep = std::min(bad.size(), limits.max_worst_hexes);
    std::partial_sort(bad.begin(), bad.begin() + static_cast<std::ptrdiff_t>(keep), bad.end(),
                      [&](Index a, Index b) { return key(a) != key(b) ? key(a) < key(b) : a < b; });
    for (std::size_t i = 0; i < keep; ++i) worst[bad[i]] = 1;
    v.worst_hexes = keep;
  }
  auto embedded_quad = [&](const QuadFace& q) {
    return v.complete || q.is_boundary() || worst[q.hex[0]] || (q.hex[1] >= 0 && worst[q.hex[1]]);
  };

  // A hex is a cell on a quad's side if every hex is embedded, if it is one of the worst
  // hexes (drawn as a solid block), or if the quad is its boundary face (the shell). Other
  // sides are left empty (-1): the viewer treats them as never kept.
  auto side_cell = [&](const QuadFace& q, int k) {
    const Index h = q.hex[k];
    return h >= 0 && (v.complete || worst[h] || q.is_boundary());
  };
  // Mark the cells and vertices in use (-2), then number them in ascending mesh order, so
  // that the numbering does not depend on the order in which quads reach them.
  constexpr std::int32_t kUsed = -2;
  std::vector<std::int32_t> cell_of(mesh.hexes.size(), -1);
  std::vector<std::int32_t> vertex_of(mesh.points.size(), -1);
  for (const QuadFace& q : all) {
    if (!embedded_quad(q)) continue;
    for (Index p : q.vertices) vertex_of[p] = kUsed;
    for (int k = 0; k < 2; ++k)
      if (side_cell(q, k)) cell_of[q.hex[k]] = kUsed;
  }
  std::int32_t cells = 0;
  for (Index h = 0; h < mesh.num_hexes(); ++h)
    if (cell_of[h] == kUsed) cell_of[h] = cells++, v.cell_hex.push_back(h);
  std::int32_t verts = 0;
  for (auto& id : vertex_of)
    if (id == kUsed) id = verts++;

  // Centre on the box of the embedded vertices and scale to radius 1: float32 then keeps
  // the shape of a mesh far from the origin, and the page's camera needs no fitting.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max()), hi = -lo;
  for (std::size_t p = 0; p < mesh.points.size(); ++p)
    if (vertex_of[p] >= 0) lo = lo.cwiseMin(mesh.points[p]), hi = hi.cwiseMax(mesh.points[p]);
  if (verts == 0) lo = hi = Vec3::Zero();
  const Vec3 centre = (lo + hi) / 2;
  const double radius = (hi - lo).norm() / 2;
  const double scale = radius > 0 ? 1 / radius : 1;
  auto put = [&](std::vector<float>& out, const Vec3& p) {
    for (int k = 0; k < 3; ++k) out.push_back(static_cast<float>((p[k] - centre[k]) * scale));
  };
  v.points.reserve(static_cast<std::size_t>(verts) * 3);
  for (std::size_t p = 0; p < mesh.points.size(); ++p)
    if (vertex_of[p] >= 0) put(v.points, mesh.points[p]);
  for (Index h : v.cell_hex) {
    Vec3 c = Vec3::Zero();
    for (Index p : mesh.hexes[h]) c += mesh.points[p];
    put(v.centroids, c / 8);
    v.sj.push_back(is_degenerate(sj[h]) ? 1e30f : static_cast<float>(sj[h]));
  }
  for (const QuadFace& q : all) {
    if (!embedded_quad(q)) continue;
    for (Index p : q.vertices) v.quads.push_back(static_cast<std::uint32_t>(vertex_of[p]));
    for (int k = 0; k < 2; ++k) v.sides.push_back(side_cell(q, k) ? cell_of[q.hex[k]] : -1);
  }
  return v;
}

namespace report_detail {

namespace {

template <typename T>
void append_words(std::string& out, const std::vector<T>& values) {
  static_assert(sizeof(T) == 4);
  for (const T& x : values) {
    std::uint32_t w;
    std::memcpy(&w, &x, 4);
    // Little-endian whatever the host, as the page's typed arrays expect on every browser.
    for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((w >> (8 * b)) & 0xff));
  }
}

}  // namespace

std::string base64_encode(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const auto n = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16 |
                   static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8 |
                   static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 2]));
    for (int k = 3; k >= 0; --k) out.push_back(kAlphabet[(n >> (6 * k)) & 63]);
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    std::uint32_t n = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16;
    if (rest == 2) n |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8;
    out.push_back(kAlphabet[(n >> 18) & 63]);
    out.push_back(kAlphabet[(n >> 12) & 63]);
    out.push_back(rest == 2 ? kAlphabet[(n >> 6) & 63] : '=');
    out.push_back('=');
  }
  return out;
}

std::string viewer_payload(const ViewerMesh& v) {
  std::string raw;
  raw.reserve(4 * (v.points.size() + v.quads.size() + v.sides.size() + v.centroids.size() + v.sj.size()));
  append_words(raw, v.points);
  append_words(raw, v.quads);
  append_words(raw, v.sides);
  append_words(raw, v.centroids);
  append_words(raw, v.sj);
  // zlib format, which the page inflates with the browser's DecompressionStream("deflate").
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string packed(size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(packed.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
                static_cast<uLong>(raw.size()), 6) != Z_OK)
    throw Error("report: zlib could not compress the viewer data");
  packed.resize(size);
  return base64_encode(packed);
}

nlohmann::json viewer_info(const ViewerMesh& v) {
  const std::size_t bytes = 4 * (v.points.size() + v.quads.size() + v.sides.size() + v.centroids.size() + v.sj.size());
  return {{"points", v.points.size() / 3}, {"quads", v.quads.size() / 4}, {"cells", v.sj.size()},
          {"bytes", bytes},                {"complete", v.complete},      {"mesh_hexes", v.mesh_hexes},
          {"worst_hexes", v.worst_hexes}};
}

}  // namespace report_detail

}  // namespace isohex
