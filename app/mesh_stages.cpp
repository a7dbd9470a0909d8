#include "mesh_stages.hpp"

#include "isohex/contour/dual_contour.hpp"
#include "isohex/contour/refine_boundary.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"
#include "isohex/quality/report.hpp"
#include "isohex/sheets/pillow.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <sys/resource.h>

namespace isohex::cli {

StageRow stage_row(const std::string& name, const HexMesh& mesh, double seconds, bool keep_values) {
  StageRow r{name, mesh.num_hexes(), mesh.num_vertices(), scaled_jacobians(mesh), {}, seconds, nlohmann::json::object()};
  r.sj = summarize(HexMetric::scaled_jacobian, r.sj_values, 0);
  if (!keep_values) std::vector<double>().swap(r.sj_values);
  return r;
}

nlohmann::json pillow_stage(HexMesh& mesh, std::vector<std::int8_t>& vertex_place, const Aabb& domain, bool terminal) {
  if (terminal) fmt::print("  pillowing...\n"), std::fflush(stdout);
  PillowOptions po;
  po.domain_lo = domain.lo;
  po.domain_hi = domain.hi;
  PillowResult p = pillow_boundary(mesh, -1, po);
  fmt::print("pillowing: {} new hexes (one per boundary quad), {} new vertices ({} clamped into the domain), min SJ "
             "of the new hexes {:.4g}\n",
             p.interface_quads, p.mesh.num_vertices() - mesh.num_vertices(), p.clamped_vertices, p.min_new_scaled_jacobian);
  // Old vertices keep their ids (the boundary among them); the copies are interior.
  vertex_place.resize(static_cast<std::size_t>(p.mesh.num_vertices()), contour::kInteriorVertex);
  nlohmann::json j = {{"new_hexes", p.interface_quads},
                      {"new_vertices", p.mesh.num_vertices() - mesh.num_vertices()},
                      {"pinch_copies", p.pinch_copies},
                      {"clamped_vertices", p.clamped_vertices},
                      {"min_new_sj", p.min_new_scaled_jacobian}};
  mesh = std::move(p.mesh);
  return j;
}

nlohmann::json refine_stage(const contour::Region& region, contour::ExtractResult& extracted, double tolerance,
                            int levels, bool terminal, double& seconds) {
  if (terminal) fmt::print("  boundary refinement...\n"), std::fflush(stdout);
  contour::BoundaryRefineOptions ro;
  ro.chord_tolerance = tolerance;
  ro.levels = levels;
  const contour::BoundaryRefineReport r = contour::refine_boundary(region, extracted, ro);
  fmt::print("boundary refinement: {} quads chord the surface deeper than {:.3g} h (deepest {:.3g} h), {} refined "
             "within the templates' budget; {} levels, {} -> {} hexes ({} vertices marked, {} by the templates); {} "
             "new boundary vertices projected ({} failed); deepest chord now {:.3g} h, {} quads over; mean chord "
             "{:.3g} h -> {:.3g} h; {} quads more than h off the surface left alone\n",
             r.coarse_quads, tolerance, r.max_chord_before, r.refined_quads, r.levels, r.hexes_before, r.hexes_after,
             r.marked_vertices, r.promoted_vertices, r.projected_vertices, r.projection_failures, r.max_chord_after,
             r.coarse_quads_after, r.mean_chord_before, r.mean_chord_after, r.unreachable_quads);
  seconds = r.seconds;
  return {{"chord_tolerance", tolerance},
          {"levels", r.levels},
          {"coarse_quads", r.coarse_quads},
          {"refined_quads", r.refined_quads},
          {"coarse_quads_after", r.coarse_quads_after},
          {"unreachable_quads", r.unreachable_quads},
          {"max_chord_before", r.max_chord_before},
          {"max_chord_after", r.max_chord_after},
          {"mean_chord_before", r.mean_chord_before},
          {"mean_chord_after", r.mean_chord_after},
          {"hexes_before", r.hexes_before},
          {"hexes_after", r.hexes_after},
          {"marked_vertices", r.marked_vertices},
          {"promoted_vertices", r.promoted_vertices},
          {"projected_vertices", r.projected_vertices},
          {"projection_failures", r.projection_failures}};
}

ProgressCallback progress_printer(std::FILE* out) {
  return [out](const IterationReport& r) {
    fmt::print(out, "  {:<8} {:>4}  objective {:.6g}  min SJ {:.4f}  inverted {}\n", r.stage, r.iteration, r.objective,
               r.min_sj, r.inverted);
    std::fflush(out);
  };
}

namespace {

// The worst pass's printed lines and JSON facts.
nlohmann::json report_worst(const WorstResult& w, double seconds) {
  fmt::print("worst: {} passes, {} moves{}{}, min SJ {:.4f} -> {:.4f}\n", w.passes, w.moves,
             w.patch_moves ? fmt::format(" and {} joint moves of patches", w.patch_moves) : "",
             w.searched ? fmt::format("; random search raised {} of {} clusters", w.search_gains, w.searched) : "",
             w.min_sj_before, w.min_sj_after);
  nlohmann::json j = {{"passes", w.passes},
                      {"moves", w.moves},
                      {"patch_moves", w.patch_moves},
                      {"patch_skipped", w.patch_skipped},
                      {"searched", w.searched},
                      {"search_gains", w.search_gains},
                      {"min_sj_before", w.min_sj_before},
                      {"min_sj_after", w.min_sj_after},
                      {"seconds", seconds},
                      {"passes_seconds", w.passes_seconds},
                      {"patch_seconds", w.patch_seconds},
                      {"search_seconds", w.search_seconds}};
  // The hexes no placement of the free vertices lifts to 0.2, proven (find_quality_bounds()).
  auto& proven = j["proven"] = nlohmann::json::array();
  for (const QualityBound& b : w.proven)
    proven.push_back({{"kind", to_string(b.kind)}, {"vertex", b.vertex}, {"free", b.free}, {"bound", b.bound},
                      {"hexes", b.hexes}});
  for (std::size_t i = 0; i < w.proven.size() && i < 5; ++i) {
    const QualityBound& b = w.proven[i];
    fmt::print("  proven with the fixed vertices: one of hexes {} stays at or below {:.4f} ({} at vertex {}{})\n",
               fmt::join(b.hexes, ","), b.bound, to_string(b.kind), b.vertex,
               b.free >= 0 ? fmt::format(", free edge to {}", b.free) : "");
  }
  if (w.proven.size() > 5) fmt::print("  ... and {} more proofs (JSON: worst.proven)\n", w.proven.size() - 5);
  return j;
}

}  // namespace

nlohmann::json run_optimisation(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const OptimizeOptions& options) {
  const OptimizeResult r = optimize_mesh(mesh, fixed, options);
  nlohmann::json j = nlohmann::json::object();
  if (r.untangled) {
    const UntangleResult& u = r.untangle;
    nlohmann::json infeasible = nlohmann::json::array();
    for (const InfeasibleSet& f : u.infeasible)
      infeasible.push_back({{"kind", to_string(f.kind)}, {"vertex", f.vertex}, {"hexes", f.hexes}});
    j["untangle"] = {{"iterations", u.iterations}, {"min_sj", u.min_sj},         {"inverted", u.inverted},
                     {"reached_margin", u.reached_margin}, {"lp_moves", u.lp_moves}, {"vertex_sweeps", u.vertex_sweeps}, {"infeasible", infeasible},
                     {"given_up", u.given_up},             {"stuck", u.stuck},       {"stop", u.stop},
                     {"seconds", r.untangle_seconds}};
    if (!u.infeasible.empty()) {
      // The proofs first: they explain why the exit code will be 1 whatever else happens.
      fmt::print("untangle: {} sets of hexes cannot all be valid with these fixed vertices; {} hexes given up:\n",
                 u.infeasible.size(), u.given_up.size());
      for (std::size_t i = 0; i < u.infeasible.size() && i < 20; ++i) {
        const InfeasibleSet& f = u.infeasible[i];
        std::string ids;
        for (Index h : f.hexes) ids += fmt::format(" {}", h);
        if (f.kind == InfeasibleSet::Kind::fixed_frame)
          fmt::print("  fixed_frame: hex{} has an inverted frame made of fixed vertices only\n", ids);
        else
          fmt::print("  vertex_cone: free vertex {} has no place keeping all of hexes{} valid\n", f.vertex, ids);
      }
      if (u.infeasible.size() > 20) fmt::print("  ... ({} more in the JSON report)\n", u.infeasible.size() - 20);
    }
    const char* why = u.stop == "margin" ? "" : u.stop == "stall" ? ", stopped: no progress" : ", stopped: iteration limit";
    fmt::print("untangle: {} iterations{}{}, min SJ {:.4f}{}, inverted {}{}{}, {:.2f} s\n", u.iterations,
               u.lp_moves ? fmt::format(" ({} LP moves)", u.lp_moves) : "", why, u.min_sj,
               u.given_up.empty() ? "" : " (hexes not given up)", u.inverted,
               u.stuck.empty() ? "" : fmt::format(" ({} stuck)", u.stuck.size()),
               u.reached_margin ? "" : fmt::format(" (margin {} not reached)", options.untangle_options.margin),
               r.untangle_seconds);
  }
  const ShapeResult& s = r.shape;
  fmt::print("shape: {} sweeps, mean inverse mean ratio {:.6f} -> {:.6f}{}\n", s.iterations, s.objective_before,
             s.objective_after, s.frozen_hexes ? fmt::format(" ({} invalid hexes held)", s.frozen_hexes) : "");
  j["shape"] = {{"iterations", s.iterations}, {"objective_before", s.objective_before},
                {"objective_after", s.objective_after}, {"frozen_hexes", s.frozen_hexes}, {"seconds", r.shape_seconds}};
  if (r.worst_run) j["worst"] = report_worst(r.worst, r.worst_seconds);
  return j;
}

namespace {


// Per hex the lower of the certified scaled Jacobian and twice the jacobian ratio (what the
// rounds release for: a ratio of 0.1 ranks with a scaled Jacobian of 0.2), and the score.
std::vector<double> round_ranks(const HexMesh& mesh, RoundScore& score) {
  std::vector<double> sj = certified_scaled_jacobians(mesh);
  const std::vector<double> ratio = hex_metric(mesh, HexMetric::jacobian_ratio);
  score = {};
  for (std::size_t h = 0; h < sj.size(); ++h) {
    const double s = is_degenerate(sj[h]) ? -1.0 : sj[h];
    score.below += s < kQuestionableSJ;
    score.poor += ratio[h] < kPoorJacobianRatio;
    score.min_sj = std::min(score.min_sj, s);
    score.min_ratio = std::min(score.min_ratio, ratio[h]);
    if (!is_degenerate(sj[h])) sj[h] = std::min(sj[h], 2 * ratio[h]);
  }
  return sj;
}

// The hexes below 0.2 by `rank`, grown by vertex-sharing rings one at a time (a release
// round widens its reach only when the nearer rings release nothing new).
class ReleaseRings {
 public:
  ReleaseRings(const HexMesh& mesh, const Incidence& inc, const std::vector<double>& rank)
      : mesh_(mesh), inc_(inc), in_(mesh.num_hexes(), 0) {
    for (Index h = 0; h < mesh.num_hexes(); ++h)
      if (rank[h] < kQuestionableSJ || is_degenerate(rank[h])) in_[h] = 1, ring_.push_back(h);
    members_ = ring_;
  }
  void grow() {
    std::vector<Index> next;
    for (Index h : ring_)
      for (Index v : mesh_.hexes[h])
        for (Index k = inc_.offsets[v]; k < inc_.offsets[v + 1]; ++k)
          if (!in_[inc_.ids[k]]) in_[inc_.ids[k]] = 1, next.push_back(inc_.ids[k]);
    members_.insert(members_.end(), next.begin(), next.end());
    ring_ = std::move(next);
  }
  /// The boundary vertices of the hexes reached so far, sorted and unique.
  [[nodiscard]] std::vector<Index> candidates(const BoundarySurface& surface) const {
    std::vector<Index> c;
    for (Index h : members_)
      for (Index v : mesh_.hexes[h])
        if (surface.role(v) != BoundarySurface::Role::interior) c.push_back(v);
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
    return c;
  }

 private:
  const HexMesh& mesh_;
  const Incidence& inc_;
  std::vector<std::uint8_t> in_;
  std::vector<Index> ring_, members_;
};

// The places, before the first release round, of the vertices the rounds moved: what running
// them again needs, without a copy of every point (cthead h 2: 15 MiB).
class RoundJournal {
 public:
  explicit RoundJournal(std::size_t vertices) : unmoved_(vertices, 1) {}
  /// Before a round that moves the vertices not `held`.
  void note(const HexMesh& mesh, const std::vector<std::uint8_t>& held) {
    for (std::size_t v = 0; v < held.size(); ++v)
      if (!held[v] && unmoved_[v]) unmoved_[v] = 0, ids_.push_back(static_cast<Index>(v)), at_.push_back(mesh.points[v]);
  }
  /// Every noted vertex back where it was.
  void restore(HexMesh& mesh) const {
    for (std::size_t i = 0; i < ids_.size(); ++i) mesh.points[ids_[i]] = at_[i];
  }
  /// 1 for the vertices no round has moved (a PointSnapshot of the others holds the rounds' result).
  [[nodiscard]] const std::vector<std::uint8_t>& unmoved() const { return unmoved_; }

 private:
  std::vector<std::uint8_t> unmoved_;
  std::vector<Index> ids_;
  std::vector<Vec3> at_;
};

// The release rounds in one band (release_rounds()); the score they end with into `score`.
nlohmann::json rounds_in_band(HexMesh& mesh, BoundarySurface& surface, double band, const OptimizeOptions& o,
                              const Incidence& inc, RoundScore& score, RoundJournal& journal) {
  nlohmann::json released = nlohmann::json::array();
  // Where the surface itself leaves no valid or good place for the hexes at it (knife edges
  // one voxel thick), its vertices of those hexes are released into the band and the whole
  // sequence runs again around them: on the hexes within kRings hex rings of those below
  // 0.2, the rest held (the rest has converged already; re-running all of it doubled the
  // stage's time). Up to four more rounds catch what is still below 0.2, reaching one ring of
  // hexes further for the release (an inner hex squeezed between sheets has no boundary
  // vertex); they stop as soon as a round releases nothing (cthead h 4 needed 5). A round
  // that leaves the mesh worse by RoundScore is undone and ends them: its shape stage may
  // trade a minimum for the mean (cthead h 4: 0.205 -> 0.194 in its fifth round).
  constexpr int kRings = 3, kMaxReach = 3;
  // The rounds' worst passes work on a few hundred vertices, and still gained at the first
  // stage's 30 passes (headsq: 0.097 -> 0.174 in its second round's 30).
  OptimizeOptions rounds = o;
  rounds.worst_options.passes = std::max(o.worst_options.passes, 100);
  // One incidence for the rounds and every stage in them (the connectivity does not change).
  rounds.untangle_options.incidence = rounds.shape_options.incidence = rounds.worst_options.incidence = &inc;
  std::vector<double> sj = round_ranks(mesh, score);
  for (int round = 1; round <= 5; ++round) {
    // Hexes that need the release: below 0.2 by the certified scaled Jacobian, or valid inside
    // with a jacobian ratio below 0.1 (a fold about to open: the worst pass ranks them alike).
    // When the reach of this round releases nothing new (all of it is loose already and a
    // hex is still below: cthead h 4 stopped at 0.182 in a pillow hex), it grows by a ring.
    std::vector<Index> candidates;
    const BoundarySurface::Roles saved = surface.roles();
    std::size_t n = 0;
    ReleaseRings rings(mesh, inc, sj);
    if (round > 1) rings.grow();
    for (int reach = round > 1 ? 1 : 0;; ++reach) {
      candidates = rings.candidates(surface);
      n = surface.loosen(mesh, candidates, band);
      if (n > 0 || reach == kMaxReach) break;
      rings.grow();
    }
    if (n == 0) break;
    fmt::print("boundary: {} vertices of hexes below 0.2 released into a band of {:.3g} about their surface; "
               "optimising again\n", n, band);
    std::vector<std::uint8_t> held = frozen_outside(mesh, inc, sj, kQuestionableSJ, kRings);
    const std::vector<std::uint8_t> pinned = surface.fixed_mask();
    for (std::size_t v = 0; v < held.size(); ++v) held[v] = held[v] || pinned[v];
    const PointSnapshot points(mesh, held);  // the round moves none of the held vertices
    journal.note(mesh, held);
    nlohmann::json again = run_optimisation(mesh, held, rounds);
    again["released"] = n;
    RoundScore after;
    std::vector<double> next = round_ranks(mesh, after);
    if (after.worse_than(score) && rounds.shape_options.max_iter > 0) {
      // The shape stage lowers minima for the mean (headsq: 0.173 -> 0.099 in a third round,
      // and the worst pass got back only to 0.148): the round again without it, and the rounds
      // after it too.
      fmt::print("boundary: round {} left the mesh worse ({} below 0.2, min SJ {:.4f}; before it {}, {:.4f}); "
                 "again without the shape stage\n", round, after.below, after.min_sj, score.below, score.min_sj);
      points.restore(mesh);
      surface.set_roles(saved);
      surface.loosen(mesh, candidates, band);
      rounds.shape_options.max_iter = 0;
      again["retried"] = run_optimisation(mesh, held, rounds);
      next = round_ranks(mesh, after);
    }
    if (after.worse_than(score)) {
      points.restore(mesh);
      surface.set_roles(saved);
      fmt::print("boundary: round {} undone ({} below 0.2, min SJ {:.4f}; before it {}, {:.4f})\n", round, after.below,
                 after.min_sj, score.below, score.min_sj);
      again["undone"] = true;
      released.push_back(again);
      break;
    }
    released.push_back(again);
    score = after;
    sj = std::move(next);
    // From the second round on, the shape stage may not take a hex below 0.2 by rank, nor
    // lower one that is below: it undid what the worst pass before it reached (cthead's bone,
    // iso 1200, h 5: 0.124 -> 0.093, each round's worst pass winning back less, ending at
    // 0.180). The first round needs it free: its released vertices are far from their best
    // places (held there, headsq's first round ended at 0.129 instead of 0.203).
    rounds.shape_options.rank_guard = std::max(rounds.shape_options.rank_guard, kQuestionableSJ);
  }
  return released;
}

}  // namespace

RoundScore mesh_score(const HexMesh& mesh) {
  RoundScore s;
  round_ranks(mesh, s);
  return s;
}

nlohmann::json attempt_json(const RoundScore& score, double tie_band) {
  nlohmann::json j = {{"below_0.2", score.below}, {"min_sj", score.min_sj}};
  if (tie_band > 0) j["tie_band"] = tie_band;
  return j;
}

nlohmann::json release_rounds(HexMesh& mesh, BoundarySurface& surface, double& band, const OptimizeOptions& o,
                              std::size_t* reattached, bool* poor_left, bool widen_if_poor) {
  const Incidence inc = vertex_hexes(mesh);
  const BoundarySurface::Roles start = surface.roles();
  RoundJournal journal(mesh.points.size());
  RoundScore score;
  nlohmann::json released = rounds_in_band(mesh, surface, band, o, inc, score, journal);
  // Rounds that end with hexes invalid (inverted, or not valid inside) run once more from
  // where they began, in a band 5/3 as wide (0.3 -> 0.5 cells by default): the band decides
  // their path, and validity outranks its reach. cthead at iso 1000 (skin to bone), h 3, kept
  // two pillow hexes at -0.0002 through five rounds in a band of 0.3 cells and ended with none
  // below 0.2 in 0.5; widening the band about those hexes alone, in later rounds, left them
  // at 0 (not valid inside). The better of the two runs (RoundScore) is kept.
  if (score.min_sj <= 0 || (widen_if_poor && score.below > 0)) {
    const double wider = band * 5 / 3;
    fmt::print("boundary: the rounds left hexes {} (min SJ {:.4f}); again from their start in a band of {:.3g}\n",
               score.min_sj <= 0 ? "invalid" : "below 0.2", score.min_sj, wider);
    const PointSnapshot first(mesh, journal.unmoved());
    BoundarySurface::Roles first_roles = surface.roles();
    journal.restore(mesh);
    surface.set_roles(start);
    RoundScore again;
    RoundJournal second(mesh.points.size());
    nlohmann::json retry = rounds_in_band(mesh, surface, wider, o, inc, again, second);
    if (again.worse_than(score)) {
      second.restore(mesh);  // back to the rounds' start, then the first run's places
      first.restore(mesh);
      surface.set_roles(std::move(first_roles));
      fmt::print("boundary: the wider band did no better ({} below 0.2, min SJ {:.4f}); the first run kept\n",
                 again.below, again.min_sj);
      released.push_back({{"retried_band", wider}, {"rounds", retry}, {"kept", false}});
    } else {
      retry.push_back({{"retried_band", wider}, {"first_rounds", released}, {"kept", true}});
      released = std::move(retry);
      band = wider;
    }
  }
  // Released for the optimiser's sake, a vertex goes back onto its surface where the mesh now
  // allows it (cthead h 3: 354 of 1,979).
  if (surface.num_loose() > 0) {
    const ReattachResult back = reattach_released(mesh, surface);
    fmt::print("boundary: {} of the {} released vertices back on their surface\n", back.reattached, back.loose_before);
    if (reattached) *reattached = back.reattached;
  }
  // (Putting vertices back takes no hex below 0.2 nor a ratio below 0.1: the score stands.)
  if (poor_left) *poor_left = score.below + score.poor > 0;
  return released;
}

nlohmann::json optimise_stage(HexMesh& mesh, bool terminal, std::size_t& inverted_left, const SlideSpec& slide,
                              std::vector<std::uint8_t>* released_mask) {
  std::unique_ptr<BoundarySurface> surface;
  if (slide.cut) {
    // With the boundary fixed, only the cut surfaces' vertices (and their curves) slide.
    std::vector<BoundarySurface::Constraint> cons = slide.cut->constraints;
    if (!slide.region)
      for (BoundarySurface::Constraint& c : cons)
        if (c.first != BoundarySurface::kNone && c.first < slide.cut->first_cut && c.second < slide.cut->first_cut)
          c.pinned = true;
    surface = std::make_unique<BoundarySurface>(mesh, slide.cut->before, slide.cut->surfaces, cons);
    surface->set_exact_from(slide.cut->first_cut);  // a cut along an isosurface is as exact as a shape
    if (slide.domain) surface->set_domain(*slide.domain);
    fmt::print("boundary: {} vertices slide (on the region's surfaces, the box and the cuts, and their curves); {} pinned\n",
               surface->num_sliding(), surface->num_pinned());
  } else if (slide.region) {
    std::vector<contour::LevelSet> surfaces = slide.region->surfaces;
    std::vector<std::int8_t> place = *slide.vertex_place;
    place.resize(mesh.points.size(), contour::kInteriorVertex);
    // A box vertex slides in the face it lies in, whether the box is an --outer box or the
    // volume's box cutting the solid (a scan cut at the neck: the cut is a plane too);
    // BoundarySurface pins those that lie in two (the box's edges and corners) or on an
    // isosurface too (where it meets the box).
    const std::size_t first = surfaces.size();
    for (const contour::LevelSet& f : contour::box_faces(slide.region->domain)) surfaces.push_back(f);
    for (std::size_t v = 0; v < place.size(); ++v)
      for (std::size_t f = first; place[v] == contour::kBoxVertex && f < surfaces.size(); ++f)
        if (surfaces[f].on(mesh.points[v])) place[v] = static_cast<std::int8_t>(f);
    surface = std::make_unique<BoundarySurface>(mesh, std::move(surfaces), place, slide.feature_degrees);
    surface->set_domain(slide.region->domain);
    // " on the S" for one surface, ": a on the S, b on the T" for several.
    std::vector<std::size_t> used;
    for (std::size_t k = 0; k < surface->surfaces().size(); ++k)
      if (surface->num_sliding_on(k) > 0) used.push_back(k);
    std::string on = used.size() == 1 ? " on the " + surface->surfaces()[used[0]].describe() : used.empty() ? "" : ":";
    for (std::size_t i = 0; used.size() > 1 && i < used.size(); ++i)
      on += fmt::format("{} {} on the {}", i ? "," : "", surface->num_sliding_on(used[i]), surface->surfaces()[used[i]].describe());
    fmt::print("boundary: {} vertices slide{}; {} pinned (on the domain box, where two surfaces meet{})\n",
               surface->num_sliding(), on, surface->num_pinned(),
               slide.feature_degrees < 180 ? fmt::format(", or on creases > {} degrees", slide.feature_degrees) : "");
  }
  const std::vector<std::uint8_t> fixed = surface ? surface->fixed_mask() : fixed_mask(mesh, FixedVertices::boundary);
  OptimizeOptions o;
  o.untangle_options.surface = o.shape_options.surface = o.worst_options.surface = surface.get();
  if (terminal) {
    const ProgressCallback progress = progress_printer(stdout);
    o.untangle_options.progress = o.shape_options.progress = o.worst_options.progress = progress;
  }
  // With release rounds to follow, the first untangler stops at its first stall: the hexes it
  // leaves inverted sit where the isosurface holds their vertices, which the first round
  // releases and untangles in a few iterations (cthead h 4: its LP rescues kept 1-2 inverted
  // hexes for 23 more iterations, 10 of its 27 s, and the round fixed them in 8). For the same
  // reason its worst pass ends with the single passes: the end game (joint moves, the walk)
  // is the rounds', where the vertices that hold the poor hexes are free (headsq h 4: the
  // first run's end game took 16 of 21 s and left the minimum at 0.10; the round reached 0.2
  // in 0.6 s. The demo: 2.9 -> 0.5 s, its minimum 0.204 -> 0.306).
  OptimizeOptions first = o;
  const bool rounds_follow = surface && slide.band > 0;
  if (rounds_follow) {
    first.untangle_options.rescues = 0;
    first.worst_options.patch_rounds = 0;
    first.worst_options.search_trials = 0;
  }
  nlohmann::json j = run_optimisation(mesh, fixed, first);
  std::size_t reattached = 0;
  double band = slide.band;  // wider if the rounds ran again (release_rounds())
  bool poor_left = false;
  nlohmann::json released =
      rounds_follow ? release_rounds(mesh, *surface, band, o, &reattached, &poor_left) : nlohmann::json::array();
  if (rounds_follow && slide.cut && poor_left) {
    // The last resort after cuts: the crease vertices (a cut on the isosurface) of hexes still
    // below 0.2 leave the isosurface for the band, staying on the cut. Not sooner: the crease
    // is the surfaces' exact curve wherever the rounds did without (cthead's y = 110 plane).
    surface->set_release_creases(true);
    fmt::print("boundary: hexes below 0.2 after the rounds; releasing the cuts' crease vertices too\n");
    std::size_t more = 0;
    // As the last resort they may widen the band for hexes below 0.2, not only invalid ones
    // (cthead h 5 plane y = 100: 3 below 0.2 in 0.5 cells, none in 0.83).
    released.push_back(
        {{"creases_released", true}, {"rounds", release_rounds(mesh, *surface, band, o, &more, &poor_left, true)}});
    reattached += more;
  }
  if (rounds_follow && released.empty() && poor_left) {
    // No round ran (no hex below 0.2 by rank has a boundary vertex to release within reach):
    // the end game the first run left to them, here, the boundary on its surfaces.
    fmt::print("worst: hexes below 0.2 and none of their boundary vertices to release: the end game\n");
    const auto t0 = std::chrono::steady_clock::now();
    const WorstResult w = improve_worst(mesh, fixed, o.worst_options);
    j["end_game"] = report_worst(w, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  if (surface) {
    const auto [far, off] = surface->fit(mesh);
    nlohmann::json per = nlohmann::json::object();
    for (std::size_t k = 0; k < surface->surfaces().size(); ++k)
      if (const std::size_t n = surface->num_sliding_on(k); n > 0) per[surface->surfaces()[k].describe()] = n;
    j["boundary"] = {{"mode", "slide"},
                     {"sliding", surface->num_sliding()},
                     {"sliding_per_surface", per},
                     {"pinned", surface->num_pinned()},
                     {"max_relative_level", far},
                     {"band", band},
                     {"band_asked", slide.band},
                     {"loose", surface->num_loose()},
                     {"reattached", reattached},
                     {"max_loose_distance", off},
                     {"rounds", released}};
    if (released_mask) {
      released_mask->assign(mesh.points.size(), 0);
      for (Index v = 0; v < mesh.num_vertices(); ++v) (*released_mask)[v] = surface->role(v) == BoundarySurface::Role::loose;
    }
    if (surface->num_loose() > 0)
      fmt::print("boundary: {} vertices within {:.3g} of their surface (band {:.3g}); the other {} on it\n",
                 surface->num_loose(), off, band, surface->num_sliding());
  } else {
    j["boundary"] = {{"mode", "fixed"}};
  }
  const MetricSummary s = summarize(HexMetric::scaled_jacobian, scaled_jacobians(mesh), 0);
  inverted_left = s.inverted + s.degenerate;
  return j;
}

void print_stage_table(const std::vector<StageRow>& rows) {
  fmt::print("\n{:<18} {:>10} {:>10} {:>8} {:>8} {:>9} {:>9} {:>9}\n", "stage", "hexes", "vertices", "min SJ", "mean SJ",
             "SJ < 0", "SJ < 0.2", "time (s)");
  for (const StageRow& r : rows)
    fmt::print("{:<18} {:>10} {:>10} {:>8.4f} {:>8.4f} {:>9} {:>9} {:>9.2f}\n", r.name, r.hexes, r.vertices, r.sj.min,
               r.sj.mean, r.sj.inverted + r.sj.degenerate, r.sj.inverted + r.sj.degenerate + r.sj.questionable,
               r.seconds);
}

nlohmann::json stage_table_json(const std::vector<StageRow>& rows) {
  nlohmann::json a = nlohmann::json::array();
  for (const StageRow& r : rows)
    a.push_back({{"stage", r.name},
                 {"hexes", r.hexes},
                 {"vertices", r.vertices},
                 {"scaled_jacobian", to_json(r.sj)},
                 {"below_0.2", r.sj.inverted + r.sj.degenerate + r.sj.questionable},
                 {"seconds", r.seconds}});
  return a;
}

void write_mesh_report(const std::string& dir, const std::string& title, const std::vector<StageRow>& rows,
                       const nlohmann::json& summary, const HexMesh& mesh) {
  ReportInput in;
  in.title = title;
  in.summary = summary;
  in.mesh = &mesh;
  for (const StageRow& r : rows)
    in.stages.push_back({r.name, r.sj_values, static_cast<std::size_t>(r.hexes), static_cast<std::size_t>(r.vertices),
                         r.seconds, r.extra});
  write_report(dir, in);
}

double peak_memory_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // Linux: KiB
}

}  // namespace isohex::cli
