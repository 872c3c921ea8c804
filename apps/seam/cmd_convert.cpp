// seam convert IN OUT: converts a model between JSON, .bpt (read only), STEP and IGES, by extension.
// STEP/IGES need OpenCASCADE (SEAM_WITH_OCCT=ON). The input is never modified; the output is written atomically.
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <string>

#include "cli_util.h"
#include "command_registry.h"

namespace seam::cli {

namespace {

void addConvert(CLI::App& app, int& exit) {
  struct Options {
    std::string in, out;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "convert", "Convert a model between .json, .bpt (input only), .step/.stp and .iges/.igs (by extension)");
  cmd->add_option("IN", options->in, "Input model file")->required();
  cmd->add_option("OUT", options->out, "Output file (.json, .step/.stp, .iges/.igs)")->required();
  cmd->callback([options, &exit]() {
    const std::filesystem::path in(options->in), out(options->out);
    if (!checkOutputPath(in, out)) {
      exit = kExitBadInput;
      return;
    }
    const std::string ext = lowerExtension(out);
    if (ext != ".json" && !isCadFile(out)) {
      printError(fmt::format("{}: unknown output format (use .json, .step/.stp or .iges/.igs)", out.string()));
      exit = kExitBadInput;
      return;
    }
    const std::optional<Model> model = loadModel(in);
    if (!model) {
      exit = kExitBadInput;
      return;
    }
    if (!saveModel(*model, out)) {
      exit = kExitBadInput;
      return;
    }
    fmt::print("wrote {} ({} patches, {} curves)\n", out.string(), model->patches.size(), model->curves.size());
    exit = kExitOk;
  });
}

}  // namespace

static CommandRegistrar registerConvert("convert", addConvert);

}  // namespace seam::cli
