// seam convert IN OUT: converts a model between JSON, .bpt (read only), STEP and IGES, by extension.
// STEP/IGES need OpenCASCADE (SEAM_WITH_OCCT=ON). The input is never modified; the output is written
// atomically. STEP/IGES -> STEP/IGES keeps the whole B-rep (occt::convertCadFile); STEP/IGES -> JSON keeps
// the trims in the JSON's "brep" (Model::brep), and a JSON with "brep" -> STEP/IGES writes that B-rep
// (occt::writeBRepCadFile). A trimmed model without its topology is refused with exit 2 by every patch-only
// output (Model::trimmedFaces).
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "cli_util.h"
#include "command_registry.h"
#include "seam/io/file.h"
#include "seam/model/brep.h"
#ifdef SEAM_HAVE_OCCT
#include "seam/occt/brep_model.h"
#include "seam/occt/cad_io.h"
#endif

namespace seam::cli {

namespace {

void addConvert(CLI::App& app, int& exit) {
  struct Options {
    std::string in, out;
    bool noSeamCheck = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "convert", "Convert a model between .json, .bpt (input only), .step/.stp and .iges/.igs (by extension)");
  cmd->add_option("IN", options->in, "Input model file")->required();
  cmd->add_option("OUT", options->out, "Output file (.json, .step/.stp, .iges/.igs)")->required();
  cmd->add_flag("--no-seam-check", options->noSeamCheck,
                "STEP/IGES -> STEP/IGES: do not check the seams of the input and of the written file (by default "
                "every seam that the round trip through OpenCASCADE's writer and reader makes worse is named in a "
                "warning)");
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
    if (isCadFile(in) && isCadFile(out)) {
      // STEP/IGES -> STEP/IGES keeps the B-rep: every face, trim, edge, shell and solid, names and colours.
#ifdef SEAM_HAVE_OCCT
      if (!checkInputPath(in)) return;
      Result<occt::CadConvertReport> r = [&] {
        const CadTimeLimit limit(in, "converting");
        occt::CadConvertOptions convert;
        convert.compareSeams = !options->noSeamCheck;
        return occt::convertCadFile(in, out, {}, convert);
      }();
      if (!r) {
        printError(r.status().message());
        exit = kExitBadInput;
        return;
      }
      for (const std::string& w : r->warnings) std::cerr << "seam: warning: " << w << "\n";
      for (const std::string& w : r->seamsWorse) std::cerr << "seam: warning: " << w << "\n";
      fmt::print("wrote {} (B-rep kept: {} faces, {} of them trimmed, {} edges, {} shells, {} solids; area {} mm²; "
                 "unit {})\n",
                 out.string(), r->faces, r->trimmedFaces, r->edges, r->shells, r->solids, formatNumber(r->area),
                 r->writtenUnit);
      if (r->seamsCompared >= 0)
        fmt::print("seams read back from {}: {}, {} of them worse than in the input{}\n", out.filename().string(),
                   r->seamsCompared, r->seamsWorse.size(), r->seamsWorse.empty() ? "" : " (warnings above)");
      exit = kExitOk;
      return;
#endif
    }
    const std::optional<Model> model = loadModel(in);
    if (!model) {
      exit = kExitBadInput;
      return;
    }
#ifdef SEAM_HAVE_OCCT
    if (model->brep && isCadFile(out)) {
      // A model with its trims (JSON "brep", docs/format.md): the B-rep is made again and written through
      // XDE.
      if (Status st = io::checkOutputFile(out); !st) {
        printError(st.message());
        exit = kExitBadInput;
        return;
      }
      Result<occt::BRepWriteReport> r = [&] {
        const CadTimeLimit limit(in, "writing");
        return occt::writeBRepCadFile(*model, out, *occt::cadFormatOf(out));
      }();
      if (!r) {
        printError(r.status().message());
        exit = kExitBadInput;
        return;
      }
      for (const std::string& w : r->warnings) std::cerr << "seam: warning: " << w << "\n";
      fmt::print(
          "wrote {} (B-rep kept: {} faces, {} of them trimmed, {} edges, {} shells, {} solids; area {} "
          "mm²)\n",
          out.string(), r->faces, r->trimmedFaces, r->edges, r->shells, r->solids, formatNumber(r->area));
      exit = kExitOk;
      return;
    }
#endif
    if (!saveModel(*model, out)) {
      exit = kExitBadInput;
      return;
    }
    if (model->brep && lowerExtension(out) == ".json")
      fmt::print("wrote {} ({} patches, {} curves; B-rep kept: {} faces, {} of them trimmed)\n", out.string(),
                 model->patches.size(), model->curves.size(), model->brep->faces.size(), model->trimmedFaces);
    else
      fmt::print("wrote {} ({} patches, {} curves)\n", out.string(), model->patches.size(),
                 model->curves.size());
    exit = kExitOk;
  });
}

}  // namespace

static CommandRegistrar registerConvert("convert", addConvert);

}  // namespace seam::cli
