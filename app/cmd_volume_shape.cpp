// PLACEHOLDER: replaced by the real command.
#include "commands.hpp"
namespace isohex::cli { void register_volume_shape(CLI::App&) {} }
