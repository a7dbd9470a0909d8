// isohex volume info|convert: what a volume file holds, and conversion to .nrrd or .vti.
// The molecule and shape subcommands of the group register themselves from their own files.
#include "commands.hpp"

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/volume/statistics.hpp"
#include "isohex/volume/volume_io.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <memory>
#include <ostream>

namespace isohex::cli {

namespace {

nlohmann::json vec_json(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

std::string vec_text(const Vec3& v) { return fmt::format("{:.6g} {:.6g} {:.6g}", v.x(), v.y(), v.z()); }

struct InfoArgs {
  std::string file, json;
  std::size_t bins = 16;
  VolumeReadArgs read;
};

void run_info(const InfoArgs& a) {
  const Volume v = read_volume(a.file, a.read.options());
  const ValueStatistics s = value_statistics(v);
  const ValueHistogram h = value_histogram(v, s, a.bins);
  const double otsu = otsu_isovalue(v);
  fmt::print("{}\n", a.file);
  fmt::print("  dims         {} x {} x {} ({} points)\n", v.dims[0], v.dims[1], v.dims[2], v.size());
  fmt::print("  spacing      {}\n", vec_text(v.spacing));
  fmt::print("  origin       {}\n", vec_text(v.origin));
  fmt::print("  extent       {}  to  {}\n", vec_text(v.origin), vec_text(v.max_corner()));
  fmt::print("  source type  {}\n", scalar_type_name(v.source_type));
  if (s.count == 0) {
    fmt::print("  values       none finite ({} NaN or infinite)\n", s.non_finite);
  } else {
    fmt::print("  values       min {:.6g}  max {:.6g}  mean {:.6g}\n", s.min, s.max, s.mean);
    if (s.non_finite) fmt::print("  non-finite   {} (NaN or infinite, left out)\n", s.non_finite);
    fmt::print("  histogram\n");
    const std::size_t peak = std::max<std::size_t>(1, *std::max_element(h.counts.begin(), h.counts.end()));
    for (std::size_t i = 0; i < h.counts.size(); ++i) {
      const std::size_t bar = h.counts[i] == 0 ? 0 : std::max<std::size_t>(1, h.counts[i] * 40 / peak);
      fmt::print("    [{:>10.4g}, {:>10.4g}{} {:>11}  {}\n", h.edge(i), h.edge(i + 1),
                 i + 1 == h.counts.size() ? "]" : ")", h.counts[i], std::string(bar, '#'));
    }
    fmt::print("  Otsu isovalue {:.6g} (suggested: it best separates the two main classes of values)\n", otsu);
  }
  if (a.json.empty()) return;
  nlohmann::json j;
  j["file"] = a.file;
  j["dims"] = {v.dims[0], v.dims[1], v.dims[2]};
  j["points"] = v.size();
  j["spacing"] = vec_json(v.spacing);
  j["origin"] = vec_json(v.origin);
  j["max_corner"] = vec_json(v.max_corner());
  j["source_type"] = std::string(scalar_type_name(v.source_type));
  j["finite_values"] = s.count;
  j["non_finite_values"] = s.non_finite;
  if (s.count > 0) {
    j["min"] = s.min;
    j["max"] = s.max;
    j["mean"] = s.mean;
    j["otsu_isovalue"] = otsu;
    std::vector<double> edges;
    for (std::size_t i = 0; i <= h.counts.size(); ++i) edges.push_back(h.edge(i));
    j["histogram"] = {{"edges", edges}, {"counts", h.counts}};
  }
  write_json(a.json, j);
}

struct ConvertArgs {
  std::string in, out;
  bool as_float = false;
  VolumeReadArgs read;
};

void run_convert(const ConvertArgs& a) {
  Volume v = read_volume(a.in, a.read.options());
  if (a.as_float) v.source_type = ScalarType::f32;
  write_volume(a.out, v);
  fmt::print("{} -> {}: {} x {} x {} points, spacing {}, origin {}, {}\n", a.in, a.out, v.dims[0], v.dims[1], v.dims[2],
             vec_text(v.spacing), vec_text(v.origin), scalar_type_name(v.source_type));
}

}  // namespace

void register_volume(CLI::App& app) {
  CLI::App* volume =
      app.add_subcommand("volume", "Volumes: inspect and convert scans, make volumes of molecules and shapes");
  volume->require_subcommand(1);

  auto info = std::make_shared<InfoArgs>();
  CLI::App* cmd = volume->add_subcommand("info", "Dimensions, spacing, value statistics and a suggested isovalue");
  cmd->add_option("file", info->file,
                  "Volume (.nrrd .nhdr .mhd .mha .vtk .vti .nii .nii.gz, or .raw with --dims --type)")
      ->required();
  cmd->add_option("--json", info->json, "Also write the report as JSON");
  cmd->add_option("--bins", info->bins, "Histogram bins to print (default 16)")->check(CLI::Range(1, 4096));
  info->read.add_to(cmd);
  cmd->callback([info] { run_info(*info); });

  auto convert = std::make_shared<ConvertArgs>();
  cmd = volume->add_subcommand("convert", "Convert a volume to .nrrd or .vti");
  cmd->add_option("in", convert->in, "Input volume (any readable format)")->required();
  cmd->add_option("out", convert->out, "Output volume: .nrrd (raw, little endian) or .vti (appended raw)")->required();
  cmd->add_flag("--float", convert->as_float, "Store float32 values (default: the source type when it holds them)");
  convert->read.add_to(cmd);
  cmd->callback([convert] { run_convert(*convert); });

  register_volume_molecule(*volume);
  register_volume_shape(*volume);
}

}  // namespace isohex::cli
