#pragma once
// The seam JSON model format (docs/format.md, schema docs/model.schema.json).
#include <filesystem>
#include <string>
#include <string_view>

#include "seam/core/result.h"
#include "seam/model/model.h"

namespace seam::io {

/// Parses a model from JSON text. `source` names the input in messages ("model.json: patch \"S2\": ...").
Result<Model> parseModelJson(std::string_view text, std::string_view source);
/// The checks parseModelJson makes before parsing, for other readers of model JSON (expression models): no NUL
/// byte, arrays and objects nested at most 256 deep (a model needs 6; nlohmann's printing recurses once per level).
/// kInvalidInput naming `source`, the line and the column otherwise.
Status checkJsonText(std::string_view text, std::string_view source);
/// nlohmann's exception text without its "[json.exception.parse_error.101] " prefix, for messages to the user.
std::string jsonExceptionText(const char* what);
/// Reads and parses a JSON model file.
Result<Model> readModelJson(const std::filesystem::path& file);
/// JSON text of the model; doubles are printed with round-trip precision (read back bit-identical).
std::string modelToJson(const Model& model);
/// Writes modelToJson(model) atomically (temporary file in the same folder + rename).
Status writeModelJson(const Model& model, const std::filesystem::path& file);

}  // namespace seam::io
