// Worst-element pass: local max–min moves on Verdict's scaled Jacobian itself.
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/ordered_moves.hpp"
#include "isohex/optimize/patch.hpp"
#include "isohex/optimize/search.hpp"
#include "isohex/optimize/worst_move.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"
#include "isohex/quality/summary.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace isohex {

namespace {

// The vertices of the lowest of a hex's nine scaled-Jacobian frames: a corner and its three
// neighbours, or all eight for the centre frame.
std::vector<Index> worst_frame_vertices(const std::array<Vec3, 8>& p, const Hex& hex) {
  int worst = 0;
  double lo = std::numeric_limits<double>::infinity();
  for (int t = 0; t < opt::kFrames; ++t)
    if (const double v = opt::scaled_frame_value(p, t); v < lo) lo = v, worst = t;
  if (worst == opt::kCentreFrame) return {hex.begin(), hex.end()};
  const auto& n = kCornerNeighbors[worst];
  return {hex[worst], hex[n[0]], hex[n[1]], hex[n[2]]};
}

// The vertices of `hexes` that are not fixed (ascending).
std::vector<Index> free_vertices(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed,
                                 const std::vector<Index>& hexes) {
  std::vector<Index> p;
  for (Index h : hexes)
    for (Index v : mesh.hexes[h])
      if (fixed.empty() || !fixed[v]) p.push_back(v);
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  return p;
}

// The hexes around the free vertices of hex h's worst frame: where that frame's one free vertex
// cannot turn without folding a corner of the next hex, that hex's other vertices must make room
// (ECR block_in with its boundary fixed: a corner of two fixed boundary edges that can reach
// 0.2026 at best stayed at 0.199, its free edge's turn taking a corner of the next hex from 0.27
// to 0.04).
std::vector<Index> frame_star(const HexMesh& mesh, const Incidence& inc, const std::vector<std::uint8_t>& fixed, Index h) {
  std::vector<Index> around;
  for (Index v : worst_frame_vertices(mesh.corners(h), mesh.hexes[h]))
    if (fixed.empty() || !fixed[v])
      for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) around.push_back(inc.ids[k]);
  return around;
}

}  // namespace

WorstResult improve_worst(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const WorstOptions& options) {
  WorstResult res;
  Incidence own_inc;
  const Incidence& inc = opt::incidence_of(mesh, options.incidence, own_inc);
  std::vector<double> sj(mesh.hexes.size());
  // The pass works on the hexes lowest in `rank`: the scaled Jacobian, or with ratio_terms the
  // lower of it and the hex's Bernstein ratio bound.
  std::vector<double> rank(mesh.hexes.size());
  const auto update = [&](Index h) {
    const auto p = mesh.corners(h);
    if (!options.ratio_terms) {
      sj[h] = rank[h] = opt::worst_sj_value(p);
      return;
    }
    const CertifiedQuality c = certified_quality(p);
    sj[h] = is_degenerate(c.scaled_jacobian) ? -2.0 : c.scaled_jacobian;
    rank[h] = opt::hex_rank(c);
  };
  tbb::parallel_for(tbb::blocked_range<Index>(0, mesh.num_hexes(), 1024), [&](const tbb::blocked_range<Index>& r) {
    for (Index h = r.begin(); h != r.end(); ++h) update(h);  // each hex its own entries
  });
  const auto mesh_min = [&] { return sj.empty() ? 1.0 : *std::min_element(sj.begin(), sj.end()); };
  res.min_sj_before = res.min_sj_after = mesh_min();
  std::vector<Index> order;
  std::vector<Index> seen(mesh.points.size(), -1);
  const std::vector<Vec3> start = mesh.points;
  // A fixed order: worst first by the ranks at the time of sorting, ties by id. The loops read
  // it while moves change ranks, so how far they go is open; it is sorted lazily instead
  // (on cthead h 2 a full sort of 585,000 hexes per pass took about a fifth of the passes'
  // time): first the hexes below max(0.2, raise_below) and at least the `count` lowest, then
  // more on demand (has()), in the same order as a full sort.
  const double needed_below = std::max(options.raise_below, kQuestionableSJ);
  std::vector<double> sorted_rank;  // the ranks `order` is sorted by
  std::vector<Index> unsorted;      // the hexes not in `order` yet
  const auto worse = [&](Index a, Index b) {
    return sorted_rank[a] < sorted_rank[b] || (sorted_rank[a] == sorted_rank[b] && a < b);
  };
  const auto take = [&](std::size_t k) {  // the k worst of `unsorted`, appended in order
    k = std::min(k, unsorted.size());
    const auto mid = unsorted.begin() + static_cast<std::ptrdiff_t>(k);
    if (mid != unsorted.end()) std::nth_element(unsorted.begin(), mid, unsorted.end(), worse);
    std::sort(unsorted.begin(), mid, worse);
    order.insert(order.end(), unsorted.begin(), mid);
    unsorted.erase(unsorted.begin(), mid);
  };
  const auto has = [&](std::size_t i) {  // order[i] exists (sorted further if needed)
    if (i >= order.size() && !unsorted.empty()) take(std::max<std::size_t>(i + 1 - order.size(), order.size()));
    return i < order.size();
  };
  const auto sort_worst_first = [&] {
    sorted_rank = rank;
    order.clear();
    unsorted.clear();
    for (Index h = 0; h < mesh.num_hexes(); ++h) (rank[h] < needed_below ? order : unsorted).push_back(h);
    std::sort(order.begin(), order.end(), worse);
    has(std::max<std::size_t>(options.count, 1) - 1);  // standing() reads them
  };
  int pass = 0;
  // What a pass is judged by, read off `order` (sorted worst first): the lowest rank, the
  // deficit of the hexes below 0.2 by rank (the sum of their distances to 0.2), and the mean of
  // the `count` lowest ranks (the tail it raises once none is below 0.2).
  struct Standing {
    double min = 2, deficit = 0, tail = 0;
  };
  const auto standing = [&] {
    Standing s;
    const std::size_t k = std::min(std::max<std::size_t>(options.count, 1), order.size());
    if (k == 0) return s;
    s.min = rank[order[0]];
    for (std::size_t i = 0; i < k; ++i) s.tail += rank[order[i]] / static_cast<double>(k);
    for (std::size_t i = 0; has(i) && rank[order[i]] < kQuestionableSJ; ++i)
      s.deficit += kQuestionableSJ - rank[order[i]];
    return s;
  };
  // A vertex whose move found no gain is not tried again until a vertex of a hex around it
  // moves (in a pass, a joint move or a walk) or the floor the move reads from the mesh
  // minimum changes: opt::worst_move() reads nothing else, so skipping it gives the same mesh.
  // (Trying every vertex again at each new minimum and after each joint move was half of
  // cthead h 2's 200,000 tries, 94 us each.)
  std::vector<std::uint8_t> settled(mesh.points.size(), 0);
  std::vector<double> settled_at(mesh.points.size(), 0);
  // When each vertex last moved, on a clock of moves (for the joint moves' memo below).
  std::vector<std::uint64_t> moved_at(mesh.points.size(), 0);
  std::uint64_t clock = 0;
  const auto unsettle_around = [&](Index v) {
    moved_at[v] = ++clock;
    for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k)
      for (Index w : mesh.hexes[inc.ids[k]]) settled[w] = 0;
  };
  // What opt::worst_move() reads of the mesh minimum: its scaled-Jacobian floor with the ratio
  // terms, nothing without them.
  const auto floor_of = [&](double min_now) { return options.ratio_terms ? std::max(options.sj_floor, min_now) : 0.0; };
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  // One pass: the vertices of the hexes in `order` while a hex is among the `count` lowest
  // below `below` or is below `raise_below` (by its rank when the pass reaches it), each moved
  // once. It is one sequence of moves, run by OrderedMoves in windows: in parallel, with the
  // sequence's result. A hex whose rank a move before it may have changed is checked once its
  // window has run, by its rank with its vertices where they were at its turn; where it ends the
  // pass, the moves after it are undone (their tries of settled vertices aside, which leave the
  // mesh as it is). Returns the number of moves.
  // Windows of 64 moves: a pass mostly ends at a hex that earlier moves raised (cthead h 4:
  // after 20-35 % of the hexes it could reach), and a window's moves after that point are
  // undone; with windows up to 1,024 moves as many were undone as kept.
  constexpr std::size_t kWindow = 64;
  opt::OrderedMoves moves(mesh, inc);
  enum : std::uint8_t { kSkipped, kFailed, kMoved };
  std::vector<std::uint8_t> outcome;
  std::vector<Vec3> old;                              // per move: its vertex's place before it
  std::vector<std::pair<std::uint8_t, double>> was;   // per failed move: its vertex's settled state before it
  std::vector<std::uint64_t> was_at;                  // per moved vertex: its moved_at before it
  struct Check {
    std::size_t i, first;  // order[i], checked after the window's first `first` moves
  };
  std::vector<Check> checks;
  const auto admits = [&](std::size_t i, double r) {
    return (i < options.count && r < options.below) || r < options.raise_below;
  };
  const auto rank_then = [&](const Check& c) {  // order[c.i]'s rank when the sequence reached it
    const Index h = order[c.i];
    auto p = mesh.corners(h);
    for (int j = 0; j < 8; ++j)
      if (const Index k = moves.position(mesh.hexes[h][j]); k >= 0 && static_cast<std::size_t>(k) >= c.first)
        p[j] = old[static_cast<std::size_t>(k)];
    return options.ratio_terms ? opt::hex_rank(certified_quality(p)) : opt::worst_sj_value(p);
  };
  const auto one_pass = [&](double min_now, double floor_now) {
    std::size_t moved = 0;
    const auto is_settled = [&](Index v) { return settled[v] && settled_at[v] == floor_now; };
    const auto undo_from = [&](std::size_t first) {
      for (std::size_t k = moves.size(); k-- > first;) {
        const Index v = moves.vertex(k);
        if (outcome[k] == kMoved) mesh.points[v] = old[k], moved_at[v] = was_at[k], --moved;
        if (outcome[k] == kFailed) settled[v] = was[k].first, settled_at[v] = was[k].second;
      }
      for (std::size_t k = first; k < moves.size(); ++k)
        if (outcome[k] == kMoved)
          for (Index n = inc.offsets[moves.vertex(k)]; n < inc.offsets[moves.vertex(k) + 1]; ++n) update(inc.ids[n]);
    };
    for (std::size_t i = 0;;) {
      moves.clear();
      checks.clear();
      // A hex none of whose vertices has come yet has the rank it was sorted by; past the
      // hexes that rank admits, one that may have changed is checked alone, after the moves
      // before it.
      bool last = false;
      while (moves.size() < kWindow) {
        if (!has(i)) { last = true; break; }
        const Hex& hx = mesh.hexes[order[i]];
        const bool changed = std::any_of(hx.begin(), hx.end(), [&](Index v) { return seen[v] == pass; });
        if (!admits(i, sorted_rank[order[i]])) {
          if (changed && (moves.size() > 0 || !checks.empty())) break;  // this window first
          if (!changed || !admits(i, rank[order[i]])) { last = true; break; }
        } else if (changed) {
          checks.push_back({i, moves.size()});
        }
        for (Index v : hx) {
          if ((!fixed.empty() && fixed[v]) || seen[v] == pass) continue;
          seen[v] = pass;
          // A settled vertex that no move before it can unsettle is no move at all.
          const int level = moves.level_of(v);
          if (level > 0 || !is_settled(v)) moves.add(v, level);
        }
        ++i;
      }
      outcome.assign(moves.size(), kSkipped);
      old.resize(moves.size());
      was.resize(moves.size());
      was_at.resize(moves.size());
      moves.run(
          [&](std::size_t k) {
            const Index v = moves.vertex(k);
            old[k] = mesh.points[v];
            if (is_settled(v)) return;
            if (!opt::worst_move(mesh, inc, v, start, options.surface, options, min_now)) {
              outcome[k] = kFailed;
              return;
            }
            outcome[k] = kMoved;
            // No other move of the level shares a hex with v: these entries are v's alone.
            for (Index n = inc.offsets[v]; n < inc.offsets[v + 1]; ++n) update(inc.ids[n]);
          },
          [&](std::size_t k) {
            const Index v = moves.vertex(k);
            if (outcome[k] == kFailed) {
              was[k] = {settled[v], settled_at[v]};
              settled[v] = 1, settled_at[v] = floor_now;
            } else if (outcome[k] == kMoved) {
              was_at[k] = moved_at[v];
              unsettle_around(v);
              ++moved;
            }
          });
      for (const Check& c : checks)
        if (!admits(c.i, rank_then(c))) {
          undo_from(c.first);
          return moved;
        }
      if (last) return moved;
    }
  };
  const auto untimed_passes = [&](int passes, int stall_passes) {
    std::vector<Standing> history;
    for (int end = pass + passes; pass < end;) {
      sort_worst_first();
      // A stall: tiny gains go on for ever (a move is kept for any rise of its own
      // minimum), so the passes stop once `stall_passes` of them together gained little by
      // the standing: the minimum, and the deficit below 0.2 while there is one, else the
      // tail (cthead h 4: 100 passes at a minimum of 0.163 that only the walk raised; with the
      // minimum alone, pave1 fixed ended at 0.303 instead of 0.403).
      history.push_back(standing());
      if (stall_passes > 0 && history.size() > static_cast<std::size_t>(stall_passes)) {
        const Standing& then = history[history.size() - 1 - static_cast<std::size_t>(stall_passes)];
        const Standing& now = history.back();
        const bool stalled = then.deficit > 0 ? now.deficit >= (1 - options.stall_fraction) * then.deficit
                                              : now.tail < then.tail + options.stall_gain;
        if (stalled && now.min < then.min + options.stall_gain) break;
      }
      ++pass;
      const double min_now = mesh_min();
      const std::size_t moved = one_pass(min_now, floor_of(min_now));
      res.passes = pass;
      res.moves += moved;
      res.min_sj_after = mesh_min();
      if (options.progress) {
        std::size_t inverted = 0;
        for (double x : sj) inverted += x <= 0;
        options.progress({"worst", pass, static_cast<double>(moved), res.min_sj_after, inverted});
      }
      if (moved == 0) break;
    }
  };
  const auto single_passes = [&](int passes, int stall_passes) {
    const auto t0 = Clock::now();
    untimed_passes(passes, stall_passes);
    res.passes_seconds += since(t0);
  };
  single_passes(options.passes, options.stall_passes);
  // The end game: each cluster of hexes still below 0.2 by rank with the free vertices of its
  // hexes moved together, or where that gains nothing those of its worst hex (or of the hexes
  // around its worst frame); the single moves again after a round that moved something.
  const auto free_vertices_of = [&](const std::vector<Index>& hexes) { return free_vertices(mesh, fixed, hexes); };
  // The hexes below 0.2 by rank that share a vertex with h, and so on (ascending): a cluster of
  // poor hexes at one bad spot of the boundary tie with each other.
  std::vector<std::uint8_t> clustered(mesh.hexes.size(), 0);
  // The members of the sets the fixed vertices keep below 0.2 (find_quality_bounds() depends on
  // the fixed vertices alone): the end game leaves them out of its count and its walks.
  // The minimum only rises, so these are also the proofs for the end, where it stays below 0.2.
  std::vector<std::uint8_t> held(mesh.hexes.size(), 0);
  std::vector<QualityBound> proofs;
  if (!fixed.empty() && mesh_min() < kQuestionableSJ) proofs = find_quality_bounds(mesh, fixed, kQuestionableSJ);
  for (const QualityBound& b : proofs)
    for (Index h : b.hexes) held[h] = 1;
  const auto poor = [&](Index h) { return rank[h] < kQuestionableSJ; };
  const auto poor_free = [&](Index h) { return poor(h) && !held[h]; };
  const auto cluster_of = [&](Index h, auto member) {
    std::vector<Index> c{h};
    clustered[h] = 1;
    for (std::size_t i = 0; i < c.size() && c.size() < options.patch_size; ++i)
      for (Index v : mesh.hexes[c[i]])
        for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k)
          if (const Index g = inc.ids[k]; !clustered[g] && member(g)) clustered[g] = 1, c.push_back(g);
    std::sort(c.begin(), c.end());
    return c;
  };
  // More hexes below 0.2 than patch_max_poor are not stalls of the single moves but a region
  // the joint moves cannot repair (a boundary held fixed at knife edges); the walk, cheaper a
  // hex and blind to the proven ones, counts only the others.
  const auto too_many_poor = [&](auto counted) {
    std::size_t n = 0;
    for (Index h = 0; h < mesh.num_hexes(); ++h) n += counted(h);
    return n > options.patch_max_poor;
  };
  // A cluster whose joint moves all failed is not tried again while the same cluster (the same
  // hexes, the same worst one) meets the same mesh minimum and no vertex of a hex around its
  // free vertices or its worst frame's star has moved: move_patch() reads nothing else (those
  // positions, `start`, the minimum), so the tries would fail again and skipping them gives the
  // same mesh. (headsq, iso 800, h 3: the joint moves were 7.5 of 14 s; 15 of their some 45
  // failed tries were such repeats.)
  struct FailedTry {
    Index worst;
    std::vector<Index> cluster;
    double min;
    std::uint64_t at;
  };
  std::vector<FailedTry> failed;
  const auto moved_since = [&](const std::vector<Index>& hexes, std::uint64_t at) {
    for (Index g : hexes)
      for (Index v : mesh.hexes[g])
        for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k)
          for (Index w : mesh.hexes[inc.ids[k]])
            if (moved_at[w] > at) return true;
    return false;
  };
  const auto fails_again = [&](Index h, const std::vector<Index>& cluster, double min_now) {
    for (const FailedTry& f : failed) {
      if (f.worst != h || f.cluster != cluster || f.min != min_now) continue;
      return !moved_since(cluster, f.at) && !moved_since(frame_star(mesh, inc, fixed, h), f.at);
    }
    return false;
  };
  for (int round = 0; round < options.patch_rounds; ++round) {
    const auto t0 = Clock::now();
    sort_worst_first();
    if (too_many_poor(poor)) break;
    std::fill(clustered.begin(), clustered.end(), 0);
    std::size_t moved = 0;
    std::vector<FailedTry> failed_now;
    for (std::size_t i = 0; i < options.count && has(i) && rank[order[i]] < kQuestionableSJ; ++i) {
      const Index h = order[i];
      if (clustered[h]) continue;
      std::vector<Index> cluster = cluster_of(h, poor);
      const double min_before = mesh_min();
      if (options.patch_memo && fails_again(h, cluster, min_before)) {
        ++res.patch_skipped;
        failed_now.push_back({h, std::move(cluster), min_before, clock});
        continue;
      }
      // The cluster together, and where that gains nothing the worst hex of it alone, then its
      // frame's star; each with the plain model and, where that gains nothing, guarded. Each try
      // reads the minimum from before the first: a failed try moves nothing, and the cluster's
      // tries end at the first that succeeds (so no scan of every hex per try).
      const auto move = [&](const std::vector<Index>& targets, const std::vector<Index>& patch) {
        if (patch.empty() || patch.size() > options.patch_size ||
            !opt::move_patch(mesh, inc, targets, patch, start, options, min_before, opt::PatchModels::both))
          return false;
        for (Index v : patch) {
          unsettle_around(v);
          for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) update(inc.ids[k]);
        }
        return true;
      };
      const auto try_patch = [&](const std::vector<Index>& targets) { return move(targets, free_vertices_of(targets)); };
      // Last, h with the free vertices of every hex around the free vertices of its worst frame.
      const auto try_star = [&](Index h) { return move({h}, free_vertices_of(frame_star(mesh, inc, fixed, h))); };
      const std::uint64_t at = clock;
      if (try_patch(cluster) || (cluster.size() > 1 && try_patch({h})) || try_star(h))
        ++moved;
      else
        failed_now.push_back({h, std::move(cluster), min_before, at});
    }
    failed = std::move(failed_now);
    res.patch_moves += moved;
    res.patch_seconds += since(t0);
    res.min_sj_after = mesh_min();
    if (options.progress) options.progress({"patch", round + 1, static_cast<double>(moved), res.min_sj_after, 0});
    if (moved == 0) break;
    single_passes(std::min(options.passes, 10), options.resume_stall_passes);
  }
  // Last resort: the random walk round each cluster still below 0.2 by rank (`member`), its
  // minimum over the hexes not in `hold`.
  const auto walk = [&](auto member, const std::vector<std::uint8_t>& hold) {
    sort_worst_first();
    if (options.search_trials == 0 || too_many_poor(member)) return;
    std::fill(clustered.begin(), clustered.end(), 0);
    std::size_t gains = 0;
    for (std::size_t i = 0; has(i) && poor(order[i]); ++i) {
      const Index h = order[i];
      if (clustered[h] || !member(h)) continue;
      const auto t0 = Clock::now();
      const opt::SearchOutcome o =
          opt::search_region(mesh, inc, fixed, cluster_of(h, member), start, options, mesh_min(), hold);
      res.search_seconds += since(t0);
      ++res.searched;
      if (!(o.after > o.before)) continue;
      ++gains;
      for (Index v : o.vertices) {
        unsettle_around(v);
        for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) update(inc.ids[k]);
      }
    }
    res.search_gains += gains;
    res.min_sj_after = mesh_min();
    if (options.progress) options.progress({"search", 1, static_cast<double>(gains), res.min_sj_after, 0});
    if (gains > 0) single_passes(std::min(options.passes, 10), options.resume_stall_passes);
  };
  // Every poor hex first (a proven one still gains towards its bound: bust_in fixed, ratio
  // -0.097 -> -0.034), then, where proofs hold some, the others alone: next to a proven hex
  // they gain nothing while it counts (armadillo_in fixed, 79 -> 65 below 0.2 unproven).
  walk(poor, {});
  if (!proofs.empty()) walk(poor_free, held);
  if (res.min_sj_after < kQuestionableSJ) res.proven = std::move(proofs);
  return res;
}

}  // namespace isohex
