// Joint max–min moves of a patch of vertices: the worst pass's end game (patch.hpp).
#include "isohex/optimize/patch.hpp"

#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"
#include "isohex/quality/summary.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace isohex::opt {

namespace {

// The unknowns of a patch: per vertex 3 (a free or loose vertex: the axes) or 2 (a sliding
// vertex: its tangent plane), at offsets `off`.
struct Layout {
  std::vector<Index> verts;
  std::vector<std::array<Vec3, 3>> basis;
  std::vector<int> dims, off;
  std::vector<Vec3> normal;  // a sliding vertex's surface normal where the model was built
  std::vector<double> len;   // mean edge length at the vertex
  int n = 0;
  [[nodiscard]] int slot(Index v) const {
    const auto it = std::lower_bound(verts.begin(), verts.end(), v);
    return it != verts.end() && *it == v ? static_cast<int>(it - verts.begin()) : -1;
  }
};

// The terms the patch changes, linearised: row i is b[i] + Σ_j a[i n + j] d_j; mine[i] for
// the terms of the hex the move is for, frame[i] for a scaled-Jacobian frame (else a ratio term).
struct Rows {
  std::vector<double> a, b;
  std::vector<std::uint8_t> mine, frame, cap;  // cap: a coefficient negated (held below a level)
  std::vector<int> hex;                         // the row's hex, an index into the patch's hexes
};

// What the hexes around the patch are judged by (as move_vertex() judges the hexes around a vertex).
struct Around {
  double min_sj = 2, min_ratio = 1, max_edges = 1;
  int below = 0;
  bool valid = true;  // no hex valid before is invalid, no edge at the patch shrank too far
};

// With `sj_out` and `ratio_out`, each hex's certified scaled Jacobian (−2 where degenerate)
// and ratio bound too; with
// `sj_before`, a hex valid there and not now makes it invalid; with `start`, so does an edge at
// the patch shorter than `shrink` times its length there.
Around measure(const HexMesh& mesh, const std::vector<Index>& hexes, const Layout& L, const std::vector<double>* sj_before,
               const std::vector<Vec3>* start, double shrink, std::vector<double>* sj_out = nullptr,
               std::vector<double>* ratio_out = nullptr) {
  Around r;
  for (std::size_t i = 0; i < hexes.size(); ++i) {
    const Index h = hexes[i];
    const auto p = mesh.corners(h);
    const CertifiedQuality c = certified_quality(p);
    const double q = is_degenerate(c.scaled_jacobian) ? -2.0 : c.scaled_jacobian;
    r.min_sj = std::min(r.min_sj, q);
    r.min_ratio = std::min(r.min_ratio, c.ratio_bound);
    r.max_edges = std::max(r.max_edges, edge_ratio(p));
    r.below += q < kQuestionableSJ;
    if (sj_out) sj_out->push_back(q);
    if (ratio_out) ratio_out->push_back(c.ratio_bound);
    if (sj_before && q <= 0 && (*sj_before)[i] > 0) r.valid = false;
    if (!start) continue;
    for (const auto& e : kHexEdges) {
      const Index a = mesh.hexes[h][e[0]], b = mesh.hexes[h][e[1]];
      if ((L.slot(a) >= 0 || L.slot(b) >= 0) &&
          (p[e[0]] - p[e[1]]).squaredNorm() < shrink * shrink * ((*start)[a] - (*start)[b]).squaredNorm())
        r.valid = false;
    }
  }
  return r;
}

// The rows of hex h: its scaled-Jacobian frames that a patch vertex is in (scaled_frame()) and, where `norm` > 0, those of its 27
// Bernstein coefficients of det J that a patch vertex changes, over `norm` and weighted
// kRatioWeight; gradients in the patch's unknowns. A term the patch cannot change is left out:
// it would cap the LP's bound where no move can help.
void hex_rows(const HexMesh& mesh, Index h, int index, const Layout& L, double norm, bool mine, bool caps, Rows& out) {
  const auto p = mesh.corners(h);
  std::array<int, 8> slot{};
  for (int k = 0; k < 8; ++k) slot[k] = L.slot(mesh.hexes[h][k]);
  const auto push = [&](double value, const std::array<Vec3, 8>& g, bool frame, double sign = 1) {
    out.b.push_back(sign * value);
    out.mine.push_back(mine && sign > 0);
    out.frame.push_back(frame);
    out.cap.push_back(sign < 0);
    out.hex.push_back(index);
    const std::size_t row = out.a.size();
    out.a.resize(row + static_cast<std::size_t>(L.n), 0.0);
    for (int k = 0; k < 8; ++k)
      if (slot[k] >= 0)
        for (int i = 0; i < L.dims[slot[k]]; ++i)
          out.a[row + static_cast<std::size_t>(L.off[slot[k]] + i)] += sign * g[k].dot(L.basis[slot[k]][i]);
  };
  std::array<Vec3, 8> g;
  for (int t = 0; t < kFrames; ++t) {
    bool used = false;
    for (int k = 0; k < 8; ++k) used = used || (slot[k] >= 0 && !frame_coefficient(t, k).isZero());
    if (!used) continue;
    const Mat3 A = frame(p, t, 1.0);
    double value = 0;
    for (int k = 0; k < 8; ++k) {
      const Affine f = scaled_frame(A, frame_coefficient(t, k), slot[k] < 0);
      value = f.b;
      g[k] = f.a;
    }
    push(value, g, true);
  }
  if (!(norm > 0)) return;
  std::array<bool, 8> corners;
  for (int k = 0; k < 8; ++k) corners[k] = slot[k] >= 0;
  std::array<double, 27> b;
  std::array<std::array<Vec3, 27>, 8> gk;
  ratio_coefficients(p, kRatioWeight, norm, corners, b, &gk);
  for (int n = 0; n < 27; ++n) {
    bool moves = false;
    for (int k = 0; k < 8; ++k) {
      g[k] = corners[k] ? gk[k][n] : Vec3::Zero();
      moves = moves || !g[k].isZero();
    }
    if (!moves) continue;
    push(b[n], g, false);
    // The ratio bound is min over max: near the ratio floor, a coefficient rising lowers it as
    // surely as the smallest falling (hold_levels() says how far it may rise).
    if (caps) push(b[n], g, false, -1);
  }
}

// `mine`: the hexes the move is for; `caps`: those whose coefficients get cap rows (per hex).
// Into `r`, emptied first (its storage kept: a large patch's rows are megabytes, and growing
// them afresh per model and per trial was a tenth of the demo's joint moves in page faults and
// copies).
void patch_rows(const HexMesh& mesh, const std::vector<Index>& hexes, const std::vector<double>& norms,
                const std::vector<std::uint8_t>& mine, const std::vector<std::uint8_t>& caps, const Layout& L, Rows& r) {
  r.a.clear(), r.b.clear(), r.mine.clear(), r.frame.clear(), r.cap.clear(), r.hex.clear();
  for (std::size_t i = 0; i < hexes.size(); ++i)
    hex_rows(mesh, hexes[i], static_cast<int>(i), L, norms[i], mine[i] != 0, caps[i] != 0, r);
}

// What the LP does with each row: NaN where the row rises with the bound s, else the level it
// is held at (f >= level). The hex's own ratio terms rise, and its frames below `sj_floor`
// (the worst pass's guard); every frame at or above the floor is held at its value or
// kFrameMargin over the floor (the guard refuses a step that takes a hex below it, and the
// model is linear); another hex's ratio terms are held at their value below the hex's smallest
// term (`now`), rise with s between it and kHoldLevel, and are held at kHoldLevel above. A
// ratio term at or above the guard's ratio floor (weighted: `ratio_level`) is held there too,
// the hex's own ones included: the LP let ratios at the floor fall to s and the guard refused
// every step (ECR block_in, its ratios pressed to 0.200 by the single moves).
constexpr double kHoldLevel = 0.3, kFrameMargin = 0.05, kInfinite = std::numeric_limits<double>::infinity();
double row_level(const Rows& r, std::size_t i, double now, double sj_floor, double rise, double ratio_level) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), f = r.b[i];
  if (r.frame[i]) return r.mine[i] && f < rise ? nan : f >= sj_floor ? std::min(f, sj_floor + kFrameMargin) : f;
  const double level = r.mine[i] ? nan : f < now ? f : f < kHoldLevel ? nan : kHoldLevel;
  if (f < ratio_level || ratio_level <= now * (1 + 1e-6)) return level;  // rising, it stays above the floor
  const double guard = std::min(f, ratio_level + kFrameMargin);
  return std::isnan(level) ? guard : std::max(level, guard);
}

// Every row's level (row_level()); a cap row's: its coefficient may rise while the smallest of
// its hex's coefficients (held at its level, or at s >= now where it rises, or not changed by
// the patch) over it stays at or above the ratio floor. `ratios`: each hex's ratio bound when
// the move began.
std::vector<double> hold_levels(const Rows& rows, const std::vector<double>& ratios, double now, double sj_floor,
                                double rise, double ratio_floor, bool guarded) {
  std::vector<double> held(rows.b.size(), 0.0), least(ratios.size());
  for (std::size_t h = 0; h < ratios.size(); ++h) least[h] = kRatioWeight * ratios[h];
  for (std::size_t i = 0; i < rows.b.size(); ++i) {
    if (rows.cap[i]) continue;
    held[i] = row_level(rows, i, now, sj_floor, rise, guarded ? kRatioWeight * ratio_floor : kInfinite);
    if (!rows.frame[i]) {
      double& l = least[static_cast<std::size_t>(rows.hex[i])];
      l = std::min(l, std::isnan(held[i]) ? now : std::min(held[i], rows.b[i]));
    }
  }
  for (std::size_t i = 0; i < rows.b.size(); ++i)
    if (rows.cap[i])  // −b >= −least / floor; 2e-6 of room for the s·1e-6 of a held row
      held[i] = std::min(rows.b[i], -least[static_cast<std::size_t>(rows.hex[i])] / ratio_floor) - kRatioWeight * 1e-6;
  return held;
}

// The smallest of the hex's terms that rise, as the model `terms` chose them (its frames below
// `sj_floor`, its ratio terms), at their values in `values` (rows of the same hexes): a frame that
// the move takes over the floor still counts.
double lowest(const Rows& terms, const Rows& values, double rise) {
  double lo = 2.0;
  for (std::size_t i = 0; i < terms.b.size(); ++i)
    if (terms.mine[i] && (!terms.frame[i] || terms.b[i] < rise)) lo = std::min(lo, values.b[i]);
  return lo;
}

// The unknowns of the patch where it stands now (a sliding vertex's tangent plane moves with it).
void layout_at(const HexMesh& mesh, const Incidence& inc, const BoundarySurface* surface, Layout& L) {
  L.basis.clear(), L.dims.clear(), L.off.clear(), L.normal.clear(), L.len.clear();
  L.n = 0;
  for (Index v : L.verts) {
    std::array<Vec3, 3> e{Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
    Vec3 nrm = Vec3::Zero();
    int dim = 3;
    if (surface && surface->role(v) == BoundarySurface::Role::slides) {
      if (!surface->tangent_normal(v, mesh.points[v], nrm)) {
        dim = 0;  // no tangent plane: the vertex stays
      } else {
        e[0] = (std::abs(nrm.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(nrm).normalized();
        e[1] = nrm.cross(e[0]);
        dim = 2;
      }
    }
    L.basis.push_back(e), L.dims.push_back(dim), L.off.push_back(L.n), L.normal.push_back(nrm);
    L.len.push_back(mean_edge_at(mesh, inc, v));
    L.n += dim;
  }
}

// The LP's rows (a, b, w) from the model: only the rows that can bind within the box go in (a
// term that rises whose lowest value in it is below the target, which caps the bound; a held
// one that can fall below its level): the patch's good frames are most of the rows. The held
// rows are constraints: f_i − held_i >= s·1e-6, which is f_i >= held_i, nearly. The target
// itself closes the list.
void lp_rows(const Rows& rows, const std::vector<double>& held, const std::vector<double>& box, double target,
             std::vector<double>& a, std::vector<double>& b, std::vector<double>& w) {
  const std::size_t n = box.size();
  for (std::size_t i = 0; i < rows.b.size(); ++i) {
    double reach = 0;
    for (std::size_t j = 0; j < n; ++j) reach += box[j] * std::abs(rows.a[i * n + j]);
    const bool rises = std::isnan(held[i]);
    if (rows.b[i] - reach >= (rises ? target : held[i])) continue;
    a.insert(a.end(), rows.a.begin() + static_cast<std::ptrdiff_t>(i * n),
             rows.a.begin() + static_cast<std::ptrdiff_t>((i + 1) * n));
    b.push_back(rises ? rows.b[i] : rows.b[i] - held[i]);
    w.push_back(rises ? 1.0 : 1e-6);
  }
  a.resize(a.size() + n, 0.0);
  b.push_back(target);
  w.push_back(1.0);
}

// What a joint move reads of the patch as it began: its hexes, their norms, scaled Jacobians
// and ratio bounds, the move's own hexes, and the guards of move_vertex() over them.
struct PatchStart {
  std::vector<Index> hexes;
  std::vector<double> norms, sj0, ratios;
  std::vector<std::uint8_t> mine;
  Around before;
  double edge_cap = 0, ratio_floor = 0, sj_floor = 0, mine_ratio = 1;
};

PatchStart patch_start(const HexMesh& mesh, const Incidence& inc, const std::vector<Index>& targets, const Layout& L,
                       const WorstOptions& options, double mesh_min) {
  PatchStart ps;
  for (Index v : L.verts)
    for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) ps.hexes.push_back(inc.ids[k]);
  std::sort(ps.hexes.begin(), ps.hexes.end());
  ps.hexes.erase(std::unique(ps.hexes.begin(), ps.hexes.end()), ps.hexes.end());
  for (Index h : ps.hexes) ps.norms.push_back(bernstein_norm(mesh.corners(h)));
  ps.before = measure(mesh, ps.hexes, L, nullptr, nullptr, 0, &ps.sj0, &ps.ratios);
  ps.edge_cap = std::max(ps.before.max_edges, ps.before.min_ratio < kPoorJacobianRatio ? options.poor_ratio_edge_limit
                                                                                       : options.max_edge_ratio);
  ps.ratio_floor = std::min(ps.before.min_ratio, options.ratio_floor);
  ps.sj_floor = std::min(ps.before.min_sj, std::max(options.sj_floor, mesh_min));
  ps.mine.resize(ps.hexes.size());
  for (std::size_t i = 0; i < ps.hexes.size(); ++i) {
    ps.mine[i] = std::binary_search(targets.begin(), targets.end(), ps.hexes[i]);
    if (ps.mine[i]) ps.mine_ratio = std::min(ps.mine_ratio, ps.ratios[i]);
  }
  return ps;
}

// The patch moved by the LP's step `d` (sliding vertices put back on their surface) and judged
// on the true values: kept if no guard fails, the hex's terms that rise (`rows`, chosen with
// `rise`) rise above `now`, and no other term falls below its level (`held`) or below them.
// Otherwise every vertex goes back where it was. True if kept.
bool take_step(HexMesh& mesh, const PatchStart& ps, const Layout& L, const std::vector<double>& d, const Rows& rows,
               const std::vector<double>& held, const std::vector<std::uint8_t>& caps, double now, double rise,
               const std::vector<Vec3>& start, const WorstOptions& options) {
  const BoundarySurface* surface = options.surface;
  const std::vector<Index>& patch = L.verts;
  thread_local std::vector<Vec3> x;
  x.clear();
  for (Index v : patch) x.push_back(mesh.points[v]);
  bool placed = true;
  for (std::size_t s = 0; s < patch.size() && placed; ++s) {
    Vec3 y = x[s];
    for (int i = 0; i < L.dims[s]; ++i) y += d[static_cast<std::size_t>(L.off[s] + i)] * L.basis[s][i];
    if (surface && L.dims[s] > 0 && !surface->put_back(patch[s], y, L.normal[s], L.len[s])) placed = false;
    mesh.points[patch[s]] = y;
  }
  bool ok = false;
  if (placed) {
    const Around after = measure(mesh, ps.hexes, L, &ps.sj0, &start, options.min_edge_shrink);
    ok = after.valid && after.below <= ps.before.below && after.min_sj >= ps.sj_floor &&
         after.min_ratio >= ps.ratio_floor && after.max_edges <= ps.edge_cap;
    if (ok) {
      // The caps are the ratio bound's, checked above on the true values.
      thread_local Rows y;
      patch_rows(mesh, ps.hexes, ps.norms, ps.mine, caps, L, y);
      ok = y.b.size() == rows.b.size();
      const double raised = ok ? lowest(rows, y, rise) : now;
      ok = ok && raised > now + 1e-9;
      for (std::size_t i = 0; ok && i < y.b.size(); ++i)
        if (!rows.cap[i] && y.b[i] < (std::isnan(held[i]) ? raised : std::min(held[i], raised))) ok = false;
    }
  }
  if (!ok)
    for (std::size_t s = 0; s < patch.size(); ++s) mesh.points[patch[s]] = x[s];
  return ok;
}

}  // namespace

bool move_patch(HexMesh& mesh, const Incidence& inc, const std::vector<Index>& targets, const std::vector<Index>& patch,
                const std::vector<Vec3>& start, const WorstOptions& options, double mesh_min, PatchModels models) {
  if (patch.empty()) return false;
  Layout L;
  L.verts = patch;
  const PatchStart ps = patch_start(mesh, inc, targets, L, options, mesh_min);
  // One model's moves (up to options.models, each rebuilt where the last gained); `unless_plain`:
  // none where its first model is the plain one's (whose moves the caller saw gain nothing).
  const auto attempt = [&](bool guarded, bool unless_plain) {
    // The hexes' own frames below this rise; one at the patch's minimum too (were it held at
    // the floor, the LP would raise the hex's ratio terms instead).
    const double rise = guarded ? std::max(ps.sj_floor, options.sj_floor) : ps.sj_floor;
    // The other hexes near the ratio floor hold their largest coefficients down (caps), where
    // the floor is not the targets' own ratio (then their ratio terms rise, the others' with
    // them): the caps are the stricter the more a hex's smallest may fall, and blocked the
    // bone's joint moves (tests/data/bone_cluster.txt) when they held every hex within twice
    // the floor.
    std::vector<std::uint8_t> caps(ps.hexes.size());
    bool capped = false;
    for (std::size_t i = 0; i < ps.hexes.size(); ++i) {
      caps[i] = guarded && !ps.mine[i] && ps.ratios[i] < 1.25 * ps.ratio_floor &&
                ps.ratio_floor < ps.mine_ratio * (1 - 1e-6);
      capped = capped || caps[i];
    }
    bool moved = false;
    double scale = options.step;
    for (int model = 0; model < options.models; ++model) {
      layout_at(mesh, inc, options.surface, L);
      if (L.n == 0) break;
      thread_local Rows rows;
      patch_rows(mesh, ps.hexes, ps.norms, ps.mine, caps, L, rows);
      const double now = lowest(rows, rows, rise);
      if (!(now < options.target)) break;
      const std::vector<double> held = hold_levels(rows, ps.ratios, now, ps.sj_floor, rise, ps.ratio_floor, guarded);
      // Without caps, with the same rising frames and every row held at the same level, the
      // LPs, steps and checks are the plain model's: the same failure (the demo's patches:
      // half of the joint moves' LP pivots were such repeats).
      if (model == 0 && unless_plain && !capped && rise == ps.sj_floor &&
          std::equal(held.begin(), held.end(),
                     hold_levels(rows, ps.ratios, now, ps.sj_floor, ps.sj_floor, ps.ratio_floor, false).begin(),
                     [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); }))
        break;
      bool gained = false;
      for (int trial = 0; trial < options.trials && !gained; ++trial, scale *= 0.5) {
        std::vector<double> box(static_cast<std::size_t>(L.n));
        for (std::size_t s = 0; s < patch.size(); ++s)
          for (int i = 0; i < L.dims[s]; ++i) box[static_cast<std::size_t>(L.off[s] + i)] = scale * L.len[s];
        thread_local std::vector<double> a, b, w;  // as the rows' storage
        a.clear(), b.clear(), w.clear();
        lp_rows(rows, held, box, options.target, a, b, w);
        const MaxMinN r = max_min_affine(L.n, a, b, w, box);
        if (!r.ok || !(r.s > now + 1e-9)) break;  // no ascent even in the model
        gained = take_step(mesh, ps, L, r.d, rows, held, caps, now, rise, start, options);
      }
      if (!gained) break;
      moved = true;
      scale = std::min(4 * scale, options.step);  // the box that worked, doubled (the loop halved it once more)
    }
    return moved;  // a step not taken was undone: without a gain the patch is where it was
  };
  switch (models) {
    case PatchModels::plain: return attempt(false, false);
    case PatchModels::guarded: return attempt(true, false);
    case PatchModels::both: return attempt(false, false) || attempt(true, true);
  }
  return false;
}

}  // namespace isohex::opt
