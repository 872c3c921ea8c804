// Expression patches through GiNaC; see include/seam/rational/expression.h.
#include "seam/rational/expression.h"

#include <fmt/format.h>
#include <ginac/ginac.h>

#include <cctype>
#include <cmath>
#include <string_view>
#include <vector>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>

#include "seam/io/file.h"
#include "seam/io/json.h"

namespace seam::rational {

namespace {

const std::set<std::string>& allowedFunctions() {
  static const std::set<std::string> f{"sin", "cos", "exp", "log"};  // sqrt parses to a power
  return f;
}

/// Numeric value of a GiNaC expression in the symbols u, v: a direct walk of the expression tree (sums, products,
/// powers, the allowed functions, numbers, pi), much faster than subs + evalf.
class TreeEvaluator {
 public:
  TreeEvaluator(const GiNaC::symbol& u, const GiNaC::symbol& v) : u_(u), v_(v) {}
  double operator()(const GiNaC::ex& e, double u, double v) const {
    using namespace GiNaC;
    if (is_a<numeric>(e)) {
      const numeric& n = ex_to<numeric>(e);
      return n.is_real() ? n.to_double() : std::nan("");
    }
    if (is_a<symbol>(e)) {
      if (e.is_equal(u_)) return u;
      if (e.is_equal(v_)) return v;
      return std::nan("");
    }
    if (is_a<add>(e)) {
      double s = 0.0;
      for (size_t i = 0; i < e.nops(); ++i) s += (*this)(e.op(i), u, v);
      return s;
    }
    if (is_a<mul>(e)) {
      double s = 1.0;
      for (size_t i = 0; i < e.nops(); ++i) s *= (*this)(e.op(i), u, v);
      return s;
    }
    if (is_a<power>(e)) {
      const double b = (*this)(e.op(0), u, v);
      const ex& x = e.op(1);
      if (is_a<numeric>(x) && ex_to<numeric>(x).is_integer()) {
        const long k = ex_to<numeric>(x).to_long();
        double r = 1.0, base = k >= 0 ? b : 1.0 / b;
        for (long m = std::labs(k); m > 0; m >>= 1) {
          if (m & 1) r *= base;
          base *= base;
        }
        return r;
      }
      return std::pow(b, (*this)(x, u, v));
    }
    if (is_a<function>(e)) {
      const std::string name = ex_to<function>(e).get_name();
      const double a = (*this)(e.op(0), u, v);
      if (name == "sin") return std::sin(a);
      if (name == "cos") return std::cos(a);
      if (name == "exp") return std::exp(a);
      if (name == "log") return std::log(a);
      return std::nan("");
    }
    if (is_a<constant>(e)) return ex_to<numeric>(e.evalf()).to_double();
    return std::nan("");
  }

 private:
  GiNaC::symbol u_, v_;
};

/// Shared state of a compiled expression surface: the symbols, the four coordinates and their derivatives, formed
/// on demand (d[a][b][k] = d^{a+b} coordinate k / du^a dv^b).
struct ExpressionState {
  GiNaC::symbol u{"u"}, v{"v"};
  std::string name;
  std::vector<std::vector<std::array<GiNaC::ex, 4>>> d;  // d[a][b], filled for a + b <= formed
  int formed = 0;
  std::mutex mutex;

  void formUpTo(int order) {
    std::lock_guard<std::mutex> lock(mutex);
    for (int n = formed + 1; n <= order; ++n) {
      d.resize(static_cast<size_t>(n + 1));
      for (int a = 0; a <= n; ++a) {
        auto& row = d[static_cast<size_t>(a)];
        row.resize(static_cast<size_t>(n - a + 1));
        const int b = n - a;
        for (int k = 0; k < 4; ++k)
          row[static_cast<size_t>(b)][static_cast<size_t>(k)] =
              b > 0 ? d[static_cast<size_t>(a)][static_cast<size_t>(b - 1)][static_cast<size_t>(k)].diff(v)
                    : d[static_cast<size_t>(a - 1)][0][static_cast<size_t>(k)].diff(u);
      }
      formed = n;
    }
  }
};

const char* kCoordinateNames[4] = {"x", "y", "z", "w"};

/// Refuses, before GiNaC sees it, an expression GiNaC cannot take in bounded time and stack: longer than
/// kMaxExpressionChars, nested deeper than kMaxExpressionNesting (parentheses and unary signs: GiNaC's
/// recursive-descent parser overflows the stack at about 10 000 levels), or with function calls nested deeper than
/// kMaxFunctionNesting (the symbolic derivatives swell: sin nested 100 deep ran for more than a minute).
Status checkExpressionSize(std::string_view text, const std::string& where) {
  if (text.size() > kMaxExpressionChars)
    return invalidInput(fmt::format("{}: the expression has {} characters, more than the {} accepted", where,
                                    text.size(), kMaxExpressionChars));
  // Stack of open parentheses (true: a function call's), and the current run of unary signs.
  std::vector<bool> open;
  int functions = 0, signs = 0;
  char previous = '(';  // a sign at the start is unary
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    if (c == '(') {
      const bool call = std::isalnum(static_cast<unsigned char>(previous)) || previous == '_';
      open.push_back(call);
      functions += call ? 1 : 0;
    } else if (c == ')') {
      if (!open.empty()) {
        functions -= open.back() ? 1 : 0;
        open.pop_back();
      }
    }
    const bool unary = (c == '-' || c == '+') && (previous == '(' || previous == '-' || previous == '+' ||
                                                  previous == '*' || previous == '/' || previous == '^' ||
                                                  previous == ',');
    signs = unary ? signs + 1 : 0;
    if (static_cast<int>(open.size()) + signs > kMaxExpressionNesting)
      return invalidInput(fmt::format("{}: parentheses or signs nested more than {} deep (at character {})", where,
                                      kMaxExpressionNesting, i + 1));
    if (functions > kMaxFunctionNesting)
      return invalidInput(fmt::format("{}: function calls nested more than {} deep (at character {}); the symbolic "
                                      "derivatives would not finish",
                                      where, kMaxFunctionNesting, i + 1));
    previous = c;
  }
  return Status::ok();
}

}  // namespace

Result<HomogeneousSurface> compileExpressionPatch(const ExpressionPatch& patch) {
  auto st = std::make_shared<ExpressionState>();
  st->name = patch.name;
  GiNaC::symtab table;
  table["u"] = st->u;
  table["v"] = st->v;
  table["pi"] = GiNaC::Pi;
  GiNaC::parser reader(table, /*strict=*/true);
  st->d.resize(1);
  st->d[0].resize(1);
  for (int k = 0; k < 4; ++k) {
    const std::string where = fmt::format("expression patch \"{}\": {} = \"{}\"", patch.name, kCoordinateNames[k],
                                          patch.homogeneous[static_cast<size_t>(k)]);
    if (Status size = checkExpressionSize(patch.homogeneous[static_cast<size_t>(k)],
                                          fmt::format("expression patch \"{}\": {}", patch.name, kCoordinateNames[k]));
        !size)
      return size;
    GiNaC::ex e;
    try {
      e = reader(patch.homogeneous[static_cast<size_t>(k)]);
    } catch (const std::exception& ex) {
      return invalidInput(fmt::format("{}: cannot parse ({}); allowed: numbers, u, v, pi, + - * / ^, sin, cos, exp, "
                                      "log, sqrt", where, ex.what()));
    }
    for (auto it = e.preorder_begin(); it != e.preorder_end(); ++it) {
      if (GiNaC::is_a<GiNaC::function>(*it)) {
        const std::string fn = GiNaC::ex_to<GiNaC::function>(*it).get_name();
        if (!allowedFunctions().count(fn))
          return invalidInput(fmt::format("{}: function \"{}\" is not supported (allowed: sin, cos, exp, log, sqrt)",
                                          where, fn));
      } else if (GiNaC::is_a<GiNaC::numeric>(*it) && !GiNaC::ex_to<GiNaC::numeric>(*it).is_real()) {
        return invalidInput(fmt::format("{}: complex numbers are not supported", where));
      }
    }
    st->d[0][0][static_cast<size_t>(k)] = e;
  }
  if (!(patch.u.length() > 0.0) || !(patch.v.length() > 0.0) || !std::isfinite(patch.u.length()) ||
      !std::isfinite(patch.v.length()))
    return invalidInput(fmt::format("expression patch \"{}\": the domain [[{}, {}], [{}, {}]] is empty or not finite",
                                    patch.name, patch.u.lo, patch.u.hi, patch.v.lo, patch.v.hi));
  HomogeneousSurface::Evaluator ev = [st](double u, double v, int order) -> Result<DerivativeTable> {
    st->formUpTo(order);
    const TreeEvaluator eval(st->u, st->v);
    DerivativeTable out(static_cast<size_t>(order + 1));
    for (int a = 0; a <= order; ++a) {
      out[static_cast<size_t>(a)].resize(static_cast<size_t>(order - a + 1));
      for (int b = 0; a + b <= order; ++b) {
        Vec4 x;
        for (int k = 0; k < 4; ++k)
          x[k] = eval(st->d[static_cast<size_t>(a)][static_cast<size_t>(b)][static_cast<size_t>(k)], u, v);
        if (!x.allFinite())
          return invalidInput(fmt::format("expression patch \"{}\": derivative ({}, {}) is not finite at (u, v) = "
                                          "({}, {})", st->name, a, b, u, v));
        out[static_cast<size_t>(a)][static_cast<size_t>(b)] = x;
      }
    }
    return out;
  };
  // Check that the surface evaluates at the domain's centre (catches e.g. log(-1) everywhere early).
  HomogeneousSurface s(patch.name, patch.u, patch.v, kMaxExpressionOrder, std::move(ev));
  if (auto p = s.derivatives(0.5 * (patch.u.lo + patch.u.hi), 0.5 * (patch.v.lo + patch.v.hi), 0); !p)
    return p.status();
  return s;
}

// ---------------------------------------------------------------------------------------------------------------
const ExpressionPatch* ModelWithExpressions::findExpression(const std::string& name) const {
  for (const ExpressionPatch& e : expressions)
    if (e.name == name) return &e;
  return nullptr;
}

namespace {

using Json = nlohmann::json;

std::string brief(const Json& j) {
  std::string s = j.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

Result<Interval> readRange(const Json& j, const std::string& where, const char* which) {
  if (!j.is_array() || j.size() != 2 || !j[0].is_number() || !j[1].is_number())
    return invalidInput(fmt::format("{}: \"domain\" {} range must be [lo, hi], found {}", where, which, brief(j)));
  const Interval r{j[0].get<double>(), j[1].get<double>()};
  if (!std::isfinite(r.lo) || !std::isfinite(r.hi) || !(r.hi > r.lo))
    return invalidInput(fmt::format("{}: \"domain\" {} range [{}, {}] must be finite with lo < hi", where, which,
                                    r.lo, r.hi));
  return r;
}

Result<ExpressionPatch> readExpression(const Json& j, const std::string& where) {
  ExpressionPatch e;
  e.name = j["name"].get<std::string>();
  for (const auto& [key, value] : j.items())
    if (key != "name" && key != "type" && key != "homogeneous" && key != "domain")
      return invalidInput(fmt::format("{}: unknown key \"{}\" for an expression patch (expected \"homogeneous\" and "
                                      "\"domain\")", where, key));
  if (!j.contains("homogeneous")) return invalidInput(where + ": missing \"homogeneous\" ([x, y, z] or [x, y, z, w])");
  const Json& h = j["homogeneous"];
  if (!h.is_array() || (h.size() != 3 && h.size() != 4))
    return invalidInput(fmt::format("{}: \"homogeneous\" must be an array of 3 or 4 expressions, found {}", where,
                                    brief(h)));
  for (size_t k = 0; k < h.size(); ++k) {
    if (h[k].is_string())
      e.homogeneous[k] = h[k].get<std::string>();
    else if (h[k].is_number())
      e.homogeneous[k] = fmt::format("{}", h[k].get<double>());
    else
      return invalidInput(fmt::format("{}: \"homogeneous\"[{}] must be a string (an expression in u and v), found {}",
                                      where, k, brief(h[k])));
  }
  if (h.size() == 3) e.homogeneous[3] = std::string(1, '1');
  if (j.contains("domain")) {
    const Json& d = j["domain"];
    if (!d.is_array() || d.size() != 2)
      return invalidInput(fmt::format("{}: \"domain\" must be [[u0, u1], [v0, v1]], found {}", where, brief(d)));
    auto u = readRange(d[0], where, "u");
    if (!u) return u.status();
    auto v = readRange(d[1], where, "v");
    if (!v) return v.status();
    e.u = *u;
    e.v = *v;
  }
  return e;
}

}  // namespace

Result<ModelWithExpressions> parseModelWithExpressions(std::string_view text, std::string_view source) {
  const std::string src(source);
  // The model reader's checks first (a NUL byte, nesting deeper than a model needs): nlohmann's dump() below
  // recurses once per level and would overflow the stack on a deeply nested text.
  if (Status st = io::checkJsonText(text, source); !st) return st;
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::parse_error&) {
    // Let the model reader produce its usual message (line and column).
    auto m = io::parseModelJson(text, source);
    if (!m) return m.status();
    return ModelWithExpressions{std::move(m).value(), {}};
  } catch (const Json::exception& e) {
    // A number literal that overflows a double (out_of_range.406, e.g. 1e1111111; found by fuzz_gcn, which it
    // crashed when only parse_error was caught). nlohmann's text names the literal.
    return Status(ErrorCode::kInvalidInput,
                  fmt::format("{}: not valid JSON: {}", src, io::jsonExceptionText(e.what())));
  }
  ModelWithExpressions out;
  if (root.is_object() && root.contains("patches") && root["patches"].is_array()) {
    Json kept = Json::array();
    size_t index = 0;
    for (const Json& p : root["patches"]) {
      const bool isExpression = p.is_object() && p.contains("type") && p["type"].is_string() &&
                                p["type"].get<std::string>() == "expression";
      if (!isExpression) {
        kept.push_back(p);
        ++index;
        continue;
      }
      std::string where = fmt::format("{}: patches[{}]", src, index);
      if (!p.contains("name") || !p["name"].is_string() || p["name"].get<std::string>().empty())
        return invalidInput(where + ": missing or empty \"name\"");
      where = fmt::format("{}: patch \"{}\"", src, p["name"].get<std::string>());
      auto e = readExpression(p, where);
      if (!e) return e.status();
      if (out.findExpression(e->name)) return invalidInput(where + ": duplicate name");
      auto compiled = compileExpressionPatch(*e);
      if (!compiled) return compiled.status().withContext(src);
      out.expressions.push_back(std::move(e).value());
      ++index;
    }
    root["patches"] = kept;
  }
  if (root.is_object() && root.contains("patches") && root["patches"].empty() && !root.contains("curves") &&
      !out.expressions.empty()) {
    // Only expression patches: nothing left for the spline reader.
    return out;
  }
  auto m = io::parseModelJson(root.dump(), source);
  if (!m) return m.status();
  out.model = std::move(m).value();
  for (const ExpressionPatch& e : out.expressions)
    if (out.model.findPatch(e.name))
      return invalidInput(fmt::format("{}: patch \"{}\": duplicate name (used by a spline patch and an expression "
                                      "patch)", src, e.name));
  return out;
}

Result<ModelWithExpressions> readModelWithExpressions(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".json") {
    auto m = io::readModel(file);
    if (!m) return m.status();
    return ModelWithExpressions{std::move(m).value(), {}};
  }
  auto text = io::readFile(file);
  if (!text) return text.status();
  return parseModelWithExpressions(*text, file.string());
}

}  // namespace seam::rational
