// Frames, per-frame energies with exact derivatives, per-vertex Newton moves, sweeps.
#include "isohex/optimize/local_energy.hpp"

#include "isohex/optimize/frame_terms.hpp"

#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace isohex::opt {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ∇N_k at (u, v, w): the coefficient of corner k in the Jacobian matrix there.
Vec3 shape_gradient(int k, double u, double v, double w) {
  const bool x = k == 1 || k == 2 || k == 5 || k == 6, y = k == 2 || k == 3 || k == 6 || k == 7, z = k >= 4;
  const double fu = x ? u : 1 - u, fv = y ? v : 1 - v, fw = z ? w : 1 - w;
  return Vec3((x ? 1 : -1) * fv * fw, (y ? 1 : -1) * fu * fw, (z ? 1 : -1) * fu * fv);
}

// The parameters of the interior frames 9..34: Gauss points, edge midpoints, face centres.
std::array<Vec3, kAllFrames - kFrames> interior_points() {
  std::array<Vec3, kAllFrames - kFrames> q;
  const double g = 0.21132486540518711775;  // (1 − 1/√3)/2
  int n = 0;
  for (int c = 0; c < 8; ++c) q[n++] = Vec3(c & 1 ? 1 - g : g, c & 2 ? 1 - g : g, c & 4 ? 1 - g : g);
  for (int a = 0; a < 3; ++a)  // edges along axis a
    for (int c = 0; c < 4; ++c) {
      Vec3 x;
      x[a] = 0.5;
      x[(a + 1) % 3] = c & 1;
      x[(a + 2) % 3] = (c >> 1) & 1;
      q[n++] = x;
    }
  for (int a = 0; a < 3; ++a)  // faces normal to axis a
    for (int side = 0; side < 2; ++side) {
      Vec3 x(0.5, 0.5, 0.5);
      x[a] = side;
      q[n++] = x;
    }
  return q;
}

// c_{t,k} for the 8 corner frames, the centre frame (principal axes / 4) and the interior ones.
std::array<std::array<Vec3, 8>, kAllFrames> make_coefficients() {
  std::array<std::array<Vec3, 8>, kAllFrames> c;
  for (auto& row : c) row.fill(Vec3::Zero());
  for (int t = 0; t < 8; ++t) {
    c[t][t] = Vec3(-1, -1, -1);
    for (int j = 0; j < 3; ++j) c[t][kCornerNeighbors[t][j]][j] = 1;
  }
  for (int k = 0; k < 8; ++k) {
    const bool x = k == 1 || k == 2 || k == 5 || k == 6;
    const bool y = k == 2 || k == 3 || k == 6 || k == 7;
    const bool z = k >= 4;
    c[kCentreFrame][k] = 0.25 * Vec3(x ? 1 : -1, y ? 1 : -1, z ? 1 : -1);
  }
  const auto q = interior_points();
  for (int t = kFrames; t < kAllFrames; ++t)
    for (int k = 0; k < 8; ++k) c[t][k] = shape_gradient(k, q[t - kFrames][0], q[t - kFrames][1], q[t - kFrames][2]);
  return c;
}
const std::array<std::array<Vec3, 8>, kAllFrames> kCoef = make_coefficients();

// The nonzero entries of each frame's coefficients, in corner order: an interior frame's
// corners mostly enter only some of its columns (an edge midpoint's frame uses 10 of the 24),
// and a zero product adds nothing to a sum that starts at +0 (which never becomes -0), so
// interior_frame() skips them with the same bits (it was a fifth of the worst pass's
// instructions, through the ratio terms' 27 lattice frames per hex).
struct CoefEntry {
  std::uint8_t k, j;
  double c;
};
const std::array<std::vector<CoefEntry>, kAllFrames> kCoefEntries = [] {
  std::array<std::vector<CoefEntry>, kAllFrames> e;
  for (int t = 0; t < kAllFrames; ++t)
    for (int k = 0; k < 8; ++k)
      for (int j = 0; j < 3; ++j)
        if (kCoef[t][k][j] != 0)
          e[t].push_back({static_cast<std::uint8_t>(k), static_cast<std::uint8_t>(j), kCoef[t][k][j]});
  return e;
}();

// One frame's energy: the untangler's, the shape term, or for the shape stage's centre and
// interior frames a constraint (validity), not optimised.
[[gnu::always_inline]] inline double term_value(const Mat3& A, int t, const EnergyParams& params, double eps) {
  const double F = A.squaredNorm(), D = A.determinant();
  if (params.untangle) return untangle_term(F, D, eps, params.lambda).f;
  if (t >= kCentreFrame) return D > kMinFeasibleDet ? 0.0 : kInf;
  return shape_term(F, D).f;
}

// The Bernstein coefficients of det J of the hex p (at the frames' scale inv_len³) that are
// not corner values (those are frames already), as the energy's extra terms: each coefficient
// is affine in one vertex's place (every lattice determinant is, by the matrix determinant
// lemma, and the coefficients are fixed combinations of them), so its term's Hessian is
// f''(b) ∇b ∇bᵀ. With `g`, the gradient and Hessian in corner k's place are added.
double bernstein_energy(const std::array<Vec3, 8>& p, int k, double inv_len, const EnergyParams& params, double eps,
                        Vec3* g, Mat3* H, TermModels* model = nullptr);

}  // namespace

const Vec3& frame_coefficient(int t, int k) { return kCoef[t][k]; }

Vec3 frame_point(int t) {
  if (t < 8) return Vec3(t == 1 || t == 2 || t == 5 || t == 6, t == 2 || t == 3 || t == 6 || t == 7, t >= 4);
  if (t == kCentreFrame) return Vec3(0.5, 0.5, 0.5);
  static const auto q = interior_points();
  return q[static_cast<std::size_t>(t - kFrames)];
}

const std::array<int, 27>& lattice_frames() {
  static const std::array<int, 27> map = [] {
    std::array<int, 27> m;
    m.fill(-1);
    for (int t = 0; t < kAllFrames; ++t) {
      const Vec3 x = 2 * frame_point(t);
      const Vec3 r = x.array().round();
      if ((x - r).norm() == 0) m[static_cast<std::size_t>(r[0] + 3 * r[1] + 9 * r[2])] = t;  // the Gauss points are not on it
    }
    return m;
  }();
  return map;
}

namespace {

double bernstein_energy(const std::array<Vec3, 8>& p, int k, double inv_len, const EnergyParams& params, double eps,
                        Vec3* g, Mat3* H, TermModels* model) {
  const std::array<int, 27>& lattice = lattice_frames();
  std::array<double, 27> b, gx, gy, gz;  // values and gradients, transformed alike
  InteriorFrames interior;
  interior_frames(relative_corners(p), inv_len, interior, false);
  for (int n = 0; n < 27; ++n) {
    const int t = lattice[static_cast<std::size_t>(n)];
    const Mat3 A = t > kCentreFrame ? interior[static_cast<std::size_t>(t - kFrames)] : frame(p, t, inv_len);
    b[n] = A.determinant();
    if (!g) continue;
    const Vec3& c = kCoef[t][k];
    const Vec3 gD = inv_len * (c[0] * A.col(1).cross(A.col(2)) + c[1] * A.col(2).cross(A.col(0)) +
                               c[2] * A.col(0).cross(A.col(1)));
    gx[n] = gD[0], gy[n] = gD[1], gz[n] = gD[2];
  }
  lattice_to_bernstein(b);
  if (g) lattice_to_bernstein(gx), lattice_to_bernstein(gy), lattice_to_bernstein(gz);
  // ε floored: a coefficient barely below 0 with ε of its size would give a term ~ 1/|b|
  // (the energy grew to 1e20 on a knot that cannot be undone); 1e-3 of a unit cube's det J
  // still presses a negative coefficient with a gradient of ~1e6.
  eps = std::max(eps, 1e-3);
  double e = 0;
  for (int n = 0; n < 27; ++n) {
    if (n == 0 || n == 2 || n == 6 || n == 8 || n == 18 || n == 20 || n == 24 || n == 26) continue;  // corners
    const TermValue<double> s = untangle_term(0.0, b[n], eps, params.lambda);
    e += s.f;
    if (!g) continue;
    const Vec3 gb(gx[n], gy[n], gz[n]);
    if (model) model->push(0, b[n], 0, eps, Vec3::Zero(), gb, false);
    *g += s.fD * gb;
    if (H) *H += s.fDD * (gb * gb.transpose());
  }
  return e;
}

}  // namespace

std::vector<double> inverse_edge_lengths(const HexMesh& mesh) {
  std::vector<double> inv(mesh.hexes.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.hexes.size()), [&](const auto& r) {
    for (std::size_t h = r.begin(); h != r.end(); ++h) {
      double sum = 0;
      for (const auto& e : kHexEdges) sum += (mesh.points[mesh.hexes[h][e[0]]] - mesh.points[mesh.hexes[h][e[1]]]).norm();
      // A fully collapsed hex has no size of its own: 1 keeps the arithmetic finite.
      inv[h] = sum > 0 ? 12.0 / sum : 1.0;
    }
  });
  return inv;
}

RelativeCorners relative_corners(const std::array<Vec3, 8>& p) {
  RelativeCorners d;
  for (int k = 0; k < 8; ++k)
    for (int i = 0; i < 3; ++i) d[k][i] = p[k][i] - p[0][i];
  return d;
}

Mat3 interior_frame(const std::array<Vec3, 8>& p, int t, double inv_len) {
  // Σ_k (P_k − P_0) c_{t,k}ᵀ (Σ c_k = 0: relative to P0), entry by entry in k order, then
  // scaled: the arithmetic of the matrix expression `A += (P_k − P_0) c_kᵀ`, whose
  // temporaries on the stack stalled every load (most of frame()'s samples on cthead).
  // (interior_frames() gives all of a hex's at once, the same bits.)
  const RelativeCorners d = relative_corners(p);
  double a[3][3] = {};
  for (const CoefEntry& e : kCoefEntries[static_cast<std::size_t>(t)])
    for (int i = 0; i < 3; ++i) a[i][e.j] += d[e.k][i] * e.c;
  Mat3 A;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) A(i, j) = a[i][j] * inv_len;
  return A;
}

double hex_energy(const std::array<Vec3, 8>& p, double inv_len, const EnergyParams& params, double eps, int frames) {
  if (eps < 0) eps = params.eps;
  double e = 0;
  for (int t = 0; t < frames; ++t) e += term_value(frame(p, t, inv_len), t, params, eps);
  return e;
}

double hex_energy(const std::array<Vec3, 8>& p, Index h, double inv_len, const EnergyParams& params) {
  if (!params.untangle && params.frames_of(h) == kFrames && !params.bernstein_of(h)) {
    // The shape objective's hex (every hex of the shape stage): its corner terms four at a
    // time, then the centre frame's constraint, as the loop below adds them.
    const double e = corner_shape_energy(p, inv_len);
    return e + term_value(frame(p, kCentreFrame, inv_len), kCentreFrame, params, params.eps);
  }
  const double eps = params.eps_of(h);
  double e = hex_energy(p, inv_len, params, eps, params.frames_of(h));
  if (params.bernstein_of(h)) e += bernstein_energy(p, 0, inv_len, params, eps, nullptr, nullptr);
  return e;
}

bool hex_feasible(const std::array<Vec3, 8>& p, double inv_len) {
  for (int t = 0; t < kFrames; ++t)
    if (!(frame(p, t, inv_len).determinant() > kMinFeasibleDet)) return false;
  return certified_valid(p, kMinFeasibleDet / (inv_len * inv_len * inv_len));
}

bool stays_feasible(const HexMesh& mesh, const Incidence& inc, const std::vector<double>& inv_len, Index v,
                    const Vec3& x, const std::vector<std::uint8_t>* skip, const std::vector<double>* ratio_floor,
                    const std::vector<double>* rank_floor, std::vector<double>* ratios) {
  if (ratios) ratios->clear();
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) {
    const Index h = inc.ids[i];
    if (skip && (*skip)[h]) continue;
    const std::array<Vec3, 8> p = corners_with(mesh, h, v, x);
    const auto at = static_cast<std::size_t>(i - inc.offsets[v]);
    // Only the certificate: a finite shape energy has checked the frames v changes already,
    // and the others are those of a hex that was feasible.
    const double floor = kMinFeasibleDet / (inv_len[h] * inv_len[h] * inv_len[h]);
    if (rank_floor) {  // both from one evaluation of the coefficients
      const CertifiedQuality c = certified_quality(p);
      if (hex_rank(c) < (*rank_floor)[at] || (ratio_floor && c.ratio_bound < (*ratio_floor)[at])) return false;
    }
    double ratio = 0;
    const bool ok = certified_valid_above_ratio(p, floor, !rank_floor && ratio_floor ? (*ratio_floor)[at] : -kInf,
                                                ratios ? &ratio : nullptr);
    if (ratios) ratios->push_back(ratio);
    if (!ok) return false;
  }
  return true;
}

namespace {

// |c_{t,k}|² as Eigen gives it, and whether frame t sees corner k at all (a zero coefficient:
// its term is a constant of the vertex's place).
const std::array<std::array<double, 8>, kAllFrames> kCoefSq = [] {
  std::array<std::array<double, 8>, kAllFrames> sq;
  for (int t = 0; t < kAllFrames; ++t)
    for (int k = 0; k < 8; ++k) sq[t][k] = kCoef[t][k].squaredNorm();
  return sq;
}();

// The hexes of one vertex_energy() call, in incidence order, with their frames' range in the batch.
struct HexFrames {
  Index h;
  int k;
  double il, eps;
  std::size_t first, last;
  bool bernstein;  // the hex also counts det J's Bernstein coefficients
};

// A frame's field in the batch (f: its first field; a block's lanes make the stride 4).
[[gnu::always_inline]] inline double& field_of(double* f, int field) { return f[4 * field]; }
[[gnu::always_inline]] inline double field_of(const double* f, int field) { return f[4 * field]; }

// Appends to `batch` the frames of hex hf (corners p, the vertex at corner hf.k) that see the
// vertex: the others' terms are constants of its place.
[[gnu::always_inline]] inline void add_frames(const std::array<Vec3, 8>& p, const HexFrames& hf, int frames,
                                              bool untangle, FrameBatch& batch) {
  const int k = hf.k;
  InteriorFrames interior;  // the hex's 26 interior frames, at once
  if (frames > kFrames) interior_frames(relative_corners(p), hf.il, interior);
  for (int t = 0; t < frames; ++t) {
    const Vec3& c = kCoef[t][k];
    if (c.isZero()) continue;
    // The frame's fields, four apart (its lane of a block): one address, not one per field.
    double* f = &batch.at(batch.add(), 0);
    if (t < 8) {  // corner_frame()'s entries, written in place
      const auto& nb = kCornerNeighbors[static_cast<std::size_t>(t)];
      for (int col = 0; col < 3; ++col)
        for (int r = 0; r < 3; ++r) field_of(f, FrameBatch::kA + r + 3 * col) = (p[nb[col]][r] - p[t][r]) * hf.il;
    } else {
      const Mat3 A = t == kCentreFrame ? frame(p, t, hf.il) : interior[static_cast<std::size_t>(t - kFrames)];
      for (int e = 0; e < 9; ++e) field_of(f, FrameBatch::kA + e) = A.data()[e];
    }
    for (int r = 0; r < 3; ++r) field_of(f, FrameBatch::kC + r) = c[r];
    field_of(f, FrameBatch::kIl) = hf.il, field_of(f, FrameBatch::kSq) = kCoefSq[t][k];
    field_of(f, FrameBatch::kEps) = hf.eps;
    field_of(f, FrameBatch::kConstraint) = !untangle && t >= kCentreFrame;
  }
}

// g and H (its lower triangle, all the eigensolver reads) summed frame by frame in locals:
// through the caller's pointers every add was a load and a store (they might alias the
// batch). The same additions in the same order; stored before a Bernstein term adds to the
// caller's and loaded back after.
struct Derivatives {
  Vec3 g = Vec3::Zero();
  double h[3][3] = {};
  // A frame's gradient and Hessian terms (f: its fields, four apart).
  void add(const double* f, bool hessian) {
    for (int i = 0; i < 3; ++i) g[i] += field_of(f, FrameBatch::kGrad + i);
    if (!hessian) return;
    const double id = field_of(f, FrameBatch::kIdentity);
    int n = FrameBatch::kHessian;
    for (int c = 0; c < 3; ++c) {
      h[c][c] += id;
      for (int r = c; r < 3; ++r) h[r][c] += field_of(f, n++);
    }
  }
  void store(Vec3* gp, Mat3* Hp) const {
    if (gp) *gp = g;
    if (Hp)
      for (int c = 0; c < 3; ++c)
        for (int r = c; r < 3; ++r) (*Hp)(r, c) = h[r][c];
  }
  void load(const Vec3* gp, const Mat3* Hp) {
    if (gp) g = *gp;
    if (Hp)
      for (int c = 0; c < 3; ++c)
        for (int r = c; r < 3; ++r) h[r][c] = (*Hp)(r, c);
  }
};

}  // namespace

double vertex_energy(const HexMesh& mesh, const Incidence& inc, const std::vector<double>& inv_len, Index v,
                     const Vec3& x, const EnergyParams& params, Vec3* g, Mat3* H, TermModels* model) {
  if (!g) model = nullptr;
  if (model) model->clear(params.untangle);
  if (g) g->setZero();
  if (H) H->setZero();
  // Per-thread buffers: a move runs to its end on its thread.
  thread_local FrameBatch batch;
  thread_local std::vector<HexFrames> hexes;
  batch.clear();
  hexes.clear();
  bool bernstein = false;
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) {
    const Index h = inc.ids[i];
    if (params.skip && (*params.skip)[h]) continue;
    std::array<Vec3, 8> p = mesh.corners(h);
    int k = 0;
    while (mesh.hexes[h][k] != v) ++k;
    p[k] = x;
    // Filled in place: a HexFrames built on the stack and copied in stalled the loads of the
    // copy on the stores just made (5-10 % of this function's time on ECR block_in).
    HexFrames& hf = hexes.emplace_back();
    hf.h = h, hf.k = k, hf.il = inv_len[h], hf.eps = params.eps_of(h), hf.first = batch.size;
    hf.bernstein = params.bernstein_of(h);
    add_frames(p, hf, params.frames_of(h), params.untangle, batch);
    hf.last = batch.size;
    bernstein = bernstein || hf.bernstein;
  }
  batch.compute(params.untangle, params.lambda);
  // The sums in frame order, hex by hex (a hex's Bernstein terms after its frames): those of
  // one frame at a time, bit for bit. H: its lower triangle (all the eigensolver reads), then
  // mirrored.
  double e = 0;
  Derivatives sums;
  for (const HexFrames& hf : hexes) {
    for (std::size_t j = hf.first; j < hf.last; ++j) {
      const double* f = &batch.at(j, 0);
      // The shape stage's centre and interior frames only constrain: no derivatives.
      const bool constraint = field_of(f, FrameBatch::kConstraint) != 0;
      const double D = field_of(f, FrameBatch::kD);
      e += constraint ? (D > kMinFeasibleDet ? 0.0 : kInf) : field_of(f, FrameBatch::kValue);
      if (!std::isfinite(e)) return kInf;
      if (!g) continue;
      if (model && bernstein)  // terms to interleave: copied one by one
        model->push(field_of(f, FrameBatch::kF), D, field_of(f, FrameBatch::kCc), hf.eps,
                    Vec3(field_of(f, FrameBatch::kGF), field_of(f, FrameBatch::kGF + 1),
                         field_of(f, FrameBatch::kGF + 2)),
                    Vec3(field_of(f, FrameBatch::kGD), field_of(f, FrameBatch::kGD + 1),
                         field_of(f, FrameBatch::kGD + 2)),
                    constraint);
      if (!constraint) sums.add(f, H != nullptr);
    }
    if (hf.bernstein) {
      std::array<Vec3, 8> p = mesh.corners(hf.h);
      p[hf.k] = x;
      sums.store(g, H);
      e += bernstein_energy(p, hf.k, hf.il, params, hf.eps, g, H, model);
      sums.load(g, H);
      if (!std::isfinite(e)) return kInf;
    }
  }
  sums.store(g, H);
  if (H)
    for (int c = 0; c < 3; ++c)
      for (int r = c + 1; r < 3; ++r) (*H)(c, r) = (*H)(r, c);
  if (model) {
    if (!bernstein) std::swap(model->terms, batch);  // the frames are the terms, in order
    model->seal();
  }
  return e;
}

Move newton_move(const HexMesh& mesh, const Incidence& inc, const std::vector<double>& inv_len, Index v,
                 const EnergyParams& params) {
  Move m{mesh.points[v], 0, false, 0};
  Vec3 g;
  Mat3 H;
  thread_local TermModels model;  // the trials' energy (a buffer per thread, as below)
  const double e0 = vertex_energy(mesh, inc, inv_len, v, m.x, params, &g, &H, &model);
  if (!std::isfinite(e0) || inc.count(v) == 0) return m;
  const double len = vertex_length(inc, inv_len, v);
  m.grad = g.norm() * len;
  if (!(m.grad > 0)) return m;
  // Newton direction on the Hessian with its eigenvalues clamped positive (the regularised
  // energy is not convex); a curvature floor from the gradient scale keeps the step bounded.
  // Closed form for 3×3 (several times cheaper than the iterative solver; same bits on every run).
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(H);
  Vec3 lam = es.eigenvalues();
  const double floor = std::max(1e-6 * lam.cwiseAbs().maxCoeff(), 1e-3 * g.norm() / len);
  for (int i = 0; i < 3; ++i) lam[i] = std::max(lam[i], floor);
  Vec3 d = -(es.eigenvectors() * (es.eigenvectors().transpose() * g).cwiseQuotient(lam));
  // A sliding boundary vertex steps in the tangent plane of the target surface (the original
  // boundary or an isosurface) where it is and is put back on that surface (on the same side:
  // the facing test), so the energy is compared at points of the surface only. A step that
  // cannot be put back is refused.
  // (A loose vertex steps freely and is clamped back into the band about its surface.)
  const bool slides = params.surface && params.surface->role(v) == BoundarySurface::Role::slides;
  Vec3 n = Vec3::Zero();
  if (slides) {
    if (!params.surface->tangent_normal(v, m.x, n)) return m;
    d -= n * n.dot(d);
  }
  const double dn = d.norm();
  if (!(dn > 0)) return m;
  if (dn > len) d *= len / dn;  // never jump further than an edge in one step
  const double slope = g.dot(d);
  // The shape stage's mean objective may trade one hex's interior for the others: no step
  // takes a hex's ratio bound from kShapeRatioFloor or above to below it. (Holding the poor
  // hexes where they are too held the first stage back: the MR head's mean inverse mean ratio
  // ended at 1.89 instead of 1.56, and 14 hexes below 0.2 were left instead of 4.)
  // With a rank guard (the band rounds), no hex's rank falls below the lower of its rank now
  // and the guard: the rounds' shape stage took cthead's bone (iso 1200, h 5) from 0.124 to
  // 0.093 and the worst pass won back less each round.
  const bool guarded = !params.untangle && params.rank_guard > -kInf;
  // The search gives up where no step can matter: a step shorter than 1e-6 of an edge, and in
  // the shape stage a predicted decrease below 1e-12 of the vertex's energy. Converged vertices
  // and blocked ones had gone through all 30 halvings: 4 % of cthead h 4's shape moves, half of
  // the stage's line-search evaluations; in cthead h 2's first untangler 81 % of the first
  // iteration's evaluations (99,000 searches), 9.5 M evaluations in all against 4.0 M with the
  // shortest step. The relative test is not the untangler's: a vertex next to a stuck hex has
  // an energy dominated by that hex's frozen terms, and held to a decrease relative to it, such
  // vertices stopped helping their other hexes (headsq iso 1000 h 2.5 left the untangler with
  // a mean ratio objective of 2.4 instead of 1.4, and the shape stage ran 100 sweeps).
  if (!params.untangle && !(-slope > 1e-12 * std::abs(e0))) return m;  // before the floors: they cost certificates
  const double shortest = 1e-6 * len;
  // The ratio bounds kept per hex (EnergyParams::hex_ratio) save a certificate's coefficients
  // per hex and move: a move's floors read them, its accepted step writes those it computed.
  std::vector<double>* cache = !params.untangle && !guarded && !params.skip ? params.hex_ratio : nullptr;
  // Per-thread buffers: a move runs to its end on its thread, and three vectors allocated per
  // move were a malloc and a free each in the innermost loop of every sweep.
  thread_local std::vector<double> ratio_floor, rank_floor, ratios;
  ratio_floor.clear(), rank_floor.clear(), ratios.clear();
  if (!params.untangle)
    for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) {
      const Index h = inc.ids[i];
      // The scaled Jacobian and its certificate only where the guard needs them.
      const CertifiedQuality c = guarded ? certified_quality(mesh.corners(h))
                                         : CertifiedQuality{0, cache ? (*cache)[static_cast<std::size_t>(h)]
                                                                     : jacobian_ratio_bound(mesh.corners(h))};
      ratio_floor.push_back(c.ratio_bound >= kShapeRatioFloor ? kShapeRatioFloor : -kInf);
      if (guarded) rank_floor.push_back(std::min(hex_rank(c), params.rank_guard));
    }
  double t = 1;
  for (int i = 0; i < 30 && t * dn >= shortest; ++i, t *= 0.5) {
    Vec3 x = m.x + t * d;
    if (params.surface && !params.surface->put_back(v, x, n, len)) continue;
    const double e = model_energy(model, x - m.x, params.lambda);
    ++m.trials;
    // The shape stage's barrier sees the 9 frames only: a step must also keep every hex
    // around v certified valid inside (hex_feasible()), or a fold could open between them.
    if (e < e0 && e <= e0 + 1e-4 * t * slope &&
        (params.untangle || stays_feasible(mesh, inc, inv_len, v, x, params.skip, &ratio_floor,
                                           guarded ? &rank_floor : nullptr, cache ? &ratios : nullptr))) {
      m.x = x;
      m.moved = true;
      if (cache)
        for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i)
          (*cache)[static_cast<std::size_t>(inc.ids[i])] = ratios[static_cast<std::size_t>(i - inc.offsets[v])];
      break;
    }
  }
  return m;
}

void hex_energies(const HexMesh& mesh, const std::vector<double>& inv_len, const EnergyParams& params,
                  const std::vector<std::uint8_t>& skip, std::vector<double>& e, const std::vector<std::uint8_t>* only) {
  e.resize(mesh.hexes.size(), 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.hexes.size()), [&](const auto& r) {
    for (std::size_t h = r.begin(); h != r.end(); ++h) {
      if (only && !(*only)[h]) continue;
      e[h] = !skip.empty() && skip[h]
                 ? 0.0
                 : hex_energy(mesh.corners(static_cast<Index>(h)), static_cast<Index>(h), inv_len[h], params);
    }
  });
}

double energy_sum(const std::vector<double>& e) {
  double sum = 0;
  for (double x : e) sum += x;  // in hex order: the same bits for any thread count
  return sum;
}

double total_energy(const HexMesh& mesh, const std::vector<double>& inv_len, const EnergyParams& params,
                    const std::vector<std::uint8_t>& skip) {
  std::vector<double> e;
  hex_energies(mesh, inv_len, params, skip, e);
  return energy_sum(e);
}

double sweep(HexMesh& mesh, const VertexColoring& coloring, const Incidence& inc, const std::vector<double>& inv_len,
             const EnergyParams& params, const std::vector<std::uint8_t>& frozen, int steps, MoveRecord* record) {
  double max_grad = 0;
  std::vector<double> grad;
  std::vector<Index> moving;
  for (const std::vector<Index>& color : coloring.colors) {
    // The colour's vertices that may move, listed first: late in a stage most are frozen, and
    // the parallel loop's tasks over the whole colour cost more than the moves (the untangler's
    // last iterations move 8,000 of cthead h 2's 634,000 vertices).
    const std::vector<Index>* list = &color;
    if (!frozen.empty()) {
      moving.clear();
      for (Index v : color)
        if (!frozen[v]) moving.push_back(v);
      list = &moving;
    }
    grad.assign(list->size(), 0.0);
    // Vertices of one colour share no hex: each move reads only vertices of other colours,
    // so moving them concurrently gives the same result as any sequential order.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, list->size(), 16), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        const Index v = (*list)[i];
        const Vec3 x0 = mesh.points[v];
        for (int s = 0; s < steps; ++s) {
          const Move m = newton_move(mesh, inc, inv_len, v, params);
          if (s == 0) grad[i] = m.grad;
          if (!m.moved) break;
          mesh.points[v] = m.x;
        }
        if (record && mesh.points[v] != x0) {
          const std::uint8_t far = (mesh.points[v] - x0).norm() > record->cull * (*record->scale)[v] ? 2 : 1;
          record->moved[v] = std::max(record->moved[v], far);
        }
      }
    });
    for (double x : grad) max_grad = std::max(max_grad, x);
  }
  return max_grad;
}

SJStats sj_stats_of(const std::vector<double>& sj, const std::vector<std::uint8_t>* skip) {
  SJStats s;
  s.min = 1.0;  // the scaled Jacobian's largest value: also the answer for no hexes
  for (std::size_t h = 0; h < sj.size(); ++h) {
    if (skip && (*skip)[h]) continue;
    double v = sj[h];
    if (is_degenerate(v)) v = -1;  // a collapsed edge is as bad as an inverted corner
    s.min = std::min(s.min, v);
    s.inverted += v <= 0;
  }
  return s;
}

SJStats sj_stats(const HexMesh& mesh, const std::vector<std::uint8_t>* skip) {
  return sj_stats_of(certified_scaled_jacobians(mesh), skip);
}

void update_certified_sj(const HexMesh& mesh, const std::vector<std::uint8_t>& only, std::vector<double>& sj) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.hexes.size(), 1024), [&](const auto& r) {
    for (std::size_t h = r.begin(); h != r.end(); ++h)
      if (only[h]) sj[h] = certified_scaled_jacobian(mesh.corners(static_cast<Index>(h)));
  });
}

void mark_far_moves(const HexMesh& mesh, const Incidence& inc, const MoveRecord& record, std::vector<std::uint8_t>& near,
                    std::vector<std::uint8_t>* changed) {
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    if (record.moved[v] == 0) continue;
    for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) {
      if (changed) (*changed)[inc.ids[i]] = 1;
      if (record.moved[v] == 2)
        for (Index w : mesh.hexes[inc.ids[i]]) near[w] = 1;
    }
  }
}

}  // namespace isohex::opt
