// Inverse mean-ratio shape optimisation (Knupp 2003) by feasible per-vertex Newton steps.
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <limits>

namespace isohex {

namespace {

// Hexes that the barrier cannot see (some frame determinant <= 0): left out of the objective.
std::vector<std::uint8_t> infeasible_hexes(const HexMesh& mesh, const std::vector<double>& inv_len) {
  std::vector<std::uint8_t> bad(mesh.hexes.size(), 0);
  tbb::parallel_for(tbb::blocked_range<Index>(0, mesh.num_hexes(), 1024), [&](const auto& r) {
    for (Index h = r.begin(); h != r.end(); ++h) bad[h] = !opt::hex_feasible(mesh.corners(h), inv_len[h]);
  });
  return bad;
}

double mean_objective(const HexMesh& mesh, const std::vector<double>& inv_len, const std::vector<std::uint8_t>& bad) {
  std::size_t terms = 0;
  for (std::uint8_t b : bad) terms += b ? 0 : 8;
  if (terms == 0) return 1.0;
  return opt::total_energy(mesh, inv_len, opt::EnergyParams{}, bad) / static_cast<double>(terms);
}

}  // namespace

double shape_objective(const HexMesh& mesh) {
  const std::vector<double> inv_len = opt::inverse_edge_lengths(mesh);
  return mean_objective(mesh, inv_len, infeasible_hexes(mesh, inv_len));
}

ShapeResult optimize_shape(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const ShapeOptions& options) {
  ShapeResult res;
  const std::vector<double> inv_len = opt::inverse_edge_lengths(mesh);
  const std::vector<std::uint8_t> bad = infeasible_hexes(mesh, inv_len);
  // The vertices of invalid hexes stay where they are: the barrier is undefined there, and
  // holding them keeps every invalid hex (and the objective's set of terms) unchanged.
  std::vector<std::uint8_t> frozen(mesh.points.size(), 0);
  for (Index h = 0; h < mesh.num_hexes(); ++h) {
    if (!bad[h]) continue;
    ++res.frozen_hexes;
    for (Index v : mesh.hexes[h]) frozen[v] = 1;
  }
  Incidence own_inc;
  const Incidence& inc = opt::incidence_of(mesh, options.incidence, own_inc);
  const VertexColoring coloring = color_vertices(mesh, fixed, &inc);
  // The objective and the scaled Jacobians per hex, evaluated again after a sweep only where a
  // vertex moved (the same values, summed in hex order: the same bits as whole-mesh passes).
  std::size_t terms = 0;
  for (std::uint8_t b : bad) terms += b ? 0 : 8;
  std::vector<double> hex_e;
  opt::hex_energies(mesh, inv_len, opt::EnergyParams{}, bad, hex_e);
  const auto objective = [&] { return terms == 0 ? 1.0 : opt::energy_sum(hex_e) / static_cast<double>(terms); };
  std::vector<double> sj = certified_scaled_jacobians(mesh);
  double e = objective();
  res.objective_before = res.objective_after = e;
  double min_sj = opt::sj_stats_of(sj).min;
  // Each hex's ratio bound, kept through the sweeps (EnergyParams::hex_ratio); a rank guard
  // reads the scaled Jacobian too, so its moves compute both and keep none.
  const bool keep_ratios = !(options.rank_guard > -std::numeric_limits<double>::infinity());
  std::vector<double> ratio(keep_ratios ? mesh.hexes.size() : 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ratio.size()), [&](const auto& r) {
    for (std::size_t h = r.begin(); h != r.end(); ++h) ratio[h] = jacobian_ratio_bound(mesh.corners(static_cast<Index>(h)));
  });
  // Culling: a sweep moves only the vertices near one that moved more than `cull` of its edge
  // length in the sweep before (the rest are held, as in `frozen`).
  std::vector<double> scale(mesh.points.size());
  for (Index v = 0; v < mesh.num_vertices(); ++v) scale[v] = opt::vertex_length(inc, inv_len, v);
  const double cull = options.cull;
  std::vector<std::uint8_t> held = frozen, changed(mesh.hexes.size(), 0), active(mesh.points.size());
  opt::MoveRecord record{&scale, cull, std::vector<std::uint8_t>(mesh.points.size(), 0)};
  std::vector<Index> changed_ids;
  for (int it = 1; it <= options.max_iter; ++it) {
    opt::EnergyParams params;
    params.surface = options.surface;
    params.rank_guard = options.rank_guard;
    params.hex_ratio = keep_ratios ? &ratio : nullptr;
    std::fill(record.moved.begin(), record.moved.end(), 0);
    const double grad = opt::sweep(mesh, coloring, inc, inv_len, params, held, 1, &record);
    std::fill(changed.begin(), changed.end(), 0);
    std::fill(active.begin(), active.end(), 0);
    opt::mark_far_moves(mesh, inc, record, active, &changed);
    res.culled = 0;
    if (cull > 0)
      for (Index v = 0; v < mesh.num_vertices(); ++v) {
        held[v] = frozen[v] || !active[v];
        res.culled += !frozen[v] && !active[v];
      }
    opt::hex_energies(mesh, inv_len, opt::EnergyParams{}, bad, hex_e, &changed);
    // Each step taken certified the hexes around its vertex valid inside above a positive floor
    // (stays_feasible()), so a hex that changed sits where a step certified it: its certified
    // scaled Jacobian is Verdict's, without a second certificate (the same bits).
    changed_ids.clear();
    for (Index h = 0; h < mesh.num_hexes(); ++h)
      if (changed[static_cast<std::size_t>(h)]) changed_ids.push_back(h);
    const std::vector<double> changed_sj = scaled_jacobians(mesh, changed_ids);
    for (std::size_t i = 0; i < changed_ids.size(); ++i) sj[static_cast<std::size_t>(changed_ids[i])] = changed_sj[i];
    const double e_new = objective();
    res.iterations = it;
    res.history.push_back(e_new);
    res.objective_after = e_new;
    const opt::SJStats s = opt::sj_stats_of(sj);
    if (options.progress) options.progress({"shape", it, e_new, s.min, s.inverted});
    const double rel = (e - e_new) / e;
    const double sj_gain = s.min - min_sj;
    e = e_new;
    min_sj = s.min;
    // The objective alone would stop while the minimum still climbs (Mesquite's pave1: 0.12
    // after 42 sweeps at 1e-4, 0.39 after 78), and the minimum is what the user sees.
    if ((rel < options.tol && !(sj_gain >= options.min_sj_gain)) || grad < options.grad_tol) break;
  }
  return res;
}

}  // namespace isohex
