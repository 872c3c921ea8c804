#include "seam/io/bpt.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include "seam/io/file.h"

namespace seam::io {

namespace {

/// One non-blank line of the file, split into whitespace-separated tokens, with its 1-based line number.
struct Line {
  int number = 0;
  std::vector<std::string_view> tokens;
};

/// Splits `text` into non-blank lines (LF, CRLF or lone CR endings) of whitespace-separated tokens.
std::vector<Line> tokenize(std::string_view text) {
  std::vector<Line> lines;
  int number = 1;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find_first_of("\r\n", pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view content = text.substr(pos, end - pos);
    Line line{number, {}};
    size_t i = 0;
    while (i < content.size()) {
      while (i < content.size() && (content[i] == ' ' || content[i] == '\t')) ++i;
      const size_t start = i;
      while (i < content.size() && content[i] != ' ' && content[i] != '\t') ++i;
      if (i > start) line.tokens.push_back(content.substr(start, i - start));
    }
    if (!line.tokens.empty()) lines.push_back(std::move(line));
    // Consume one line ending: "\r\n", "\n" or "\r".
    if (end + 1 < text.size() && text[end] == '\r' && text[end + 1] == '\n') ++end;
    pos = end + 1;
    ++number;
  }
  return lines;
}

bool parseInt(std::string_view token, long long& out) {
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), out);
  return ec == std::errc() && ptr == token.data() + token.size();
}

/// Parses a finite double; rejects trailing characters, NaN, infinities and out-of-range literals.
bool parseFinite(std::string_view token, double& out) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-')
    token.remove_prefix(1);  // from_chars rejects '+'
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), out);
  return ec == std::errc() && ptr == token.data() + token.size() && std::isfinite(out);
}

std::string quoted(const Line& line) {
  std::string s;
  for (const std::string_view t : line.tokens) {
    if (!s.empty()) s += ' ';
    s += t;
  }
  return "\"" + s + "\"";
}

/// Bezier knots on [0,1]: degree+1 zeros, then degree+1 ones.
std::vector<double> bezierKnots(int degree) {
  std::vector<double> knots(static_cast<size_t>(2 * (degree + 1)), 0.0);
  for (size_t k = knots.size() / 2; k < knots.size(); ++k) knots[k] = 1.0;
  return knots;
}

}  // namespace

Result<Model> parseBpt(std::string_view text, std::string_view source) {
  const std::string src(source);
  const std::vector<Line> lines = tokenize(text);
  auto fail = [&](const std::string& problem) { return Result<Model>(invalidInput(src + ": " + problem)); };
  auto at = [&](const Line& line) { return "line " + std::to_string(line.number) + ": "; };

  if (lines.empty()) return fail("empty file (expected the number of patches on the first line)");
  long long count = 0;
  if (lines[0].tokens.size() != 1 || !parseInt(lines[0].tokens[0], count) || count < 0) {
    return fail(at(lines[0]) + "expected the number of patches (a non-negative integer), found " +
                quoted(lines[0]));
  }

  Model model;
  size_t next = 1;
  for (long long index = 0; index < count; ++index) {
    const std::string name = fmt::format("P{}", index);
    const std::string where = "patch " + name + ": ";
    if (next >= lines.size()) {
      return fail("file ends after " + std::to_string(index) + " of " + std::to_string(count) +
                  " patches (the first line announces " + std::to_string(count) + ")");
    }
    const Line& header = lines[next++];
    long long du = 0;
    long long dv = 0;
    if (header.tokens.size() != 2 || !parseInt(header.tokens[0], du) || !parseInt(header.tokens[1], dv)) {
      return fail(where + at(header) + "expected the degrees \"du dv\" (two integers), found " +
                  quoted(header));
    }
    if (du < 1 || dv < 1) {
      return fail(where + at(header) + "degrees " + std::to_string(du) + " " + std::to_string(dv) +
                  ": both must be at least 1");
    }
    // Check that the file can hold the points before allocating anything of that size.
    const size_t remaining = lines.size() - next;
    if (static_cast<unsigned long long>(du) + 1 > remaining ||
        static_cast<unsigned long long>(dv) + 1 > remaining ||
        static_cast<unsigned long long>(du + 1) * static_cast<unsigned long long>(dv + 1) > remaining) {
      return fail(where + "file ends before the " + std::to_string(du + 1) + " x " + std::to_string(dv + 1) +
                  " control points of degree " + std::to_string(du) + " " + std::to_string(dv) + " (only " +
                  std::to_string(remaining) + " lines left)");
    }
    const int nu = static_cast<int>(du) + 1;
    const int nv = static_cast<int>(dv) + 1;
    Matrix points(nu * nv, 3);
    for (int k = 0; k < nu * nv; ++k) {
      const Line& line = lines[next++];
      if (line.tokens.size() != 3) {
        return fail(where + at(line) + "expected a point \"x y z\" (3 numbers), found " + quoted(line));
      }
      for (int c = 0; c < 3; ++c) {
        double value = 0.0;
        if (!parseFinite(line.tokens[static_cast<size_t>(c)], value)) {
          return fail(where + at(line) + "\"" + std::string(line.tokens[static_cast<size_t>(c)]) +
                      "\" is not a finite number");
        }
        points(k, c) = value;
      }
    }
    const int pu = static_cast<int>(du);
    const int pv = static_cast<int>(dv);
    Result<BSplineSurface> surface =
        BSplineSurface::create(pu, pv, bezierKnots(pu), bezierKnots(pv), nu, nv, std::move(points));
    if (!surface) return Result<Model>(surface.status().withContext(src + ": patch " + name));
    model.patches.push_back(Patch{name, PatchKind::kBezier, std::move(surface).value()});
  }
  if (next < lines.size()) {
    return fail(at(lines[next]) + "unexpected content after the last of the " + std::to_string(count) +
                " patches: " + quoted(lines[next]));
  }
  return model;
}

Result<Model> readBpt(const std::filesystem::path& file) {
  Result<std::string> text = readFile(file);
  if (!text) return text.status();
  return parseBpt(*text, file.string());
}

}  // namespace seam::io
