// Expression patches through GiNaC; see include/seam/rational/expression.h.
#include "seam/rational/expression.h"

#include <fmt/format.h>
#include <ginac/ginac.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string_view>
#include <vector>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <map>
#include <numbers>

#include "seam/io/file.h"
#include "seam/io/json.h"

namespace seam::rational {

namespace {

/// What an expression may call: sin, cos, exp, log, sqrt (a power to GiNaC) and pow (the same as ^).
bool callable(std::string_view name) {
  return name == "sin" || name == "cos" || name == "exp" || name == "log" || name == "sqrt" || name == "pow";
}

/// GiNaC's parser table cut down to the callable functions. The default table holds every GiNaC function, and the
/// parser evaluates them while it reads: binomial(9999999, 4999999) took 5.8 s, factorial of a large number longer.
const GiNaC::prototype_table& expressionFunctions() {
  static const GiNaC::prototype_table table = [] {
    GiNaC::prototype_table t;
    for (const auto& [prototype, reader] : GiNaC::get_default_reader())
      if (callable(prototype.first)) t.emplace(prototype, reader);
    return t;
  }();
  return table;
}

/// Largest integer exponent TreeEvaluator takes by repeated squaring (numeric::to_long is undefined beyond a long).
constexpr long kLongExponent = 1L << 62;

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
      // An integer exponent by repeated squaring, when it fits a long (u^(2^70) is a valid expression too).
      if (is_a<numeric>(x) && ex_to<numeric>(x).is_integer() && abs(ex_to<numeric>(x)) <= numeric(kLongExponent)) {
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

  /// Forms the derivatives up to `order`, each order from the one before; refuses an order whose derivatives would
  /// exceed kMaxDerivativeNodes (predicted from the one before, so that the refusal comes before GiNaC's work).
  Status formUpTo(int order) {
    std::lock_guard<std::mutex> lock(mutex);
    for (int n = formed + 1; n <= order; ++n) {
      const auto source = [&](int a, int k) -> const GiNaC::ex& {
        const int b = n - a;
        return b > 0 ? d[static_cast<size_t>(a)][static_cast<size_t>(b - 1)][static_cast<size_t>(k)]
                     : d[static_cast<size_t>(a - 1)][0][static_cast<size_t>(k)];
      };
      double predicted = 0.0;
      for (int a = 0; a <= n; ++a)
        for (int k = 0; k < 4; ++k) predicted += predictedDerivativeNodes(source(a, k), n - a > 0 ? v : u);
      if (predicted > static_cast<double>(kMaxDerivativeNodes))
        return invalidInput(fmt::format("expression patch \"{}\": the derivatives of order {} would hold about {:.3g} "
                                        "expression nodes, more than the {} accepted (the expression is too large to "
                                        "differentiate symbolically to that order; a product of m factors has "
                                        "about m^n terms in its n-th derivative)",
                                        name, n, predicted, kMaxDerivativeNodes));
      d.resize(static_cast<size_t>(n + 1));
      for (int a = 0; a <= n; ++a) {
        auto& row = d[static_cast<size_t>(a)];
        row.resize(static_cast<size_t>(n - a + 1));
        for (int k = 0; k < 4; ++k)
          row[static_cast<size_t>(n - a)][static_cast<size_t>(k)] = source(a, k).diff(n - a > 0 ? v : u);
      }
      formed = n;
    }
    return Status::ok();
  }

  /// A bound on the size of e's derivative, from e's size as a tree (GiNaC shares subexpressions, its derivative
  /// rules walk them as a tree) and its widest product: the product rule turns a product of m factors into m
  /// products, the chain rule f(g) into f'(g) g'. Counted up to kMaxDerivativeNodes + 1 nodes; 1 when e does not
  /// depend on the variable.
  static double predictedDerivativeNodes(const GiNaC::ex& e, const GiNaC::symbol& variable) {
    size_t nodes = 0, factors = 2;
    bool depends = false;
    for (auto it = e.preorder_begin(); it != e.preorder_end() && nodes <= kMaxDerivativeNodes; ++it) {
      ++nodes;
      if (GiNaC::is_a<GiNaC::mul>(*it)) factors = std::max(factors, it->nops());
      depends = depends || it->is_equal(variable);
    }
    if (!depends && nodes <= kMaxDerivativeNodes) return 1.0;  // the derivative is 0
    return static_cast<double>(nodes) * static_cast<double>(factors + 2);
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

/// What the number check knows of a node of the guard parse (see checkExpressionNumbers).
struct NumberBound {
  bool constant = false;  ///< no u, no v
  double bits = 0.0;      ///< bound on the bits of the exact numbers the node holds (its value, or its coefficients)
  GiNaC::ex value;        ///< a constant's value as GiNaC forms it (formed only once `bits` is checked)
};

/// Binary length of an exact rational n / d, numerator plus denominator (0 -> 1, +-1 -> 2, 2 and 1/2 -> 3).
double exactBits(const GiNaC::numeric& n) {
  return static_cast<double>(GiNaC::abs(n.numer()).int_length() + n.denom().int_length());
}

/// Bits of a number: an exact rational's binary length, 0 for a float; 0 for a symbolic constant (pi, sin(2)),
/// which the walk uses only where GiNaC keeps it symbolic.
double valueBits(const GiNaC::ex& value) {
  if (!GiNaC::is_a<GiNaC::numeric>(value)) return 0.0;
  const GiNaC::numeric& n = GiNaC::ex_to<GiNaC::numeric>(value);
  return n.is_rational() ? exactBits(n) : 0.0;
}

/// Whether a constant holds a float (GiNaC computes with it in CLN's floats, not exactly).
bool hasFloat(const GiNaC::ex& e) {
  for (auto it = e.preorder_begin(); it != e.preorder_end(); ++it)
    if (GiNaC::is_a<GiNaC::numeric>(*it) && !GiNaC::ex_to<GiNaC::numeric>(*it).is_crational()) return true;
  return false;
}

/// Bound on |log2 |b^e|| for constants b and e: ln |b^e| = Re(e) ln |b| - Im(e) arg(b) with |arg(b)| <= pi, each
/// product formed from logarithms (e may lie beyond a double), in bits. 0 for b = 0 (the walk refuses 0^e with
/// Re(e) <= 0 where b is a number); +inf where a value has no float (not expected for constants).
double floatPowerBits(const GiNaC::ex& base, const GiNaC::ex& exponent) {
  using namespace GiNaC;
  const ex b = evalf(base), e = evalf(exponent);
  if (!is_a<numeric>(b) || !is_a<numeric>(e)) return HUGE_VAL;
  const numeric& nb = ex_to<numeric>(b);
  const numeric& ne = ex_to<numeric>(e);
  if (nb.is_zero()) return 0.0;
  const auto lnAbs = [](const numeric& x) { return log(abs(x)).to_double(); };  // x != 0
  const double lnBase = std::abs(lnAbs(nb));
  double ln = 0.0;
  if (!ne.real().is_zero() && lnBase > 0.0) ln += std::exp(lnAbs(ne.real()) + std::log(lnBase));
  if (!ne.imag().is_zero()) ln += std::exp(lnAbs(ne.imag()) + std::log(std::numbers::pi));
  return ln / std::numbers::ln2;
}

/// Walks the guard parse bottom-up (sums, products, powers, the functions, numbers, u, v, the number symbols) and
/// bounds, before anything is computed, the size of every exact number GiNaC's evaluation would form: the bits of a
/// sum or a product are at most the sum of the operands' bits (plus one per term); an exact rational power k of a
/// number, or of a product or a sum (GiNaC raises a product's coefficient, and the content, the gcd of the
/// coefficients, that it takes out of a sum: (5/6 u + 1/6 v)^k is (1/6)^k (5 u + v)^k), at most |k| + 1 times the
/// base's; 0, 1 and -1 stay small. A constant's value is then formed with GiNaC's own operations,
/// so that an exponent is known exactly (10^25 + 10^9 - 10^25 is 10^9, not 0 as in doubles; exp(0) is 1). The
/// first bound above kMaxExpressionNumberBits stops the walk, with a message in `tooLarge`.
class NumberBoundWalk {
 public:
  /// `numbers`: the number symbols of the guard parse and each literal's value.
  explicit NumberBoundWalk(std::map<GiNaC::ex, NumberBound, GiNaC::ex_is_less> numbers)
      : numbers_(std::move(numbers)) {}

  NumberBound operator()(const GiNaC::ex& e) {
    using namespace GiNaC;
    if (!tooLarge.empty() || !undefined.empty() || !outOfRange.empty()) return {};
    if (is_a<numeric>(e) || is_a<constant>(e)) return {true, valueBits(e), e};
    if (is_a<symbol>(e)) {
      const auto it = numbers_.find(e);
      return it != numbers_.end() ? it->second : NumberBound{};  // a number literal, or u, v
    }
    if (is_a<add>(e) || is_a<mul>(e)) {
      const bool sum = is_a<add>(e);
      std::vector<NumberBound> operands;
      operands.reserve(e.nops());
      NumberBound out{true, 0.0, {}};
      for (size_t i = 0; i < e.nops(); ++i) {
        operands.push_back((*this)(e.op(i)));
        out.constant = out.constant && operands.back().constant;
        out.bits += operands.back().bits + (sum ? 1.0 : 0.0);
      }
      if (!check(out, sum ? "a sum" : "a product") || !out.constant || !undefined.empty() || !outOfRange.empty())
        return out;
      out.value = sum ? ex(0) : ex(1);
      for (const NumberBound& b : operands) out.value = sum ? out.value + b.value : out.value * b.value;
      if (is_a<numeric>(out.value)) out.bits = valueBits(out.value);
      return out;
    }
    if (is_a<power>(e)) {
      const NumberBound base = (*this)(e.op(0)), exponent = (*this)(e.op(1));
      if (!tooLarge.empty() || !undefined.empty() || !outOfRange.empty()) return {};
      NumberBound out{base.constant && exponent.constant, base.bits, {}};
      const bool rationalExponent = exponent.constant && is_a<numeric>(exponent.value) &&
                                    ex_to<numeric>(exponent.value).is_rational();
      const bool unit = base.constant && is_a<numeric>(base.value) &&
                        (ex_to<numeric>(base.value).is_zero() || abs(ex_to<numeric>(base.value)).is_equal(1));
      if (rationalExponent && !unit && base.bits > 0.0) {
        const numeric& k = ex_to<numeric>(exponent.value);
        const double magnitude = abs(k).to_double();  // at most 2^65536: may be infinite
        out.bits = (magnitude + (k.is_integer() ? 0.0 : 1.0)) * base.bits;
        if (!(out.bits >= 0.0)) out.bits = HUGE_VAL;
      }
      if (!check(out, "a power") || !out.constant) return out;
      // 0 to a power that is not positive: GiNaC's power::eval throws there, and the power it allocated leaks.
      if (is_a<numeric>(base.value) && ex_to<numeric>(base.value).is_zero() && is_a<numeric>(exponent.value) &&
          !ex_to<numeric>(exponent.value).is_positive()) {
        undefined = ex_to<numeric>(exponent.value).is_zero() ? "0^0 is undefined" : "division by zero";
        return {};
      }
      // A float in the power (2.0^k, 2^1.5, (-2/111)^9.1e111): CLN forms a float with a bounded exponent, whose
      // overflow or underflow throws inside GiNaC's power::eval after it allocated the power (a leak; found by
      // fuzz_gcn). Such a power's magnitude is bounded first, from the floats, in the exact numbers' units.
      if (hasFloat(base.value) || hasFloat(exponent.value)) {
        const double magnitude = floatPowerBits(base.value, exponent.value);
        if (!(magnitude <= static_cast<double>(kMaxExpressionNumberBits))) {
          outOfRange = fmt::format("a power of floats whose binary exponent may reach {}, more than the {} accepted",
                                   std::isfinite(magnitude) ? fmt::format("{:.3g}", magnitude) : "over 1e308",
                                   kMaxExpressionNumberBits);
          return {};
        }
      }
      out.value = pow(base.value, exponent.value);
      // A number: its size. Otherwise the bound stays: 2^(-1/111) is 1/2 * 2^(110/111), whose powers grow.
      if (is_a<numeric>(out.value)) out.bits = valueBits(out.value);
      return out;
    }
    if (is_a<function>(e)) {
      const NumberBound argument = (*this)(e.op(0));
      if (!tooLarge.empty() || !undefined.empty() || !outOfRange.empty() || !argument.constant)
        return {false, 0.0, {}};
      // sin(0) and exp(0) are exact, sin(2) stays symbolic, sin(2.0) is a float: as GiNaC evaluates them.
      const std::string name = ex_to<function>(e).get_name();
      // Only these four reach here: the scan refuses other calls, and sqrt and pow are powers.
      const ex value = name == "sin"   ? sin(argument.value)
                       : name == "cos" ? cos(argument.value)
                       : name == "exp" ? exp(argument.value)
                                       : log(argument.value);
      return {true, valueBits(value), value};
    }
    return {};
  }

  std::string tooLarge;   ///< the first refusal's message (empty: none)
  std::string undefined;  ///< a constant part that has no value (0^-1, 0^0), as GiNaC would report it
  std::string outOfRange;  ///< a power of floats beyond 2^+-kMaxExpressionNumberBits (its message; empty: none)

 private:
  bool check(const NumberBound& b, const char* what) {
    if (tooLarge.empty() && !(b.bits <= static_cast<double>(kMaxExpressionNumberBits)))
      tooLarge = fmt::format("{} whose exact value would take {} bits, more than the {} accepted", what,
                             std::isfinite(b.bits) ? fmt::format("{:.0f}", b.bits) : std::string("over 1e308"),
                             kMaxExpressionNumberBits);
    return tooLarge.empty();
  }

  std::map<GiNaC::ex, NumberBound, GiNaC::ex_is_less> numbers_;
};

/// GiNaC's parser message without the source location it appends ("\n[GiNaC::ex GiNaC::parser::operator()...]").
std::string parserMessage(const std::exception& ex) {
  std::string message = ex.what();
  if (const size_t at = message.find("\n["); at != std::string::npos) message.erase(at);
  return message;
}

/// The error for a text GiNaC cannot parse.
Status parseError(const std::string& where, const std::string& message) {
  return invalidInput(fmt::format("{}: cannot parse ({}); allowed: numbers, u, v, pi, + - * / ^, sin, cos, exp, log, "
                                  "sqrt", where, message));
}

/// Name of the symbol that stands for the k-th number literal in the check's parse (an identifier GiNaC's lexer
/// reads whole; a user's text using it is refused by the real parse, which does not know it).
std::string numberSymbol(size_t k) { return fmt::format("seam_number_{}_", k); }

/// A token for a message: at most 40 characters, anything but printable ASCII as '?'.
std::string printable(std::string_view token) {
  std::string out(token.substr(0, 40));
  for (char& c : out)
    if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
  return token.size() > 40 ? out.substr(0, 37) + "..." : out;
}

/// Index of the next character of `text` from `i` that GiNaC's lexer does not skip (white space, '#' comments to the
/// end of the line); text.size() when none.
size_t nextToken(std::string_view text, size_t i) {
  while (i < text.size()) {
    if (text[i] == '#') {
      i = text.find_first_of("\n\r", i);
      if (i == std::string_view::npos) return text.size();
    } else if (!std::isspace(static_cast<unsigned char>(text[i]))) {
      return i;
    }
    ++i;
  }
  return text.size();
}

/// Refuses, before GiNaC evaluates it, an expression whose numbers GiNaC's exact arithmetic cannot take in bounded
/// time: GiNaC evaluates numbers while it parses (2^9999999 ran for 1.5 s, 3^(3^15) for 3 s, (1 + 2^-99999)^999
/// for more than 20 s, and reading the literal 1e11111111111 did not finish; found by fuzz_gcn). The check parses
/// the text once with every number literal replaced by a symbol, so that nothing is computed, and bounds the size of
/// every exact number the real parse would form (NumberBoundWalk). A float literal's decimal exponent is limited
/// to kMaxExpressionNumberBits * log10(2) (about 19 728). The number tokens are found as GiNaC's lexer finds them
/// ([0-9.]+, then E, one character and digits), and '#' comments are skipped; a malformed number ("1.2.3", "1e",
/// "1ex") is refused here with its text (GiNaC's message would show its internal form and the end-of-file byte).
/// A call of a function other than sin, cos, exp, log, sqrt (pow) is refused here too, and so is one without an
/// argument ("sin()" crashed GiNaC's parser).
Status checkExpressionNumbers(std::string_view text, const std::string& where) {
  const double maxDecimalExponent = static_cast<double>(kMaxExpressionNumberBits) * std::log10(2.0);
  std::string guarded;
  guarded.reserve(text.size() + 16);
  std::vector<std::string> literals;
  std::vector<NumberBound> bounds;
  for (size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '#') {  // a comment, to the end of the line
      const size_t end = text.find_first_of("\n\r", i);
      guarded.append(text.substr(i, end == std::string_view::npos ? std::string_view::npos : end - i));
      i = end == std::string_view::npos ? text.size() : end;
    } else if (std::isalpha(c)) {  // an identifier: [a-zA-Z][a-zA-Z0-9_]*
      const size_t start = i;
      while (i < text.size() && (std::isalnum(static_cast<unsigned char>(text[i])) || text[i] == '_')) ++i;
      const std::string_view name = text.substr(start, i - start);
      guarded.append(name);
      // A call: only the allowed functions, and never without an argument (GiNaC's parser matches "sin()" to sin
      // and evaluates it with no argument: a null dereference).
      if (size_t open = nextToken(text, i); open < text.size() && text[open] == '(') {
        if (!callable(name))
          return invalidInput(fmt::format("{}: function \"{}\" is not supported (allowed: sin, cos, exp, log, sqrt)",
                                          where, printable(name)));
        if (size_t close = nextToken(text, open + 1); close < text.size() && text[close] == ')')
          return invalidInput(fmt::format("{}: {}() has no argument", where, printable(name)));
      }
    } else if (std::isdigit(c) || c == '.') {
      const size_t start = i;
      while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.')) ++i;
      const size_t mantissaEnd = i;
      size_t exponentStart = i;
      if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
        ++i;
        if (i < text.size()) ++i;  // a sign, a digit or anything: GiNaC's lexer takes it
        exponentStart = i - 1;
        while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
      }
      const std::string_view token = text.substr(start, i - start);
      const std::string_view mantissa = text.substr(start, mantissaEnd - start);
      const std::string_view exponent = text.substr(exponentStart, i - exponentStart);  // empty without E
      const bool wellFormed =
          std::count(mantissa.begin(), mantissa.end(), '.') <= 1 && mantissa != "." &&
          (exponent.empty() || (std::isdigit(static_cast<unsigned char>(exponent[0])) ||
                                ((exponent[0] == '+' || exponent[0] == '-') && exponent.size() >= 2)));
      if (!wellFormed)
        return invalidInput(fmt::format("{}: \"{}\" is not a number (digits with at most one decimal point, then "
                                        "optionally e, a sign and digits)", where, printable(token)));
      const bool exact = exponent.empty() && mantissa.find('.') == std::string_view::npos;
      if (!exponent.empty()) {
        // The decimal exponent's size, without converting an arbitrarily long digit string.
        const std::string_view digits = exponent.substr(exponent[0] == '+' || exponent[0] == '-' ? 1 : 0);
        const size_t first = std::min(digits.find_first_not_of('0'), digits.size());
        const double magnitude =
            digits.size() - first > 9 ? HUGE_VAL : std::strtod(std::string(digits).c_str(), nullptr);
        if (magnitude > maxDecimalExponent)
          return invalidInput(fmt::format("{}: the number {} is out of range (decimal exponents up to {:.0f} are "
                                          "accepted; a double holds up to 1e308)",
                                          where, printable(token), std::floor(maxDecimalExponent)));
      }
      // A float literal beyond a double: GiNaC would carry it in its own float format, where exp(1e19000) is 1.
      if (!exact && !std::isfinite(std::strtod(std::string(token).c_str(), nullptr)))
        return invalidInput(fmt::format("{}: the number {} is beyond the range of a double (about 1.8e308)", where,
                                        printable(token)));
      // The literal as GiNaC's lexer hands it to numeric: E, and + before an unsigned exponent. An exact literal has
      // at most kMaxExpressionChars digits, a float one a checked exponent: cheap to form.
      std::string normalised(mantissa);
      if (!exponent.empty())
        normalised += std::string("E") + (std::isdigit(static_cast<unsigned char>(exponent[0])) ? "+" : "") +
                      std::string(exponent);
      const GiNaC::numeric value(normalised.c_str());
      bounds.push_back({true, valueBits(value), value});
      guarded += " " + numberSymbol(literals.size()) + " ";
      literals.emplace_back(token);
    } else {
      guarded.push_back(static_cast<char>(c));
      ++i;
    }
  }
  if (literals.empty()) return Status::ok();  // nothing GiNaC would compute at large size
  GiNaC::symbol u("u"), v("v");
  GiNaC::symtab table;
  table["u"] = u;
  table["v"] = v;
  table["pi"] = GiNaC::Pi;
  std::map<GiNaC::ex, NumberBound, GiNaC::ex_is_less> numbers;
  for (size_t k = 0; k < literals.size(); ++k) {
    const GiNaC::symbol number(numberSymbol(k));
    table[number.get_name()] = number;
    numbers.emplace(number, bounds[k]);
  }
  GiNaC::ex e;
  try {
    GiNaC::parser reader(table, /*strict=*/true, expressionFunctions());
    e = reader(guarded);
  } catch (const std::exception& ex) {
    // The real parse would fail too, but only after computing what comes before the error: report it from here,
    // with the literals put back into GiNaC's message.
    std::string message = parserMessage(ex);
    for (size_t k = literals.size(); k-- > 0;) {
      const std::string name = numberSymbol(k);
      for (size_t at = message.find(name); at != std::string::npos; at = message.find(name, at))
        message.replace(at, name.size(), literals[k]);
    }
    return parseError(where, message);
  }
  NumberBoundWalk walk(std::move(numbers));
  try {
    walk(e);
  } catch (const std::exception& ex) {  // GiNaC's evaluation of a constant part, e.g. 0^(-1): division by zero
    return invalidInput(fmt::format("{}: cannot evaluate ({})", where, parserMessage(ex)));
  }
  if (!walk.undefined.empty()) return invalidInput(fmt::format("{}: cannot evaluate ({})", where, walk.undefined));
  if (!walk.outOfRange.empty())
    return invalidInput(fmt::format("{}: the expression holds {} (a double's binary exponent reaches 1024)", where,
                                    walk.outOfRange));
  if (!walk.tooLarge.empty())
    return invalidInput(fmt::format("{}: the expression holds {}; GiNaC computes exact numbers at any size and would "
                                    "not finish (a double holds up to 1e308)", where, walk.tooLarge));
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
  GiNaC::parser reader(table, /*strict=*/true, expressionFunctions());
  st->d.resize(1);
  st->d[0].resize(1);
  for (int k = 0; k < 4; ++k) {
    const std::string where = fmt::format("expression patch \"{}\": {} = \"{}\"", patch.name, kCoordinateNames[k],
                                          patch.homogeneous[static_cast<size_t>(k)]);
    if (Status size = checkExpressionSize(patch.homogeneous[static_cast<size_t>(k)],
                                          fmt::format("expression patch \"{}\": {}", patch.name, kCoordinateNames[k]));
        !size)
      return size;
    if (Status numbers = checkExpressionNumbers(patch.homogeneous[static_cast<size_t>(k)], where); !numbers)
      return numbers;
    GiNaC::ex e;
    try {
      e = reader(patch.homogeneous[static_cast<size_t>(k)]);
    } catch (const std::exception& ex) {
      return parseError(where, parserMessage(ex));
    }
    // Other functions were refused by checkExpressionNumbers and are not in the parser's table; I is not.
    for (auto it = e.preorder_begin(); it != e.preorder_end(); ++it)
      if (GiNaC::is_a<GiNaC::numeric>(*it) && !GiNaC::ex_to<GiNaC::numeric>(*it).is_real())
        return invalidInput(fmt::format("{}: complex numbers are not supported", where));
    st->d[0][0][static_cast<size_t>(k)] = e;
  }
  if (!(patch.u.length() > 0.0) || !(patch.v.length() > 0.0) || !std::isfinite(patch.u.length()) ||
      !std::isfinite(patch.v.length()))
    return invalidInput(fmt::format("expression patch \"{}\": the domain [[{}, {}], [{}, {}]] is empty or not finite",
                                    patch.name, patch.u.lo, patch.u.hi, patch.v.lo, patch.v.hi));
  HomogeneousSurface::Evaluator ev = [st](double u, double v, int order) -> Result<DerivativeTable> {
    if (Status formed = st->formUpTo(order); !formed) return formed;
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
