#pragma once
// The two routes of io::parseModelJson (src/io/json.cpp), for tests. Private to the library.
#include <filesystem>
#include <optional>
#include <string_view>

#include "seam/core/result.h"
#include "seam/model/model.h"

namespace seam::io::detail {

/// The fast route: simdjson's DOM through the same converter. std::nullopt when it declines: anything that is not
/// a valid model (a syntax error, a number that overflows a double, an integer beyond 64 bits, a \u escape, any
/// validation failure), so that every message comes from the nlohmann route.
std::optional<Model> parseModelJsonFast(std::string_view text, std::string_view source);
/// The streamed route of readModelJson (its first): the file read forward in chunks, each element of "patches" and
/// "curves" parsed alone (simdjson) and converted at once, so that neither the whole text nor a document of it is
/// held. std::nullopt when it declines: anything the fast route declines, and a repeated or unknown top-level key.
std::optional<Model> readModelJsonStreamed(const std::filesystem::path& file, std::string_view source);
/// The nlohmann route: nlohmann's DOM and the converter; every message of the format's checks.
Result<Model> parseModelJsonNlohmann(std::string_view text, std::string_view source);

}  // namespace seam::io::detail
