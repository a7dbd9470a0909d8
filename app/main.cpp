// isohex command-line tool: one subcommand per stage.
#include "commands.hpp"

#include "isohex/error.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <malloc.h>
#include <exception>

namespace isohex::cli {
int& exit_code() {
  static int code = 0;
  return code;
}
}  // namespace isohex::cli

int main(int argc, char** argv) {
  // Arrays of 1 MiB and more always mapped apart and returned when freed: glibc's threshold
  // otherwise rises each time such an array is freed, later ones come from the heap, and its
  // high-water mark stays (cthead h 2's peak 168 -> 161 MiB, the same time).
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  CLI::App app{"isohex: all-hexahedral meshes from volumes, with verified element quality"};
  app.set_version_flag("--version", "isohex 0.1.0");
  app.require_subcommand(1);
  isohex::cli::register_quality(app);
  isohex::cli::register_check(app);
  isohex::cli::register_convert(app);
  isohex::cli::register_cut(app);
  isohex::cli::register_generate(app);
  isohex::cli::register_mesh(app);
  isohex::cli::register_pillow(app);
  isohex::cli::register_refine(app);
  isohex::cli::register_sheets(app);
  isohex::cli::register_smooth(app);
  isohex::cli::register_volume(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every bad option gives the documented 2 (CLI11's own codes
    // run from 100 up, one per kind of fault).
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const isohex::Error& e) {
    fmt::print(stderr, "isohex: error: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "isohex: internal error: {}\n", e.what());
    return 3;
  }
  return isohex::cli::exit_code();
}
