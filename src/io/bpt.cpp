#include "seam/io/bpt.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <limits>
#include <cmath>
#include <string>
#include <vector>

#include "seam/io/file.h"

namespace seam::io {

namespace {

/// Largest degree read from a file: degrees are stored as int, and degree + 1 (the points it needs) must fit too.
constexpr long long kMaxDegree = std::numeric_limits<int>::max() - 1;

/// One whitespace-separated token of the file with its 1-based line number.
struct Token {
  std::string_view text;
  int line = 0;
  bool startsLine = false;  ///< the first token of its line
  int tokensOnLine = 0;     ///< how many tokens its line holds
};

/// Splits `text` into tokens (separated by spaces, tabs and LF, CRLF or lone CR line endings); '#' starts a comment
/// that runs to the end of its line.
std::vector<Token> tokenize(std::string_view text) {
  std::vector<Token> tokens;
  int number = 1;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find_first_of("\r\n", pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view content = text.substr(pos, end - pos);
    content = content.substr(0, std::min(content.size(), content.find('#')));
    const size_t first = tokens.size();
    size_t i = 0;
    while (i < content.size()) {
      while (i < content.size() && (content[i] == ' ' || content[i] == '\t')) ++i;
      const size_t start = i;
      while (i < content.size() && content[i] != ' ' && content[i] != '\t') ++i;
      if (i > start) tokens.push_back(Token{content.substr(start, i - start), number, tokens.size() == first, 0});
    }
    for (size_t k = first; k < tokens.size(); ++k) tokens[k].tokensOnLine = static_cast<int>(tokens.size() - first);
    // Consume one line ending: "\r\n", "\n" or "\r".
    if (end + 1 < text.size() && text[end] == '\r' && text[end + 1] == '\n') ++end;
    pos = end + 1;
    ++number;
  }
  return tokens;
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

/// Tokens quoted in a message at most (a file on one line would otherwise be quoted whole).
constexpr size_t kMaxQuotedTokens = 6;

/// The tokens of `token`'s line, starting at `token` (for messages; at most kMaxQuotedTokens, then "...").
std::string quotedLine(const std::vector<Token>& tokens, size_t k) {
  std::string s;
  for (size_t i = k; i < tokens.size() && tokens[i].line == tokens[k].line; ++i) {
    if (i - k == kMaxQuotedTokens) {
      s += " ...";
      break;
    }
    if (!s.empty()) s += ' ';
    s += tokens[i].text;
  }
  return "\"" + s + "\"";
}

/// Bezier knots on [0,1]: degree+1 zeros, then degree+1 ones.
std::vector<double> bezierKnots(int degree) {
  std::vector<double> knots(static_cast<size_t>(2 * (degree + 1)), 0.0);
  for (size_t k = knots.size() / 2; k < knots.size(); ++k) knots[k] = 1.0;
  return knots;
}

/// Where the degrees of the patches are.
enum class Layout {
  kPerPatch,      ///< "du dv" before the points of every patch (the Newell files)
  kSharedDegree,  ///< one "du dv" after the patch count, for every patch
};

/// The outcome of reading the tokens in one layout: the model, or the message and how far the reading got (the
/// index of the token where it failed), so that the better of two failed readings can be reported.
struct Attempt {
  Result<Model> model = Status(ErrorCode::kInvalidInput, "not read");
  size_t reached = 0;
};

class BptReader {
 public:
  BptReader(const std::vector<Token>& tokens, std::string src, long long count)
      : tokens_(tokens), src_(std::move(src)), count_(count) {}

  Attempt read(Layout layout) {
    Attempt a;
    a.model = readImpl(layout);
    a.reached = next_;
    return a;
  }

 private:
  Status fail(const std::string& problem) const { return invalidInput(src_ + ": " + problem); }
  static std::string at(const Token& t) { return "line " + std::to_string(t.line) + ": "; }

  /// Reads "du dv" at next_ into du, dv and checks them.
  Status readDegrees(const std::string& where, long long& du, long long& dv) {
    if (next_ >= tokens_.size()) return fail(where + "file ends before the degrees \"du dv\"");
    const Token& first = tokens_[next_];
    const bool two = next_ + 1 < tokens_.size();
    if (!two || !parseInt(first.text, du) || !parseInt(tokens_[next_ + 1].text, dv)) {
      return fail(where + at(first) + "expected the degrees \"du dv\" (two integers), found " +
                  quotedLine(tokens_, next_));
    }
    // A line holding only the degrees (the usual layout) must hold exactly two tokens.
    if (first.startsLine && first.tokensOnLine < 2) {
      return fail(where + at(first) + "expected the degrees \"du dv\" (two integers), found " +
                  quotedLine(tokens_, next_));
    }
    if (du < 1 || dv < 1) {
      return fail(where + at(first) + "degrees " + std::to_string(du) + " " + std::to_string(dv) +
                  ": both must be at least 1");
    }
    if (du > kMaxDegree || dv > kMaxDegree) {
      return fail(where + at(first) + "degrees " + std::to_string(du) + " " + std::to_string(dv) +
                  ": too large (at most " + std::to_string(kMaxDegree) + ")");
    }
    next_ += 2;
    return Status::ok();
  }

  Result<Model> readImpl(Layout layout) {
    next_ = 1;
    long long du = 0;
    long long dv = 0;
    if (layout == Layout::kSharedDegree) {
      if (Status s = readDegrees("shared degrees: ", du, dv); !s) return s;
    }
    Model model;
    for (long long index = 0; index < count_; ++index) {
      const std::string name = fmt::format("P{}", index);
      const std::string where = "patch " + name + ": ";
      if (next_ >= tokens_.size()) {
        return fail("file ends after " + std::to_string(index) + " of " + std::to_string(count_) +
                    " patches (the first line announces " + std::to_string(count_) + ")");
      }
      if (layout == Layout::kPerPatch) {
        if (Status s = readDegrees(where, du, dv); !s) return s;
      }
      // The points are read one by one, so that a malformed line is reported where it is; nothing of the size
      // the degrees announce is allocated before the file is seen to hold it (du, dv <= kMaxDegree: no overflow).
      const unsigned long long numbers = 3ULL * static_cast<unsigned long long>(du + 1) *
                                         static_cast<unsigned long long>(dv + 1);
      const size_t remaining = tokens_.size() - next_;
      const auto fileEnds = [&] {
        return fail(where + "file ends before the " + std::to_string(du + 1) + " x " + std::to_string(dv + 1) +
                    " control points of degree " + std::to_string(du) + " " + std::to_string(dv) + " (only " +
                    std::to_string(remaining) + " numbers left, " + std::to_string(numbers) + " needed)");
      };
      std::vector<double> values;
      values.reserve(static_cast<size_t>(std::min<unsigned long long>(numbers, remaining)));
      for (unsigned long long k = 0; k < numbers; k += 3) {
        if (next_ >= tokens_.size()) return fileEnds();
        const Token& first = tokens_[next_];
        // A point that starts a line: the line must hold whole points (one "x y z", or several).
        if (first.startsLine && first.tokensOnLine % 3 != 0) {
          return fail(where + at(first) + "expected a point \"x y z\" (3 numbers), found " +
                      quotedLine(tokens_, next_));
        }
        for (int c = 0; c < 3; ++c) {
          if (next_ >= tokens_.size()) return fileEnds();
          const Token& t = tokens_[next_];
          double value = 0.0;
          if (!parseFinite(t.text, value)) {
            return fail(where + at(t) + "\"" + std::string(t.text) + "\" is not a finite number");
          }
          values.push_back(value);
          ++next_;
        }
      }
      const int nu = static_cast<int>(du) + 1;
      const int nv = static_cast<int>(dv) + 1;
      Matrix points(nu * nv, 3);
      for (int k = 0; k < nu * nv; ++k) {
        for (int c = 0; c < 3; ++c) points(k, c) = values[static_cast<size_t>(3 * k + c)];
      }
      const int pu = static_cast<int>(du);
      const int pv = static_cast<int>(dv);
      Result<BSplineSurface> surface =
          BSplineSurface::create(pu, pv, bezierKnots(pu), bezierKnots(pv), nu, nv, std::move(points));
      if (!surface) return Result<Model>(surface.status().withContext(src_ + ": patch " + name));
      model.patches.push_back(Patch{name, PatchKind::kBezier, std::move(surface).value()});
    }
    if (next_ < tokens_.size()) {
      return fail(at(tokens_[next_]) + "unexpected content after the last of the " + std::to_string(count_) +
                  " patches: " + quotedLine(tokens_, next_));
    }
    return model;
  }

  const std::vector<Token>& tokens_;
  std::string src_;
  long long count_ = 0;
  size_t next_ = 1;  ///< the next token to read
};

/// True when the token count fits the shared-degree layout: N, du, dv, then N (du+1)(dv+1) points.
bool fitsSharedDegree(const std::vector<Token>& tokens, long long count) {
  long long du = 0;
  long long dv = 0;
  if (tokens.size() < 3 || !parseInt(tokens[1].text, du) || !parseInt(tokens[2].text, dv)) return false;
  if (du < 1 || dv < 1 || du > kMaxDegree || dv > kMaxDegree || count < 1) return false;
  const unsigned long long perPatch =
      3ULL * static_cast<unsigned long long>(du + 1) * static_cast<unsigned long long>(dv + 1);
  const unsigned long long numbers = tokens.size() - 3;
  return numbers % perPatch == 0 && numbers / perPatch == static_cast<unsigned long long>(count);
}

}  // namespace

Result<Model> parseBpt(std::string_view text, std::string_view source) {
  const std::string src(source);
  const std::vector<Token> tokens = tokenize(text);
  if (tokens.empty()) {
    return invalidInput(src + ": empty file (expected the number of patches on the first line)");
  }
  long long count = 0;
  if (!parseInt(tokens[0].text, count) || count < 0) {
    return invalidInput(src + ": line " + std::to_string(tokens[0].line) +
                        ": expected the number of patches (a non-negative integer), found " +
                        quotedLine(tokens, 0));
  }
  // The per-patch layout first (the Newell files); when it fails and the token count fits one shared degree pair,
  // the shared layout. When neither reads, the message of the reading that got further.
  BptReader reader(tokens, src, count);
  Attempt perPatch = reader.read(Layout::kPerPatch);
  if (perPatch.model || !fitsSharedDegree(tokens, count)) return std::move(perPatch.model);
  Attempt shared = reader.read(Layout::kSharedDegree);
  if (shared.model || shared.reached > perPatch.reached) return std::move(shared.model);
  return std::move(perPatch.model);
}

Result<Model> readBpt(const std::filesystem::path& file) {
  Result<std::string> text = readFile(file);
  if (!text) return text.status();
  return parseBpt(*text, file.string());
}

}  // namespace seam::io
