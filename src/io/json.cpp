#include "seam/io/json.h"

#include <fmt/format.h>

#include <fcntl.h>
#include <simdjson.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "json_read.h"
#include "seam/core/tolerances.h"
#include "seam/io/file.h"
#include "seam/model/brep.h"

namespace seam::io {

namespace {

using Json = nlohmann::json;

// ---------------------------------------------------------------------------------------------------------------
// Small formatting helpers for messages.

/// A name in double quotes with JSON escapes (names may hold quotes or control characters).
std::string quote(const std::string& s) {
  return Json(s).dump(-1, ' ', false, Json::error_handler_t::replace);
}


// ---------------------------------------------------------------------------------------------------------------
// The fast parser's DOM (simdjson) behind the member names of nlohmann::json that ModelReader uses, so that one
// converter serves both parsers. Only values that the converter reads go through it; it never throws.

class SimdValue {
 public:
  SimdValue() = default;
  explicit SimdValue(simdjson::dom::element e) : e_(e), valid_(true) {}

  bool is_object() const { return type() == simdjson::dom::element_type::OBJECT; }
  bool is_array() const { return type() == simdjson::dom::element_type::ARRAY; }
  bool is_string() const { return type() == simdjson::dom::element_type::STRING; }
  bool is_number() const { return is_number_integer() || type() == simdjson::dom::element_type::DOUBLE; }
  /// nlohmann: a non-negative integer literal; simdjson keeps those up to INT64_MAX as int64.
  bool is_number_unsigned() const {
    if (type() == simdjson::dom::element_type::UINT64) return true;
    int64_t v = 0;
    return type() == simdjson::dom::element_type::INT64 && e_.get_int64().get(v) == simdjson::SUCCESS && v >= 0;
  }
  bool is_number_integer() const {
    return type() == simdjson::dom::element_type::INT64 || type() == simdjson::dom::element_type::UINT64;
  }

  const char* type_name() const {
    switch (type()) {
      case simdjson::dom::element_type::OBJECT: return "object";
      case simdjson::dom::element_type::ARRAY: return "array";
      case simdjson::dom::element_type::STRING: return "string";
      case simdjson::dom::element_type::BOOL: return "boolean";
      case simdjson::dom::element_type::NULL_VALUE: return "null";
      default: return "number";
    }
  }

  size_t size() const {
    if (is_array()) return simdjson::dom::array(e_).size();
    if (is_object()) return simdjson::dom::object(e_).size();
    return 1;  // as nlohmann: a scalar has size 1
  }
  bool empty() const { return size() == 0; }

  /// Element `i` of an array (the caller has checked the size). simdjson's at(i) walks the array from its start,
  /// so a long array ("patches", a long knot vector) lists its elements once, on the first access.
  SimdValue operator[](size_t i) const {
    constexpr size_t kWalkAtMost = 16;
    if (i < kWalkAtMost && !elements_) {
      simdjson::dom::element out;
      if (simdjson::dom::array(e_).at(i).get(out) != simdjson::SUCCESS) return {};
      return SimdValue(out);
    }
    if (!elements_) {
      auto elements = std::make_shared<std::vector<simdjson::dom::element>>();
      for (const simdjson::dom::element e : simdjson::dom::array(e_)) elements->push_back(e);
      elements_ = std::move(elements);
    }
    return i < elements_->size() ? SimdValue((*elements_)[i]) : SimdValue();
  }
  /// The value of `key`; with a repeated key the last one, as nlohmann keeps it.
  SimdValue operator[](std::string_view key) const {
    SimdValue found;
    if (!is_object()) return found;
    for (const auto field : simdjson::dom::object(e_)) {
      if (field.key == key) found = SimdValue(field.value);
    }
    return found;
  }
  bool contains(std::string_view key) const {
    if (!is_object()) return false;
    for (const auto field : simdjson::dom::object(e_)) {
      if (field.key == key) return true;
    }
    return false;
  }
  /// (key, value) of each member, as nlohmann's items() (membership is all the converter asks of them).
  std::vector<std::pair<std::string, SimdValue>> items() const {
    std::vector<std::pair<std::string, SimdValue>> out;
    if (!is_object()) return out;
    for (const auto field : simdjson::dom::object(e_)) out.emplace_back(std::string(field.key), SimdValue(field.value));
    return out;
  }

  template <class T>
  T get() const {
    if constexpr (std::is_same_v<T, double>) {
      double v = 0.0;  // simdjson converts int64/uint64 with a cast, as nlohmann does
      return e_.get_double().get(v) == simdjson::SUCCESS ? v : 0.0;
    } else if constexpr (std::is_same_v<T, std::uint64_t>) {
      if (type() == simdjson::dom::element_type::UINT64) return e_.get_uint64().value_unsafe();
      return static_cast<std::uint64_t>(e_.get_int64().value_unsafe());
    } else if constexpr (std::is_same_v<T, std::int64_t>) {
      if (type() == simdjson::dom::element_type::UINT64)
        return static_cast<std::int64_t>(e_.get_uint64().value_unsafe());
      return e_.get_int64().value_unsafe();
    } else {
      static_assert(std::is_same_v<T, std::string>);
      std::string_view v;
      return e_.get_string().get(v) == simdjson::SUCCESS ? std::string(v) : std::string();
    }
  }
  template <class T>
  std::string get_ref() const {
    return get<std::string>();
  }

  /// Compact text of the value (simdjson's minified form; messages of the fast route are not shown, see
  /// parseModelJson).
  std::string dump() const { return valid_ ? simdjson::minify(e_) : std::string("null"); }

 private:
  /// A default value (a key not found) reads as null.
  simdjson::dom::element_type type() const {
    return valid_ ? e_.type() : simdjson::dom::element_type::NULL_VALUE;
  }

  simdjson::dom::element e_;
  bool valid_ = false;
  mutable std::shared_ptr<const std::vector<simdjson::dom::element>> elements_;  ///< a long array's elements
};

std::string brief(const SimdValue& j) {
  constexpr size_t kMaxChars = 40;
  std::string s = j.dump();
  if (s.size() > kMaxChars) s = s.substr(0, kMaxChars) + "...";
  return s;
}

// ---------------------------------------------------------------------------------------------------------------
// The nlohmann route's document: a compact tree built from nlohmann's SAX events (16 bytes a value, one array of
// values and one of child indices, both reserved once from a count of the text's commas, brackets and colons), behind
// the member names of nlohmann::json that ModelReader uses. Not nlohmann's own DOM: a node of it is a heap object
// per value (3 to 5 times the text), and destroying a partly built one allocates, so an out-of-memory during parsing
// threw again while unwinding and aborted the process (issue 39 goal 4).

class CompactDoc {
 public:
  enum class Type : std::uint8_t { kNull, kBool, kInteger, kUnsigned, kFloat, kString, kArray, kObject };
  struct Node {
    Type type = Type::kNull;
    std::uint32_t count = 0;  ///< elements of an array, members of an object, bytes of a string
    union {
      std::int64_t integer;
      std::uint64_t unsignedValue;
      double floating;
      std::uint64_t offset;  ///< into children_ (arrays: element indices; objects: key, value pairs) or strings_
      bool boolean;
    };
    Node() : offset(0) {}
  };
  static_assert(sizeof(Node) == 16);

  /// Capacities for a text of `values` values (keys included): nothing grows while parsing.
  void reserve(size_t values) {
    nodes_.reserve(values);
    children_.reserve(values);
  }

  const Node& node(std::uint32_t k) const { return nodes_[k]; }
  std::uint32_t child(const Node& n, size_t i) const { return children_[n.offset + i]; }
  std::string_view text(const Node& n) const { return std::string_view(strings_).substr(n.offset, n.count); }

  class Builder;

 private:
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> children_;
  std::string strings_;
};

/// nlohmann's SAX interface filling a CompactDoc; a parse error is kept (with nlohmann's message and id) and stops
/// the parse.
class CompactDoc::Builder {
 public:
  using number_integer_t = Json::number_integer_t;
  using number_unsigned_t = Json::number_unsigned_t;
  using number_float_t = Json::number_float_t;
  using string_t = Json::string_t;
  using binary_t = Json::binary_t;

  explicit Builder(CompactDoc& doc) : doc_(doc) {}

  bool null() { return add(Node()); }
  bool boolean(bool b) {
    Node n;
    n.type = Type::kBool;
    n.boolean = b;
    return add(n);
  }
  bool number_integer(number_integer_t v) {
    Node n;
    n.type = Type::kInteger;
    n.integer = v;
    return add(n);
  }
  bool number_unsigned(number_unsigned_t v) {
    Node n;
    n.type = Type::kUnsigned;
    n.unsignedValue = v;
    return add(n);
  }
  bool number_float(number_float_t v, const string_t& /*literal*/) {
    Node n;
    n.type = Type::kFloat;
    n.floating = v;
    return add(n);
  }
  bool string(string_t& v) { return add(stringNode(v)); }
  bool binary(binary_t& /*unused*/) { return false; }  // never in JSON text
  bool key(string_t& k) {
    pending_.push_back(static_cast<std::uint32_t>(doc_.nodes_.size()));
    doc_.nodes_.push_back(stringNode(k));
    return true;
  }
  bool start_object(std::size_t /*unknown*/) { return open(Type::kObject); }
  bool end_object() { return close(); }
  bool start_array(std::size_t /*unknown*/) { return open(Type::kArray); }
  bool end_array() { return close(); }
  bool parse_error(std::size_t /*position*/, const std::string& /*last_token*/,
                   const nlohmann::detail::exception& ex) {
    errorId = ex.id;
    error = ex.what();
    return false;
  }

  int errorId = 0;    ///< nlohmann's exception id (1xx: syntax, 406: a number that overflows a double)
  std::string error;  ///< nlohmann's exception text

 private:
  Node stringNode(const std::string& v) {
    Node n;
    n.type = Type::kString;
    n.offset = doc_.strings_.size();
    n.count = static_cast<std::uint32_t>(v.size());
    doc_.strings_ += v;
    return n;
  }
  bool add(const Node& n) {
    if (!frames_.empty()) pending_.push_back(static_cast<std::uint32_t>(doc_.nodes_.size()));
    doc_.nodes_.push_back(n);
    return true;
  }
  bool open(Type type) {
    Node n;
    n.type = type;
    add(n);
    frames_.push_back({static_cast<std::uint32_t>(doc_.nodes_.size() - 1), pending_.size()});
    return true;
  }
  bool close() {
    const Frame f = frames_.back();
    frames_.pop_back();
    Node& n = doc_.nodes_[f.node];
    const size_t count = pending_.size() - f.start;
    n.count = static_cast<std::uint32_t>(n.type == Type::kObject ? count / 2 : count);
    n.offset = doc_.children_.size();
    doc_.children_.insert(doc_.children_.end(), pending_.begin() + static_cast<std::ptrdiff_t>(f.start),
                          pending_.end());
    pending_.resize(f.start);
    return true;
  }

  struct Frame {
    std::uint32_t node;  ///< the open array or object
    size_t start;        ///< its first child in pending_
  };
  CompactDoc& doc_;
  std::vector<Frame> frames_;
  std::vector<std::uint32_t> pending_;  ///< children of the open containers, innermost last
};

/// A value of a CompactDoc with the member names of nlohmann::json that ModelReader uses (const access; a key or
/// index not found reads as null, as nlohmann's const operator[] would not be asked for one: every access is
/// checked first). Objects behave as nlohmann's: keys in sorted order, a repeated key keeps its last value.
class DocValue {
 public:
  using Type = CompactDoc::Type;
  DocValue() = default;
  DocValue(const CompactDoc* doc, std::uint32_t node) : doc_(doc), node_(node) {}

  bool is_object() const { return type() == Type::kObject; }
  bool is_array() const { return type() == Type::kArray; }
  bool is_string() const { return type() == Type::kString; }
  bool is_number() const { return is_number_integer() || type() == Type::kFloat; }
  bool is_number_unsigned() const { return type() == Type::kUnsigned; }
  bool is_number_integer() const { return type() == Type::kInteger || type() == Type::kUnsigned; }

  const char* type_name() const {
    switch (type()) {
      case Type::kNull: return "null";
      case Type::kBool: return "boolean";
      case Type::kString: return "string";
      case Type::kArray: return "array";
      case Type::kObject: return "object";
      default: return "number";
    }
  }

  size_t size() const {
    switch (type()) {
      case Type::kNull: return 0;
      case Type::kArray: return node().count;
      case Type::kObject: return members().size();
      default: return 1;
    }
  }
  bool empty() const { return size() == 0; }

  DocValue operator[](size_t i) const {
    if (!is_array() || i >= node().count) return {};
    return {doc_, doc_->child(node(), i)};
  }
  DocValue operator[](std::string_view key) const {
    DocValue found;
    if (!is_object()) return found;
    for (std::uint32_t m = 0; m < node().count; ++m) {
      if (doc_->text(doc_->node(doc_->child(node(), 2 * m))) == key) found = {doc_, doc_->child(node(), 2 * m + 1)};
    }
    return found;
  }
  bool contains(std::string_view key) const { return is_object() && operator[](key).doc_ != nullptr; }
  std::vector<std::pair<std::string, DocValue>> items() const { return members(); }

  template <class T>
  T get() const {
    const CompactDoc::Node& n = node();
    if constexpr (std::is_same_v<T, double>) {
      switch (n.type) {
        case Type::kFloat: return n.floating;
        case Type::kInteger: return static_cast<double>(n.integer);
        case Type::kUnsigned: return static_cast<double>(n.unsignedValue);
        default: return 0.0;
      }
    } else if constexpr (std::is_same_v<T, std::uint64_t>) {
      return n.type == Type::kUnsigned ? n.unsignedValue : static_cast<std::uint64_t>(n.integer);
    } else if constexpr (std::is_same_v<T, std::int64_t>) {
      return n.type == Type::kUnsigned ? static_cast<std::int64_t>(n.unsignedValue) : n.integer;
    } else {
      static_assert(std::is_same_v<T, std::string>);
      return is_string() ? std::string(doc_->text(n)) : std::string();
    }
  }
  template <class T>
  std::string get_ref() const {
    return get<std::string>();
  }

  /// nlohmann's dump() (compact, invalid UTF-8 replaced), stopped once longer than `limit` characters.
  void dump(std::string& out, size_t limit) const {
    if (out.size() > limit) return;
    const CompactDoc::Node& n = node();
    switch (type()) {
      case Type::kNull: out += "null"; return;
      case Type::kBool: out += n.boolean ? "true" : "false"; return;
      case Type::kInteger: out += std::to_string(n.integer); return;
      case Type::kUnsigned: out += std::to_string(n.unsignedValue); return;
      case Type::kFloat: out += Json(n.floating).dump(); return;
      case Type::kString: out += quote(std::string(doc_->text(n))); return;
      case Type::kArray:
        out += '[';
        for (std::uint32_t k = 0; k < n.count && out.size() <= limit; ++k) {
          if (k > 0) out += ',';
          operator[](k).dump(out, limit);
        }
        out += ']';
        return;
      case Type::kObject: {
        out += '{';
        bool first = true;
        for (const auto& [key, value] : members()) {
          if (out.size() > limit) break;
          if (!first) out += ',';
          first = false;
          out += quote(key) + ':';
          value.dump(out, limit);
        }
        out += '}';
        return;
      }
    }
  }

 private:
  Type type() const { return doc_ == nullptr ? Type::kNull : node().type; }
  const CompactDoc::Node& node() const { return doc_->node(node_); }
  /// The members in nlohmann's order (sorted by key), a repeated key with its last value.
  std::vector<std::pair<std::string, DocValue>> members() const {
    std::map<std::string, DocValue> sorted;
    if (is_object()) {
      for (std::uint32_t m = 0; m < node().count; ++m)
        sorted[std::string(doc_->text(doc_->node(doc_->child(node(), 2 * m))))] = {doc_, doc_->child(node(), 2 * m + 1)};
    }
    return {sorted.begin(), sorted.end()};
  }

  const CompactDoc* doc_ = nullptr;
  std::uint32_t node_ = 0;
};

std::string brief(const DocValue& j) {
  constexpr size_t kMaxChars = 40;
  std::string s;
  j.dump(s, kMaxChars);
  if (s.size() > kMaxChars) s = s.substr(0, kMaxChars) + "...";
  return s;
}

/// Shortest text that reads back as the same double ("0.5", "1e+300", "inf").
std::string num(double x) { return fmt::format("{}", x); }

const char* axisName(int k) {
  static const char* const kNames[] = {"x", "y", "z"};
  return k >= 0 && k < 3 ? kNames[k] : "w";
}

/// 1-based line and column of a byte offset.
std::string lineColumn(std::string_view text, size_t offset) {
  size_t line = 1;
  size_t column = 1;
  for (size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return fmt::format("line {}, column {}", line, column);
}

// ---------------------------------------------------------------------------------------------------------------
// A scan before parsing: nesting depth and NUL bytes.

/// Deepest nesting of arrays and objects accepted in a model file. A model needs 6 levels (the top object,
/// "patches", a patch, its rows, a row, a point); deeper text is refused before it is parsed, because nlohmann's
/// printing of a value for a message recurses once per level and a file nested 80 000 deep overflowed the stack.
constexpr int kMaxJsonDepth = 256;

/// Rejects what no model file holds and what would harm the parser: a NUL byte anywhere (text after it would be
/// silently ignored by some readers) and arrays/objects nested deeper than kMaxJsonDepth.
/// `values` (when given): an upper bound of the number of values and keys in the text, exact for valid JSON (one
/// more than its commas, colons and opening brackets outside strings), for CompactDoc::reserve.
Status scanJsonText(std::string_view text, std::string_view src, size_t* values = nullptr) {
  bool inString = false;
  int depth = 0;
  size_t separators = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\0') {
      return invalidInput(fmt::format("{}: not valid JSON: {}: a NUL byte (JSON text cannot hold one; the file is "
                                      "binary or damaged)",
                                      src, lineColumn(text, i)));
    }
    if (inString) {
      if (c == '\\') {
        ++i;  // the escaped character cannot end the string
        if (i < text.size() && text[i] == '\0') --i;  // report the NUL on the next round
      } else if (c == '"') {
        inString = false;
      }
      continue;
    }
    if (c == '"') {
      inString = true;
    } else if (c == ',' || c == ':') {
      ++separators;
    } else if (c == '[' || c == '{') {
      ++separators;
      if (++depth > kMaxJsonDepth) {
        return invalidInput(fmt::format("{}: not valid as a model: {}: arrays and objects nested more than {} "
                                        "deep (a model needs 6 levels)",
                                        src, lineColumn(text, i), kMaxJsonDepth));
      }
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  if (values != nullptr) *values = separators + 1;
  return Status::ok();
}

// ---------------------------------------------------------------------------------------------------------------
// Number literals that overflow a double (1e999). nlohmann rejects them without saying where; we rewrite each
// into a marker string so that the model reader can report the object and the field that holds it.

/// Prefix of the decoded marker string that replaces an overflowing number literal (a control character
/// cannot appear unescaped in JSON text, so no real string starts with it).
constexpr std::string_view kOverflowMarker = "\x01overflow:";

struct OverflowScan {
  std::string text;          ///< the rewritten text
  size_t count = 0;          ///< how many literals were rewritten
  size_t firstOffset = 0;    ///< byte offset of the first one in the original text
  std::string firstLiteral;  ///< the first one
};

OverflowScan rewriteOverflowingNumbers(std::string_view text) {
  OverflowScan scan;
  scan.text.reserve(text.size());
  bool inString = false;
  size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (inString) {
      scan.text += c;
      if (c == '\\' && i + 1 < text.size()) {
        scan.text += text[i + 1];
        i += 2;
        continue;
      }
      if (c == '"') inString = false;
      ++i;
      continue;
    }
    if (c == '"') {
      inString = true;
      scan.text += c;
      ++i;
      continue;
    }
    if (c == '-' || (c >= '0' && c <= '9')) {
      size_t end = i + 1;
      while (end < text.size() &&
             ((text[end] >= '0' && text[end] <= '9') || text[end] == '.' || text[end] == 'e' ||
              text[end] == 'E' || text[end] == '+' || text[end] == '-')) {
        ++end;
      }
      const std::string literal(text.substr(i, end - i));
      const double value = std::strtod(literal.c_str(), nullptr);
      if (std::isinf(value)) {
        if (scan.count++ == 0) {
          scan.firstOffset = i;
          scan.firstLiteral = literal;
        }
        scan.text += "\"\\u0001overflow:" + literal + "\"";
      } else {
        scan.text += literal;
      }
      i = end;
      continue;
    }
    scan.text += c;
    ++i;
  }
  return scan;
}


// ---------------------------------------------------------------------------------------------------------------
// Reading.

/// Largest degree read from a file: degrees are stored as int and degree + 1 (the points it needs) must fit too.
constexpr long long kMaxDegree = std::numeric_limits<int>::max() - 1;

template <class J>
std::optional<long long> asInteger(const J& j) {
  if (j.is_number_unsigned()) {
    const auto v = j.template get<std::uint64_t>();
    return v > static_cast<std::uint64_t>(std::numeric_limits<long long>::max())
               ? std::numeric_limits<long long>::max()
               : static_cast<long long>(v);
  }
  if (j.is_number_integer()) return j.template get<std::int64_t>();
  return std::nullopt;
}

/// Pieces of a patch or curve as read from the file, before building the spline.
struct PointGrid {
  int nu = 0;  ///< rows (along u)
  int nv = 0;  ///< points per row (along v); 1 for curves
  int dim = 0;
  Matrix points;  ///< row i * nv + j
  VecX weights;   ///< empty or nu * nv
};

/// Turns a parsed JSON value into a Model, with the messages that name the file, the object and the problem.
/// J is nlohmann::json or SimdValue (the fast parser's DOM behind the same member names); one converter for both.
template <class J>
class ModelReader {
 public:
  explicit ModelReader(std::string source) : src_(std::move(source)) {}

  /// The model of `root`; out of memory is a message naming the object being read, never an exception.
  Result<Model> read(const J& root) {
    try {
      return readUnguarded(root);
    } catch (const std::bad_alloc&) {
      return invalidInput(fmt::format("{}: {}: out of memory while building its control points and knots (the model "
                                      "is too large for the memory this process may use; raise the limit or split "
                                      "the model)",
                                      src_, current_));
    }
  }

 private:
  Result<Model> readUnguarded(const J& root) {
    current_ = "the top-level object";
    if (!root.is_object()) {
      return top(std::string("the top level must be an object with \"patches\" and/or \"curves\", found ") +
                 root.type_name());
    }
    for (const auto& [key, value] : root.items()) {
      if (key != "patches" && key != "curves" && key != "brep" && key != "$schema") {
        return top("unknown top-level key " + quote(key) +
                   " (expected \"patches\" and/or \"curves\", and \"brep\")");
      }
    }
    if (!root.contains("patches") && !root.contains("curves")) {
      return top("no \"patches\" or \"curves\" array at the top level");
    }
    Model model;
    if (root.contains("patches")) {
      const auto& patches = root["patches"];
      if (!patches.is_array())
        return top(std::string("\"patches\" must be an array, found ") + patches.type_name());
      model.patches.reserve(patches.size());
      for (size_t index = 0; index < patches.size(); ++index) {
        Result<Patch> patch = readPatch(patches[index], index);
        if (!patch) return patch.status();
        model.patches.push_back(std::move(patch).value());
      }
    }
    if (root.contains("curves")) {
      const auto& curves = root["curves"];
      if (!curves.is_array())
        return top(std::string("\"curves\" must be an array, found ") + curves.type_name());
      for (size_t index = 0; index < curves.size(); ++index) {
        Result<Curve> curve = readCurve(curves[index], index);
        if (!curve) return curve.status();
        model.curves.push_back(std::move(curve).value());
      }
    }
    if (root.contains("brep")) {
      if (Status st = addBRep(root["brep"], model); !st) return st;
    }
    return model;
  }

 public:
  // One member at a time, for the streamed route of readModelJson (streamedRoute): the same converter and checks as
  // read(), which runs them in this order on the whole document. Out of memory throws std::bad_alloc here.
  Result<Patch> patchAt(const J& j, size_t index) { return readPatch(j, index); }
  Result<Curve> curveAt(const J& j, size_t index) { return readCurve(j, index); }
  /// The "brep" member `b` of `model` (its patches read): read, checked by validateBRep, and set.
  Status addBRep(const J& b, Model& model) {
    current_ = "brep";
    Result<BRepTopology> brep = readBRep(b, model);
    if (!brep) return brep.status();
    if (Status st = validateBRep(model, *brep, src_); !st) return st;
    model.trimmedFaces = countTrimmedFaces(model, *brep);
    model.brep = std::make_shared<const BRepTopology>(std::move(brep).value());
    return Status::ok();
  }

 private:

  // -------------------------------------------------------------------------------------------------------------
  // "brep" (docs/format.md, "Trimmed faces"): read here, checked by validateBRep.

  /// Only the keys in `allowed` (a member of an object of the brep).
  Status onlyKeys(const J& j, const std::string& where,
                  std::initializer_list<std::string_view> allowed) const {
    for (const auto& [key, value] : j.items())
      if (std::find(allowed.begin(), allowed.end(), std::string_view(key)) == allowed.end())
        return fail(where, "unknown key " + quote(key));
    return Status::ok();
  }
  Status needObject(const J& j, const std::string& where) const {
    if (!j.is_object()) return fail(where, std::string("must be an object, found ") + j.type_name());
    return Status::ok();
  }
  /// j[key] must be an array (empty allowed when `mayBeEmpty`).
  Status needArray(const J& j, const std::string& where, const char* key, bool required = true) const {
    if (!j.contains(key)) return required ? fail(where, fmt::format("missing \"{}\"", key)) : Status::ok();
    if (!j[key].is_array())
      return fail(where, fmt::format("\"{}\" must be an array, found {}", key, j[key].type_name()));
    return Status::ok();
  }
  Status readId(const J& j, const std::string& where, const char* what, int& out) const {
    const std::optional<long long> id = asInteger(j);
    if (!id || *id < 0 || *id > std::numeric_limits<int>::max())
      return fail(where, fmt::format("{} must be an id (an integer >= 0), found {}", what, brief(j)));
    out = static_cast<int>(*id);
    return Status::ok();
  }
  Status readOrientation(const J& j, const std::string& where, bool& reversed) const {
    if (!j.contains("orientation")) {
      reversed = false;
      return Status::ok();
    }
    const auto& o = j["orientation"];
    if (o.is_string() && o.template get<std::string>() == "forward")
      reversed = false;
    else if (o.is_string() && o.template get<std::string>() == "reversed")
      reversed = true;
    else
      return fail(where, "\"orientation\" must be \"forward\" or \"reversed\", found " + brief(o));
    return Status::ok();
  }
  Status readTolerance(const J& j, const std::string& where, double& out) const {
    out = 0.0;
    if (!j.contains("tolerance")) return Status::ok();
    if (Status s = readNumber(j["tolerance"], where, "tolerance", out); !s) return s;
    if (out < 0) return fail(where, fmt::format("tolerance {} is negative", out));
    return Status::ok();
  }
  Status readRange(const J& j, const std::string& where, double& t0, double& t1) const {
    if (!j.contains("range")) return fail(where, "missing \"range\" ([t0, t1])");
    const auto& r = j["range"];
    if (!r.is_array() || r.size() != 2) return fail(where, "\"range\" must be [t0, t1], found " + brief(r));
    if (Status s = readNumber(r[size_t{0}], where, "range t0", t0); !s) return s;
    if (Status s = readNumber(r[size_t{1}], where, "range t1", t1); !s) return s;
    if (!(t1 > t0)) return fail(where, fmt::format("range [{}, {}] is empty (t1 must be > t0)", t0, t1));
    return Status::ok();
  }
  /// A B-spline curve object {"degree", "knots", "points", "weights"} with points of dimension `dim`.
  Result<BSplineCurve> readSpline(const J& j, const std::string& where, int dim) const {
    if (Status s = needObject(j, where); !s) return s;
    if (Status s = onlyKeys(j, where, {"degree", "knots", "points", "weights"}); !s) return s;
    PointGrid grid;
    if (Status s = readCurvePoints(j, where, grid); !s) return s;
    if (grid.dim != dim)
      return fail(where, fmt::format("points have {} coordinates, expected {}", grid.dim, dim));
    if (!j.contains("degree")) return fail(where, "missing \"degree\" (an integer)");
    const std::optional<long long> d = asInteger(j["degree"]);
    if (!d) return fail(where, "\"degree\" must be an integer, found " + brief(j["degree"]));
    if (!j.contains("knots")) return fail(where, "missing \"knots\" (an array of numbers)");
    std::vector<double> knots;
    if (Status s = readKnotArray(j["knots"], where, "", knots); !s) return s;
    if (Status s = checkDegree(*d, grid.nu, where, ""); !s) return s;
    if (Status s = checkKnots(knots, static_cast<int>(*d), grid.nu, where, ""); !s) return s;
    Result<BSplineCurve> c = BSplineCurve::create(static_cast<int>(*d), std::move(knots),
                                                  std::move(grid.points), std::move(grid.weights));
    if (!c) return c.status().withContext(src_ + ": " + where);
    return c;
  }
  /// Uses of faces in a shell, shells in a solid: [{"face": id, "orientation": ...}, ...].
  Status readUses(const J& j, const std::string& where, const char* array, const char* key,
                  std::vector<BRepUse>& out) const {
    if (Status s = needArray(j, where, array); !s) return s;
    const auto& a = j[array];
    for (size_t i = 0; i < a.size(); ++i) {
      const std::string w = fmt::format("{}: {}[{}]", where, array, i);
      const auto& u = a[i];
      if (Status s = needObject(u, w); !s) return s;
      if (Status s = onlyKeys(u, w, {key, "orientation"}); !s) return s;
      if (!u.contains(key)) return fail(w, fmt::format("missing \"{}\"", key));
      BRepUse use;
      if (Status s = readId(u[key], w, key, use.id); !s) return s;
      if (Status s = readOrientation(u, w, use.reversed); !s) return s;
      out.push_back(use);
    }
    return Status::ok();
  }

  Result<BRepTopology> readBRep(const J& b, const Model& model) {
    const std::string where = "brep";
    if (Status s = needObject(b, where); !s) return s;
    if (Status s = onlyKeys(b, where, {"vertices", "edges", "faces", "shells", "solids", "roots"}); !s)
      return s;
    for (const char* key : {"vertices", "edges", "faces"})
      if (Status s = needArray(b, where, key); !s) return s;
    for (const char* key : {"shells", "solids", "roots"})
      if (Status s = needArray(b, where, key, false); !s) return s;
    BRepTopology t;
    const auto& vertices = b["vertices"];
    for (size_t i = 0; i < vertices.size(); ++i) {
      const std::string w = fmt::format("brep vertex {}", i);
      current_ = w;
      const auto& v = vertices[i];
      if (Status s = needObject(v, w); !s) return s;
      if (Status s = onlyKeys(v, w, {"point", "tolerance"}); !s) return s;
      if (!v.contains("point")) return fail(w, "missing \"point\"");
      BRepVertex vertex;
      int dim = 3;
      if (Status s = readPoint(v["point"], w, "point", dim, vertex.point.data()); !s) return s;
      if (Status s = readTolerance(v, w, vertex.tolerance); !s) return s;
      t.vertices.push_back(vertex);
    }
    const auto& edges = b["edges"];
    for (size_t i = 0; i < edges.size(); ++i) {
      const std::string w = fmt::format("brep edge {}", i);
      current_ = w;
      const auto& e = edges[i];
      if (Status s = needObject(e, w); !s) return s;
      if (Status s = onlyKeys(e, w, {"vertices", "range", "tolerance", "curve", "degenerate"}); !s) return s;
      BRepEdge edge;
      if (!e.contains("vertices") || !e["vertices"].is_array() || e["vertices"].size() != 2)
        return fail(w, "\"vertices\" must be [start vertex id, end vertex id]");
      if (Status s = readId(e["vertices"][size_t{0}], w, "start vertex", edge.v0); !s) return s;
      if (Status s = readId(e["vertices"][size_t{1}], w, "end vertex", edge.v1); !s) return s;
      if (Status s = readRange(e, w, edge.t0, edge.t1); !s) return s;
      if (Status s = readTolerance(e, w, edge.tolerance); !s) return s;
      if (e.contains("degenerate")) {
        const auto& d = e["degenerate"];
        if (!d.is_string() || d.template get<std::string>() != "yes")
          return fail(
              w, "\"degenerate\" must be \"yes\" (a degenerate edge has no 3-D curve), found " + brief(d));
        if (e.contains("curve")) return fail(w, "a degenerate edge has no \"curve\"");
        edge.degenerate = true;
      } else {
        if (!e.contains("curve")) return fail(w, "missing \"curve\" (its 3-D B-spline curve)");
        Result<BSplineCurve> c = readSpline(e["curve"], w + ": curve", 3);
        if (!c) return c.status();
        edge.curve = std::move(c).value();
      }
      t.edges.push_back(std::move(edge));
    }
    std::map<std::string, int> patchIndex;
    for (size_t k = 0; k < model.patches.size(); ++k)
      patchIndex.emplace(model.patches[k].name, static_cast<int>(k));
    const auto& faces = b["faces"];
    for (size_t i = 0; i < faces.size(); ++i) {
      const std::string w = fmt::format("brep face {}", i);
      current_ = w;
      const auto& f = faces[i];
      if (Status s = needObject(f, w); !s) return s;
      if (Status s = onlyKeys(f, w, {"patch", "orientation", "tolerance", "loops", "open_as_read"}); !s) return s;
      BRepFace face;
      if (!f.contains("patch") || !f["patch"].is_string())
        return fail(w, "\"patch\" must be the name of the face's patch");
      const std::string name = f["patch"].template get<std::string>();
      const auto it = patchIndex.find(name);
      if (it == patchIndex.end()) return fail(w, "no patch named " + quote(name));
      face.patch = it->second;
      if (Status s = readOrientation(f, w, face.reversed); !s) return s;
      if (Status s = readTolerance(f, w, face.tolerance); !s) return s;
      if (f.contains("open_as_read")) {
        const auto& o = f["open_as_read"];
        if (!(o.is_string() && o.template get<std::string>() == "yes"))
          return fail(w, "\"open_as_read\" must be \"yes\" (the face's loops do not close in the file it was read "
                         "from), found " + brief(o));
        face.openAsRead = true;
      }
      if (Status s = needArray(f, w, "loops"); !s) return s;
      const auto& loops = f["loops"];
      for (size_t l = 0; l < loops.size(); ++l) {
        const std::string lw = fmt::format("{}: loop {}", w, l);
        const auto& loop = loops[l];
        if (!loop.is_array())
          return fail(lw, std::string("must be an array of coedges, found ") + loop.type_name());
        std::vector<BRepCoedge> coedges;
        for (size_t k = 0; k < loop.size(); ++k) {
          const std::string cw = fmt::format("{}: coedge {}", lw, k);
          const auto& c = loop[k];
          if (Status s = needObject(c, cw); !s) return s;
          if (Status s = onlyKeys(c, cw, {"edge", "orientation", "range", "pcurve"}); !s) return s;
          BRepCoedge coedge;
          if (!c.contains("edge")) return fail(cw, "missing \"edge\"");
          if (Status s = readId(c["edge"], cw, "edge", coedge.edge); !s) return s;
          if (Status s = readOrientation(c, cw, coedge.reversed); !s) return s;
          if (Status s = readRange(c, cw, coedge.t0, coedge.t1); !s) return s;
          if (!c.contains("pcurve")) return fail(cw, "missing \"pcurve\" (a 2-D B-spline curve in (u, v))");
          Result<BSplineCurve> pc = readSpline(c["pcurve"], cw + ": pcurve", 2);
          if (!pc) return pc.status();
          coedge.pcurve = std::move(pc).value();
          coedges.push_back(std::move(coedge));
        }
        face.loops.push_back(std::move(coedges));
      }
      t.faces.push_back(std::move(face));
    }
    if (b.contains("shells")) {
      const auto& shells = b["shells"];
      for (size_t i = 0; i < shells.size(); ++i) {
        const std::string w = fmt::format("brep shell {}", i);
        if (Status s = needObject(shells[i], w); !s) return s;
        if (Status s = onlyKeys(shells[i], w, {"faces"}); !s) return s;
        BRepShell shell;
        if (Status s = readUses(shells[i], w, "faces", "face", shell.faces); !s) return s;
        t.shells.push_back(std::move(shell));
      }
    }
    if (b.contains("solids")) {
      const auto& solids = b["solids"];
      for (size_t i = 0; i < solids.size(); ++i) {
        const std::string w = fmt::format("brep solid {}", i);
        if (Status s = needObject(solids[i], w); !s) return s;
        if (Status s = onlyKeys(solids[i], w, {"shells"}); !s) return s;
        BRepSolid solid;
        if (Status s = readUses(solids[i], w, "shells", "shell", solid.shells); !s) return s;
        t.solids.push_back(std::move(solid));
      }
    }
    if (b.contains("roots")) {
      const auto& roots = b["roots"];
      for (size_t i = 0; i < roots.size(); ++i) {
        const std::string w = fmt::format("brep root {}", i);
        const auto& r = roots[i];
        if (Status s = needObject(r, w); !s) return s;
        if (Status s = onlyKeys(r, w, {"solid", "shell", "face", "orientation"}); !s) return s;
        BRepRoot root;
        int kinds = 0;
        for (const auto& [key, kind] :
             {std::pair{"solid", BRepRoot::Kind::kSolid}, std::pair{"shell", BRepRoot::Kind::kShell},
              std::pair{"face", BRepRoot::Kind::kFace}}) {
          if (!r.contains(key)) continue;
          ++kinds;
          root.kind = kind;
          if (Status s = readId(r[key], w, key, root.use.id); !s) return s;
        }
        if (kinds != 1) return fail(w, "must name exactly one of \"solid\", \"shell\", \"face\"");
        if (Status s = readOrientation(r, w, root.use.reversed); !s) return s;
        t.roots.push_back(root);
      }
    } else {
      // Without "roots": the solids, then the shells in no solid, then the faces in no shell.
      std::vector<bool> shellUsed(t.shells.size()), faceUsed(t.faces.size());
      for (const BRepSolid& s : t.solids)
        for (const BRepUse& u : s.shells)
          if (u.id >= 0 && static_cast<size_t>(u.id) < shellUsed.size())
            shellUsed[static_cast<size_t>(u.id)] = true;
      for (const BRepShell& s : t.shells)
        for (const BRepUse& u : s.faces)
          if (u.id >= 0 && static_cast<size_t>(u.id) < faceUsed.size())
            faceUsed[static_cast<size_t>(u.id)] = true;
      for (size_t i = 0; i < t.solids.size(); ++i)
        t.roots.push_back({BRepRoot::Kind::kSolid, {static_cast<int>(i), false}});
      for (size_t i = 0; i < t.shells.size(); ++i)
        if (!shellUsed[i]) t.roots.push_back({BRepRoot::Kind::kShell, {static_cast<int>(i), false}});
      for (size_t i = 0; i < t.faces.size(); ++i)
        if (!faceUsed[i])
          t.roots.push_back({BRepRoot::Kind::kFace, {static_cast<int>(i), t.faces[i].reversed}});
    }
    return t;
  }

  Status top(const std::string& problem) const { return invalidInput(src_ + ": " + problem); }
  Status fail(const std::string& where, const std::string& problem) const {
    return invalidInput(src_ + ": " + where + ": " + problem);
  }

  /// Reads "name" of element `index` of the "patches"/"curves" array and checks it is unique. On success
  /// `where` becomes `patch "S1"` / `curve "C1"`.
  Status readName(const J& j, const char* kind, const char* array, size_t index, std::string& name,
                  std::string& where) {
    where = fmt::format("{}[{}]", array, index);
    current_ = where;
    if (!j.is_object()) return fail(where, std::string("must be an object, found ") + j.type_name());
    if (!j.contains("name")) return fail(where, "missing \"name\"");
    const auto& n = j["name"];
    if (!n.is_string() || n.template get_ref<const std::string&>().empty()) {
      return fail(where, "\"name\" must be a non-empty string, found " + brief(n));
    }
    name = n.template get<std::string>();
    where = std::string(kind) + " " + quote(name);
    current_ = where;
    const auto [it, inserted] = usedNames_.emplace(name, where);
    if (!inserted) return fail(where, "duplicate name (already used by " + it->second + ")");
    return Status::ok();
  }

  /// Reads "type": "bspline" or "bezier" and rejects keys that the type does not have.
  Status readType(const J& j, const std::string& where, const char* kind, bool& bezier) {
    if (!j.contains("type")) return fail(where, "missing \"type\" (\"bspline\" or \"bezier\")");
    const auto& t = j["type"];
    if (!t.is_string())
      return fail(where, "\"type\" must be the string \"bspline\" or \"bezier\", found " + brief(t));
    const std::string& type = t.template get_ref<const std::string&>();
    if (type != "bspline" && type != "bezier") {
      return fail(where, "unknown type " + quote(type) + " (expected \"bspline\" or \"bezier\")");
    }
    bezier = type == "bezier";
    for (const auto& [key, value] : j.items()) {
      if (key == "name" || key == "type" || key == "points" || key == "weights" || key == "degree") continue;
      if (key == "knots" && !bezier) continue;
      if (key == "knots") {
        return fail(where, std::string("a bezier ") + kind +
                               " has no \"knots\" (its degree is the number of points minus 1; use type "
                               "\"bspline\" to give knots)");
      }
      return fail(where, "unknown key " + quote(key));
    }
    return Status::ok();
  }

  /// A finite number, or a message naming `what` (e.g. `point [1][2]: z`, `u knot 3`).
  Status readNumber(const J& j, const std::string& where, const std::string& what, double& out) const {
    if (j.is_string()) {
      const std::string& s = j.template get_ref<const std::string&>();
      if (s.compare(0, kOverflowMarker.size(), kOverflowMarker) == 0) {
        return fail(where, what + " = " + s.substr(kOverflowMarker.size()) +
                               " is not a finite number (it overflows a double)");
      }
    }
    if (!j.is_number()) return fail(where, what + " is not a number (found " + brief(j) + ")");
    out = j.template get<double>();
    if (!std::isfinite(out)) return fail(where, what + " = " + num(out) + " is not a finite number");
    return Status::ok();
  }

  Status readWeight(const J& j, const std::string& where, const std::string& what, double& out) const {
    if (Status s = readNumber(j, where, what, out); !s) return s;
    if (!(out > 0.0)) return fail(where, what + " = " + num(out) + " is not positive (weights must be > 0)");
    return Status::ok();
  }

  /// One point: an array of numbers with `dim` entries (dim = 0: take 2 or 3 from this point).
  Status readPoint(const J& j, const std::string& where, const std::string& what, int& dim,
                   double* out) const {
    const char* expected = dim == 0 ? "2 or 3" : (dim == 2 ? "2" : "3");
    if (!j.is_array()) {
      return fail(where, what + " must be an array of " + expected + " numbers, found " + brief(j));
    }
    const int count = static_cast<int>(j.size());
    if (dim == 0) {
      if (count != 2 && count != 3)
        return fail(where, fmt::format("{} has {} coordinates, expected 2 or 3", what, count));
      dim = count;
    } else if (count != dim) {
      return fail(where, fmt::format("{} has {} coordinates, expected {}", what, count, dim));
    }
    for (int k = 0; k < count; ++k) {
      if (Status s = readNumber(j[static_cast<size_t>(k)], where, what + ": " + axisName(k), out[k]); !s)
        return s;
    }
    return Status::ok();
  }

  /// The degrees against the size of a patch's grid (nu rows of nv points), before its points are read: the
  /// messages of readPatch's later checks, given first. A malformed "degree" is left to readPatch.
  Status checkGridShape(const J& j, const std::string& where, size_t nu, size_t nv) const {
    const int numU = static_cast<int>(nu);
    const int numV = static_cast<int>(nv);
    const auto& t = j["type"];
    if (t.is_string() && t.template get<std::string>() == "bezier") {
      if (Status s = checkDegree(numU - 1, numU, where, "u "); !s) return s;
      return checkDegree(numV - 1, numV, where, "v ");
    }
    if (!j.contains("degree")) return Status::ok();
    const auto& d = j["degree"];
    if (!d.is_array() || d.size() != 2 || !asInteger(d[0]) || !asInteger(d[1])) return Status::ok();
    if (Status s = checkDegree(*asInteger(d[0]), numU, where, "u "); !s) return s;
    return checkDegree(*asInteger(d[1]), numV, where, "v ");
  }

  /// "points" (and "weights") of a patch: points[i][j] = [x, y, z], i along u.
  Status readPatchGrid(const J& j, const std::string& where, PointGrid& grid) const {
    if (!j.contains("points")) return fail(where, "missing \"points\"");
    const auto& rows = j["points"];
    if (!rows.is_array() || rows.empty()) {
      return fail(where,
                  "\"points\" must be a non-empty array of rows of points [[[x, y, z], ...], ...], found " +
                      brief(rows));
    }
    const size_t rowSize = rows[0].is_array() ? rows[0].size() : 0;
    for (size_t i = 0; i < rows.size(); ++i) {
      const auto& r = rows[i];
      if (!r.is_array() || r.empty()) {
        return fail(where, fmt::format("\"points\"[{}] must be a non-empty array of points [[x, y, z], ...], "
                                       "found {}",
                                       i, brief(r)));
      }
      if (r.size() != rowSize) {
        return fail(where, fmt::format("ragged point grid: row {} has {} points, row 0 has {}", i, r.size(),
                                       rowSize));
      }
    }
    // The size of the grid is checked against the degrees before any point is read, so that a hostile shape (a
    // single row of 10^6 points) is refused before work that grows with it.
    if (Status s = checkGridShape(j, where, rows.size(), rowSize); !s) return s;
    grid.nu = static_cast<int>(rows.size());
    grid.nv = static_cast<int>(rowSize);
    grid.dim = 3;
    grid.points.resize(static_cast<Eigen::Index>(grid.nu) * grid.nv, 3);
    for (int i = 0; i < grid.nu; ++i) {
      // One value per row, indexed by k: the fast route's value lists a long row's elements once (SimdValue's
      // operator[]); taking rows[i] again for each point walked the row from its start (quadratic in its length).
      const auto& row = rows[static_cast<size_t>(i)];
      for (int k = 0; k < grid.nv; ++k) {
        const Eigen::Index at = static_cast<Eigen::Index>(i) * grid.nv + k;
        if (Status s = readPoint(row[static_cast<size_t>(k)], where, fmt::format("point [{}][{}]", i, k),
                                 grid.dim, grid.points.row(at).data());
            !s) {
          return s;
        }
      }
    }
    if (!j.contains("weights")) return Status::ok();
    const auto& w = j["weights"];
    if (!w.is_array()) {
      return fail(
          where, "\"weights\" must be an array of rows of numbers shaped like \"points\", found " + brief(w));
    }
    if (static_cast<int>(w.size()) != grid.nu) {
      return fail(where,
                  fmt::format("\"weights\" has {} rows, expected {} like \"points\"", w.size(), grid.nu));
    }
    grid.weights.resize(static_cast<Eigen::Index>(grid.nu) * grid.nv);
    for (int i = 0; i < grid.nu; ++i) {
      const auto& row = w[static_cast<size_t>(i)];
      if (!row.is_array() || static_cast<int>(row.size()) != grid.nv) {
        return fail(
            where, fmt::format("\"weights\"[{}] must be an array of {} numbers like \"points\"[{}], found {}",
                               i, grid.nv, i, brief(row)));
      }
      for (int k = 0; k < grid.nv; ++k) {
        if (Status s = readWeight(row[static_cast<size_t>(k)], where, fmt::format("weight [{}][{}]", i, k),
                                  grid.weights[static_cast<Eigen::Index>(i) * grid.nv + k]);
            !s) {
          return s;
        }
      }
    }
    return Status::ok();
  }

  /// "points" (and "weights") of a curve: points[i] = [x, y, z] or [x, y] (all the same dimension).
  Status readCurvePoints(const J& j, const std::string& where, PointGrid& grid) const {
    if (!j.contains("points")) return fail(where, "missing \"points\"");
    const auto& pts = j["points"];
    if (!pts.is_array() || pts.empty()) {
      return fail(where,
                  "\"points\" must be a non-empty array of points [[x, y, z], ...], found " + brief(pts));
    }
    grid.nu = static_cast<int>(pts.size());
    grid.nv = 1;
    grid.dim = 0;
    std::vector<double> values(3 * pts.size());
    for (int i = 0; i < grid.nu; ++i) {
      const std::string what = fmt::format("point {}", i);
      const int before = grid.dim;
      if (Status s = readPoint(pts[static_cast<size_t>(i)], where, what, grid.dim, values.data() + 3 * i);
          !s) {
        if (before != 0 && pts[static_cast<size_t>(i)].is_array() &&
            static_cast<int>(pts[static_cast<size_t>(i)].size()) != before) {
          return fail(where, fmt::format("{} has {} coordinates, expected {} like point 0", what,
                                         pts[static_cast<size_t>(i)].size(), before));
        }
        return s;
      }
    }
    grid.points.resize(grid.nu, grid.dim);
    for (int i = 0; i < grid.nu; ++i) {
      for (int k = 0; k < grid.dim; ++k) grid.points(i, k) = values[static_cast<size_t>(3 * i + k)];
    }
    if (!j.contains("weights")) return Status::ok();
    const auto& w = j["weights"];
    if (!w.is_array()) return fail(where, "\"weights\" must be an array of numbers, found " + brief(w));
    if (static_cast<int>(w.size()) != grid.nu) {
      return fail(where,
                  fmt::format("\"weights\" has {} entries, expected {} (one per point)", w.size(), grid.nu));
    }
    grid.weights.resize(grid.nu);
    for (int i = 0; i < grid.nu; ++i) {
      if (Status s =
              readWeight(w[static_cast<size_t>(i)], where, fmt::format("weight {}", i), grid.weights[i]);
          !s) {
        return s;
      }
    }
    return Status::ok();
  }

  /// Checks a degree read from the file against the number of control points in that direction.
  Status checkDegree(long long degree, int numPoints, const std::string& where,
                     const std::string& dir) const {
    if (degree < 1) return fail(where, fmt::format("{}degree is {}, must be at least 1", dir, degree));
    if (degree > kMaxDegree) {
      return fail(where, fmt::format("{}degree {} is too large (at most {}, and at most the number of control "
                                     "points{} minus 1, here {})",
                                     dir, degree, kMaxDegree, dir.empty() ? "" : " in that direction", numPoints - 1));
    }
    if (degree > numPoints - 1) {
      return fail(where, fmt::format("{}degree {} needs at least {} control points{}, found {}", dir, degree,
                                     degree + 1, dir.empty() ? "" : " in that direction", numPoints));
    }
    return Status::ok();
  }

  /// A knot vector: an array of finite numbers.
  Status readKnotArray(const J& j, const std::string& where, const std::string& dir,
                       std::vector<double>& knots) const {
    if (!j.is_array()) {
      return fail(where, fmt::format("{}knot vector must be an array of numbers, found {}", dir, brief(j)));
    }
    knots.resize(j.size());
    for (size_t k = 0; k < j.size(); ++k) {
      if (Status s = readNumber(j[k], where, fmt::format("{}knot {}", dir, k), knots[k]); !s) return s;
    }
    return Status::ok();
  }

  /// The knot checks of KnotVector::validate, with messages that say which knot is wrong.
  Status checkKnots(const std::vector<double>& t, int degree, int numPoints, const std::string& where,
                    const std::string& dir) const {
    const size_t expected = static_cast<size_t>(numPoints) + static_cast<size_t>(degree) + 1;
    if (t.size() != expected) {
      return fail(where,
                  fmt::format("{}knot vector has {} entries, expected {} for {} control points of degree {}",
                              dir, t.size(), expected, numPoints, degree));
    }
    for (size_t k = 1; k < t.size(); ++k) {
      if (t[k] < t[k - 1]) {
        return fail(where, fmt::format("{}knots must be non-decreasing, but knot {} ({}) < knot {} ({})", dir,
                                       k, num(t[k]), k - 1, num(t[k - 1])));
      }
    }
    // Knots closer than kKnotRelTol x (length of the knot vector) are the same knot, as in KnotVector.
    const double tol = kKnotRelTol * (t.back() - t.front());
    const double lo = t[static_cast<size_t>(degree)];
    const double hi = t[static_cast<size_t>(numPoints)];
    if (hi - lo <= tol) {
      return fail(where, fmt::format("{}parameter domain [{}, {}] is empty (knots {} and {} are equal)", dir,
                                     num(lo), num(hi), degree, numPoints));
    }
    size_t first = 0;
    while (first < t.size()) {
      size_t last = first;
      while (last + 1 < t.size() && t[last + 1] - t[first] <= tol) ++last;
      const int mult = static_cast<int>(last - first + 1);
      const double value = t[first];
      const bool interior = value - lo > tol && hi - value > tol;
      if (interior && mult > degree) {
        return fail(where,
                    fmt::format("{}knot {} has multiplicity {} inside the domain, more than the degree {}",
                                dir, num(value), mult, degree));
      }
      if (mult > degree + 1) {
        return fail(where, fmt::format("{}knot {} has multiplicity {}, more than degree + 1 = {}", dir,
                                       num(value), mult, degree + 1));
      }
      first = last + 1;
    }
    return Status::ok();
  }

  Result<Patch> readPatch(const J& j, size_t index) {
    Patch patch;
    std::string where;
    if (Status s = readName(j, "patch", "patches", index, patch.name, where); !s) return s;
    bool bezier = false;
    if (Status s = readType(j, where, "patch", bezier); !s) return s;
    PointGrid grid;
    if (Status s = readPatchGrid(j, where, grid); !s) return s;

    long long pu = grid.nu - 1;
    long long pv = grid.nv - 1;
    std::vector<double> ku;
    std::vector<double> kv;
    if (bezier) {
      if (Status s = checkBezierDegree(j, where, {grid.nu, grid.nv}); !s) return s;
      ku = bezierKnots(static_cast<int>(pu));
      kv = bezierKnots(static_cast<int>(pv));
    } else {
      if (!j.contains("degree")) return fail(where, "missing \"degree\" ([p, q] for a bspline patch)");
      const auto& d = j["degree"];
      if (!d.is_array() || d.size() != 2 || !asInteger(d[0]) || !asInteger(d[1])) {
        return fail(where, "\"degree\" must be an array of two integers [p, q], found " + brief(d));
      }
      pu = *asInteger(d[0]);
      pv = *asInteger(d[1]);
      if (!j.contains("knots"))
        return fail(where, "missing \"knots\" ([[u knots], [v knots]] for a bspline patch)");
      const auto& k = j["knots"];
      if (!k.is_array() || k.size() != 2) {
        return fail(where, "\"knots\" must be an array of two knot vectors [[u knots], [v knots]], found " +
                               brief(k));
      }
      if (Status s = readKnotArray(k[0], where, "u ", ku); !s) return s;
      if (Status s = readKnotArray(k[1], where, "v ", kv); !s) return s;
    }
    if (Status s = checkDegree(pu, grid.nu, where, "u "); !s) return s;
    if (Status s = checkDegree(pv, grid.nv, where, "v "); !s) return s;
    if (Status s = checkKnots(ku, static_cast<int>(pu), grid.nu, where, "u "); !s) return s;
    if (Status s = checkKnots(kv, static_cast<int>(pv), grid.nv, where, "v "); !s) return s;

    Result<BSplineSurface> surface =
        BSplineSurface::create(static_cast<int>(pu), static_cast<int>(pv), std::move(ku), std::move(kv),
                               grid.nu, grid.nv, std::move(grid.points), std::move(grid.weights));
    if (!surface) return surface.status().withContext(src_ + ": " + where);
    patch.kind = bezier ? PatchKind::kBezier : PatchKind::kBSpline;
    patch.surface = std::move(surface).value();
    return patch;
  }

  /// A bezier object may repeat its degree; it must then be (number of points - 1) per direction.
  Status checkBezierDegree(const J& j, const std::string& where, std::vector<int> counts) const {
    if (!j.contains("degree")) return Status::ok();
    const auto& d = j["degree"];
    bool matches = false;
    if (counts.size() == 1) {
      matches = asInteger(d) && *asInteger(d) == counts[0] - 1;
    } else {
      matches = d.is_array() && d.size() == 2 && asInteger(d[0]) && asInteger(d[1]) &&
                *asInteger(d[0]) == counts[0] - 1 && *asInteger(d[1]) == counts[1] - 1;
    }
    if (matches) return Status::ok();
    const std::string expected = counts.size() == 1 ? fmt::format("{}", counts[0] - 1)
                                                    : fmt::format("[{}, {}]", counts[0] - 1, counts[1] - 1);
    return fail(where, "\"degree\" " + brief(d) +
                           " does not match the control points: a bezier degree is the "
                           "number of points minus 1, here " +
                           expected);
  }

  Result<Curve> readCurve(const J& j, size_t index) {
    Curve curve;
    std::string where;
    if (Status s = readName(j, "curve", "curves", index, curve.name, where); !s) return s;
    bool bezier = false;
    if (Status s = readType(j, where, "curve", bezier); !s) return s;
    PointGrid grid;
    if (Status s = readCurvePoints(j, where, grid); !s) return s;

    long long p = grid.nu - 1;
    std::vector<double> knots;
    if (bezier) {
      if (Status s = checkBezierDegree(j, where, {grid.nu}); !s) return s;
      knots = bezierKnots(static_cast<int>(p));
    } else {
      if (!j.contains("degree")) return fail(where, "missing \"degree\" (an integer for a bspline curve)");
      const std::optional<long long> d = asInteger(j["degree"]);
      if (!d) return fail(where, "\"degree\" must be an integer, found " + brief(j["degree"]));
      p = *d;
      if (!j.contains("knots"))
        return fail(where, "missing \"knots\" (an array of numbers for a bspline curve)");
      if (Status s = readKnotArray(j["knots"], where, "", knots); !s) return s;
    }
    if (Status s = checkDegree(p, grid.nu, where, ""); !s) return s;
    if (Status s = checkKnots(knots, static_cast<int>(p), grid.nu, where, ""); !s) return s;

    Result<BSplineCurve> c = BSplineCurve::create(static_cast<int>(p), std::move(knots),
                                                  std::move(grid.points), std::move(grid.weights));
    if (!c) return c.status().withContext(src_ + ": " + where);
    curve.curve = std::move(c).value();
    return curve;
  }

  static std::vector<double> bezierKnots(int degree) {
    std::vector<double> knots(static_cast<size_t>(2 * (degree + 1)), 0.0);
    for (size_t k = knots.size() / 2; k < knots.size(); ++k) knots[k] = 1.0;
    return knots;
  }

  std::string src_;
  std::string current_;  ///< the object being read (`patch "S1"`), for an out-of-memory message
  std::map<std::string, std::string> usedNames_;  ///< name -> `patch "S1"` / `curve "C1"`
};

// ---------------------------------------------------------------------------------------------------------------
// Writing.

/// Appends the JSON number text that reads back bit-identical: nlohmann's shortest round-trip form ("1.0", "-0.0",
/// "1e+300"), the bytes of Json(x).dump(), written in place (no JSON value and no string per number: the model
/// writer formats millions of them). Non-finite values cannot occur in a valid model; they are written as nlohmann
/// writes them ("null").
void appendNumber(std::string& out, double x) {
  if (!std::isfinite(x)) {
    out += "null";
    return;
  }
  constexpr size_t kNumberBuffer = 64;  // nlohmann's serializer buffer
  std::array<char, kNumberBuffer> buffer{};
  char* end = nlohmann::detail::to_chars(buffer.data(), buffer.data() + buffer.size(), x);
  out.append(buffer.data(), end);
}

/// True when the knots are exactly degree+1 zeros followed by degree+1 ones (the implied knots of a
/// "bezier").
bool isBezierKnots(const KnotVector& knots, int degree, int numPoints) {
  if (numPoints != degree + 1 || knots.size() != 2 * (degree + 1)) return false;
  for (int k = 0; k < knots.size(); ++k) {
    const double expected = k <= degree ? 0.0 : 1.0;
    if (knots[k] != expected || std::signbit(knots[k])) return false;
  }
  return true;
}

void appendNumbers(std::string& out, const double* values, Eigen::Index count) {
  out += '[';
  for (Eigen::Index k = 0; k < count; ++k) {
    if (k > 0) out += ", ";
    appendNumber(out, values[k]);
  }
  out += ']';
}

void appendNumbers(std::string& out, const std::vector<double>& values) {
  appendNumbers(out, values.data(), static_cast<Eigen::Index>(values.size()));
}

void appendPoint(std::string& out, const Matrix& points, Eigen::Index row) {
  out += '[';
  for (Eigen::Index k = 0; k < points.cols(); ++k) {
    if (k > 0) out += ", ";
    appendNumber(out, points(row, k));
  }
  out += ']';
}

void appendPatch(std::string& out, const Patch& patch) {
  const BSplineSurface& s = patch.surface;
  const bool bezier = patch.kind == PatchKind::kBezier && isBezierKnots(s.knotsU(), s.degreeU(), s.numU()) &&
                      isBezierKnots(s.knotsV(), s.degreeV(), s.numV());
  out += "    {\n      \"name\": " + quote(patch.name) + ",\n";
  out += std::string("      \"type\": \"") + (bezier ? "bezier" : "bspline") + "\",\n";
  if (!bezier) {
    out += fmt::format("      \"degree\": [{}, {}],\n", s.degreeU(), s.degreeV());
    out += "      \"knots\": [\n        ";
    appendNumbers(out, s.knotsU().values());
    out += ",\n        ";
    appendNumbers(out, s.knotsV().values());
    out += "\n      ],\n";
  }
  out += "      \"points\": [\n";
  for (int i = 0; i < s.numU(); ++i) {
    out += "        [\n";
    for (int j = 0; j < s.numV(); ++j) {
      out += "          ";
      appendPoint(out, s.points(), static_cast<Eigen::Index>(i) * s.numV() + j);
      out += j + 1 < s.numV() ? ",\n" : "\n";
    }
    out += i + 1 < s.numU() ? "        ],\n" : "        ]\n";
  }
  out += "      ]";
  if (s.isRational()) {
    out += ",\n      \"weights\": [\n";
    for (int i = 0; i < s.numU(); ++i) {
      out += "        ";
      appendNumbers(out, s.weights().data() + static_cast<Eigen::Index>(i) * s.numV(), s.numV());
      out += i + 1 < s.numU() ? ",\n" : "\n";
    }
    out += "      ]";
  }
  out += "\n    }";
}

/// A B-spline curve of the brep on one line: {"degree": p, "knots": [...], "points": [[...], ...], "weights":
/// [...]}.
void appendSplineInline(std::string& out, const BSplineCurve& c) {
  out += fmt::format("{{\"degree\": {}, \"knots\": ", c.degree());
  appendNumbers(out, c.knots().values());
  out += ", \"points\": [";
  for (int i = 0; i < c.numPoints(); ++i) {
    if (i > 0) out += ", ";
    appendPoint(out, c.points(), i);
  }
  out += ']';
  if (c.isRational()) {
    out += ", \"weights\": ";
    appendNumbers(out, c.weights().data(), c.weights().size());
  }
  out += '}';
}

const char* orientationName(bool reversed) { return reversed ? "reversed" : "forward"; }

/// The "brep" member (docs/format.md, "Trimmed faces"): one vertex, edge, coedge, shell, solid or root a
/// line.
void appendBRep(std::string& out, const Model& model, const BRepTopology& b) {
  out += ",\n  \"brep\": {\n    \"vertices\": [";
  for (size_t i = 0; i < b.vertices.size(); ++i) {
    out += i == 0 ? "\n      {\"point\": " : ",\n      {\"point\": ";
    appendNumbers(out, b.vertices[i].point.data(), 3);
    out += ", \"tolerance\": ";
    appendNumber(out, b.vertices[i].tolerance);
    out += '}';
  }
  out += b.vertices.empty() ? "],\n    \"edges\": [" : "\n    ],\n    \"edges\": [";
  for (size_t i = 0; i < b.edges.size(); ++i) {
    const BRepEdge& e = b.edges[i];
    out += i == 0 ? "\n      " : ",\n      ";
    out += fmt::format("{{\"vertices\": [{}, {}], \"range\": ", e.v0, e.v1);
    appendNumbers(out, std::vector<double>{e.t0, e.t1});
    out += ", \"tolerance\": ";
    appendNumber(out, e.tolerance);
    if (e.degenerate) {
      out += ", \"degenerate\": \"yes\"}";
    } else {
      out += ", \"curve\": ";
      appendSplineInline(out, e.curve);
      out += '}';
    }
  }
  out += b.edges.empty() ? "],\n    \"faces\": [" : "\n    ],\n    \"faces\": [";
  for (size_t i = 0; i < b.faces.size(); ++i) {
    const BRepFace& f = b.faces[i];
    out += i == 0 ? "\n      {" : ",\n      {";
    out += "\"patch\": " + quote(model.patches[static_cast<size_t>(f.patch)].name) + ", \"orientation\": \"" +
           orientationName(f.reversed) + "\", \"tolerance\": ";
    appendNumber(out, f.tolerance);
    if (f.openAsRead) out += ", \"open_as_read\": \"yes\"";
    out += ", \"loops\": [";
    for (size_t l = 0; l < f.loops.size(); ++l) {
      out += l == 0 ? "\n        [" : ",\n        [";
      for (size_t k = 0; k < f.loops[l].size(); ++k) {
        const BRepCoedge& c = f.loops[l][k];
        out += k == 0 ? "\n          " : ",\n          ";
        out += fmt::format("{{\"edge\": {}, \"orientation\": \"{}\", \"range\": ", c.edge,
                           orientationName(c.reversed));
        appendNumbers(out, std::vector<double>{c.t0, c.t1});
        out += ", \"pcurve\": ";
        appendSplineInline(out, c.pcurve);
        out += '}';
      }
      out += "\n        ]";
    }
    out += "\n      ]}";
  }
  out += b.faces.empty() ? "]" : "\n    ]";
  auto uses = [&](const char* key, const std::vector<BRepUse>& list) {
    std::string s = "[";
    for (size_t k = 0; k < list.size(); ++k)
      s += fmt::format("{}{{\"{}\": {}, \"orientation\": \"{}\"}}", k == 0 ? "" : ", ", key, list[k].id,
                       orientationName(list[k].reversed));
    return s + "]";
  };
  out += ",\n    \"shells\": [";
  for (size_t i = 0; i < b.shells.size(); ++i)
    out +=
        (i == 0 ? "\n      {\"faces\": " : ",\n      {\"faces\": ") + uses("face", b.shells[i].faces) + "}";
  out += b.shells.empty() ? "]" : "\n    ]";
  out += ",\n    \"solids\": [";
  for (size_t i = 0; i < b.solids.size(); ++i)
    out += (i == 0 ? "\n      {\"shells\": " : ",\n      {\"shells\": ") + uses("shell", b.solids[i].shells) +
           "}";
  out += b.solids.empty() ? "]" : "\n    ]";
  out += ",\n    \"roots\": [";
  for (size_t i = 0; i < b.roots.size(); ++i) {
    const BRepRoot& r = b.roots[i];
    const char* kind = r.kind == BRepRoot::Kind::kSolid   ? "solid"
                       : r.kind == BRepRoot::Kind::kShell ? "shell"
                                                          : "face";
    out += fmt::format("{}{{\"{}\": {}, \"orientation\": \"{}\"}}", i == 0 ? "\n      " : ",\n      ", kind,
                       r.use.id, orientationName(r.use.reversed));
  }
  out += b.roots.empty() ? "]" : "\n    ]";
  out += "\n  }";
}

void appendCurve(std::string& out, const Curve& curve) {
  const BSplineCurve& c = curve.curve;
  const bool bezier = isBezierKnots(c.knots(), c.degree(), c.numPoints());
  out += "    {\n      \"name\": " + quote(curve.name) + ",\n";
  out += std::string("      \"type\": \"") + (bezier ? "bezier" : "bspline") + "\",\n";
  if (!bezier) {
    out += fmt::format("      \"degree\": {},\n", c.degree());
    out += "      \"knots\": ";
    appendNumbers(out, c.knots().values());
    out += ",\n";
  }
  out += "      \"points\": [\n";
  for (int i = 0; i < c.numPoints(); ++i) {
    out += "        ";
    appendPoint(out, c.points(), i);
    out += i + 1 < c.numPoints() ? ",\n" : "\n";
  }
  out += "      ]";
  if (c.isRational()) {
    out += ",\n      \"weights\": ";
    appendNumbers(out, c.weights().data(), c.weights().size());
  }
  out += "\n    }";
}

}  // namespace

std::string jsonExceptionText(const char* what) {
  std::string s(what);
  if (!s.empty() && s[0] == '[') {
    const size_t close = s.find("] ");
    if (close != std::string::npos) s = s.substr(close + 2);
  }
  return s;
}

namespace {

/// The message of an out-of-memory while reading `src`: the file, what was being built, and what to do.
Status outOfMemory(const std::string& src, const std::string& what) {
  return invalidInput(fmt::format("{}: out of memory while {} (the model is too large for the memory this process "
                                  "may use; raise the limit or split the model)",
                                  src, what));
}

/// Parses `text` into `doc` through nlohmann's SAX parser. False with `builder`'s error when the text is not JSON.
bool parseCompact(std::string_view text, size_t values, CompactDoc& doc, int& errorId, std::string& error) {
  doc = CompactDoc();
  try {
    doc.reserve(values);
  } catch (const std::bad_alloc&) {
    doc = CompactDoc();  // too much at once for this process: the arrays grow as the text is read
  }
  CompactDoc::Builder builder(doc);
  if (Json::sax_parse(text, &builder)) return true;
  errorId = builder.errorId;
  error = builder.error;
  return false;
}

}  // namespace

Result<Model> detail::parseModelJsonNlohmann(std::string_view text, std::string_view source) {
  const std::string src(source);
  size_t values = 0;
  if (Status s = scanJsonText(text, src, &values); !s) return s;
  std::string stage = fmt::format("building the document of its JSON text ({} bytes, {} values)", text.size(), values);
  try {
    CompactDoc doc;
    int errorId = 0;
    std::string error;
    if (!parseCompact(text, values, doc, errorId, error)) {
      // nlohmann's parse_error ids are 1xx; a number literal that overflows a double (1e999) is out_of_range 406,
      // without a position: mark such literals and parse again, so that the model reader names the object that
      // holds the number.
      constexpr int kParseErrorIds = 100;
      if (errorId / kParseErrorIds == 1) return invalidInput(src + ": not valid JSON: " + jsonExceptionText(error.c_str()));
      stage = "rewriting the number literals that overflow a double";
      const OverflowScan scan = rewriteOverflowingNumbers(text);
      if (scan.count == 0) return invalidInput(src + ": not valid JSON: " + jsonExceptionText(error.c_str()));
      stage = fmt::format("building the document of its JSON text ({} bytes, {} values)", scan.text.size(), values);
      if (!parseCompact(scan.text, values, doc, errorId, error)) {
        return invalidInput(src + ": not valid JSON: " + lineColumn(text, scan.firstOffset) + ": number " +
                            scan.firstLiteral + " is not a finite number (it overflows a double)");
      }
    }
    return ModelReader<DocValue>(src).read(DocValue(&doc, 0));
  } catch (const std::bad_alloc&) {
    return outOfMemory(src, stage);
  } catch (const std::exception& e) {
    // Not expected (every access is checked first); never let an exception leave the library.
    return invalidInput(src + ": " + e.what());
  }
}

namespace {

/// The fast route on `size` bytes of `text`. `padded`: text holds simdjson's padding after them (readModelJson),
/// so simdjson parses it in place instead of copying it; then, once parsed, `owner` (the text's string) is freed
/// and so is the parser's index of the text, before the model is built: the peak is the text and simdjson's tape,
/// not the text twice, the tape, the index and the model (issue 39 goal 4).
std::optional<Model> fastRoute(const char* text, size_t size, bool padded, std::string* owner,
                               std::string_view source) {
  const std::string src(source);
  // A \u escape (only names and types hold strings) goes the nlohmann way: the two parsers differ on lone
  // surrogates, and models rarely have one.
  if (std::string_view(text, size).find("\\u") != std::string_view::npos) return std::nullopt;
  // scanJsonText's checks without its pass over the text: simdjson refuses a NUL byte (outside a string it is no
  // JSON, inside one an unescaped control character) and, with this limit, nesting deeper than kMaxJsonDepth.
  // Out of memory anywhere here declines too: the nlohmann route needs less, and says what it could not build.
  simdjson::dom::document doc;
  {
    simdjson::dom::parser parser;
    if (parser.allocate(size, kMaxJsonDepth) != simdjson::SUCCESS) return std::nullopt;
    simdjson::dom::element parsed;
    // Syntax errors, numbers that overflow a double, integers beyond 64 bits, invalid UTF-8, a byte-order mark:
    // declined, the nlohmann route gives its message or reads it as before.
    if (parser.parse(text, size, !padded).get(parsed) != simdjson::SUCCESS) return std::nullopt;
    doc = std::move(parser.doc);  // the tape and strings; the parser's index of the text goes with the parser
  }
  if (owner != nullptr) {
    owner->clear();
    owner->shrink_to_fit();
  }
  try {
    Result<Model> model = ModelReader<SimdValue>(src).read(SimdValue(doc.root()));
    if (!model) return std::nullopt;  // the message comes from the nlohmann route, exactly as before
    return std::move(model).value();
  } catch (const std::exception&) {
    return std::nullopt;  // not expected (every access is checked first); the nlohmann route decides
  }
}

}  // namespace

/// The text of a file read forward in chunks, of which only the part from the oldest byte still needed is held
/// (streamedRoute). Positions are offsets in the file. Any read error ends the text (the route then declines, and
/// readFile says what went wrong).
class ChunkedFile {
 public:
  explicit ChunkedFile(int fd) : fd_(fd) {}
  ChunkedFile(const ChunkedFile&) = delete;
  ChunkedFile& operator=(const ChunkedFile&) = delete;
  ~ChunkedFile() { ::close(fd_); }

  /// True when byte `pos` exists (reading more of the file if needed).
  bool has(size_t pos) {
    while (pos >= base_ + buf_.size()) {
      if (eof_) return false;
      const size_t old = buf_.size();
      buf_.resize(old + kChunkBytes);
      ssize_t got = 0;
      do {
        got = ::read(fd_, buf_.data() + old, kChunkBytes);
      } while (got < 0 && errno == EINTR);
      buf_.resize(old + static_cast<size_t>(std::max<ssize_t>(got, 0)));
      if (got <= 0) eof_ = true;
      if (got < 0) failed_ = true;
    }
    return true;
  }
  [[nodiscard]] char at(size_t pos) const { return buf_[pos - base_]; }
  [[nodiscard]] std::string_view view(size_t from, size_t to) const {
    return std::string_view(buf_).substr(from - base_, to - from);
  }
  /// Bytes before `pos` are no longer needed: dropped once they are a sizeable part of what is held.
  void release(size_t pos) {
    const size_t drop = pos - base_;
    if (drop < kChunkBytes || drop < buf_.size() / 2) return;
    buf_.erase(0, drop);
    base_ = pos;
  }
  [[nodiscard]] bool failed() const { return failed_; }

 private:
  static constexpr size_t kChunkBytes = size_t{1} << 20;
  int fd_;
  std::string buf_;
  size_t base_ = 0;
  bool eof_ = false, failed_ = false;
};

bool isJsonSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

/// The end of the JSON value that starts at `pos` (past its last byte): an object or array to its matching bracket
/// (strings skipped), a string to its closing quote, a literal to the next delimiter. nullopt on a NUL byte outside
/// a string, nesting deeper than kMaxJsonDepth counted from the top level (the value lies `outer` levels down), or
/// the end of the file inside the value. Not a validation: simdjson parses the value afterwards.
std::optional<size_t> valueEnd(ChunkedFile& f, size_t pos, int outer) {
  if (!f.has(pos)) return std::nullopt;
  const char first = f.at(pos);
  if (first != '{' && first != '[' && first != '"') {
    while (f.has(pos) && !isJsonSpace(f.at(pos)) && f.at(pos) != ',' && f.at(pos) != '}' && f.at(pos) != ']') {
      if (f.at(pos) == '\0') return std::nullopt;
      ++pos;
    }
    return pos;
  }
  int depth = 0;
  bool inString = false;
  for (;; ++pos) {
    if (!f.has(pos)) return std::nullopt;
    const char c = f.at(pos);
    if (inString) {
      if (c == '\\') {
        ++pos;
      } else if (c == '"') {
        inString = false;
        if (depth == 0) return pos + 1;
      }
      continue;
    }
    if (c == '"') {
      inString = true;
    } else if (c == '{' || c == '[') {
      if (++depth + outer > kMaxJsonDepth) return std::nullopt;
    } else if (c == '}' || c == ']') {
      if (--depth == 0) return pos + 1;
    } else if (c == '\0') {
      return std::nullopt;
    }
  }
}

/// readModelJson's first route (issue 37 goal 4: the peak memory of loading a model at most twice its file): the
/// file is read forward in chunks and each element of "patches" and "curves" is parsed alone (simdjson) and turned
/// into its patch or curve at once, so that neither the whole text nor a document of the whole file is ever held:
/// the peak is the model, one chunk and the "brep" member's text and document. The same converter as the other
/// routes (ModelReader), so the same model. nullopt (declined) on anything but a valid model: the other routes then
/// read the file and give their message. Declined too, as in fastRoute: a \u escape, a repeated or unknown
/// top-level key.
std::optional<Model> streamedRoute(const std::filesystem::path& file, std::string_view source) {
  if (!checkInputFile(file)) return std::nullopt;
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return std::nullopt;
  ChunkedFile f(fd);
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
  try {
    ModelReader<SimdValue> reader{std::string(source)};
    simdjson::dom::parser parser;
    Model model;
    std::string brepText;
    bool seenPatches = false, seenCurves = false, seenBRep = false, seenSchema = false;
    size_t pos = 0;
    auto skipSpace = [&] {
      while (f.has(pos) && isJsonSpace(f.at(pos))) ++pos;
    };
    // Parses the value at [from, to) alone; nullopt on an error or a \u escape.
    auto parsed = [&](size_t from, size_t to) -> std::optional<simdjson::dom::element> {
      const std::string_view text = f.view(from, to);
      if (text.find("\\u") != std::string_view::npos) return std::nullopt;
      simdjson::dom::element e;
      if (parser.parse(text.data(), text.size(), true).get(e) != simdjson::SUCCESS) return std::nullopt;
      return e;
    };
    // The elements of the array at pos, each handed to `take` with its index.
    auto eachElement = [&](auto take) -> bool {
      if (!f.has(pos) || f.at(pos) != '[') return false;
      ++pos;
      skipSpace();
      if (f.has(pos) && f.at(pos) == ']') {
        ++pos;
        return true;
      }
      for (size_t index = 0;; ++index) {
        skipSpace();
        const std::optional<size_t> end = valueEnd(f, pos, 2);
        if (!end || f.at(pos) != '{') return false;
        const std::optional<simdjson::dom::element> e = parsed(pos, *end);
        if (!e || !take(SimdValue(*e), index)) return false;
        pos = *end;
        f.release(pos);
        skipSpace();
        if (!f.has(pos)) return false;
        const char c = f.at(pos++);
        if (c == ']') return true;
        if (c != ',') return false;
      }
    };
    // Every element of the array at pos, converted by `read` (patchAt, curveAt), appended to `out`.
    auto readArray = [&](auto& out, auto read) {
      return eachElement([&](const SimdValue& v, size_t index) {
        auto item = read(v, index);
        if (!item) return false;
        out.push_back(std::move(item).value());
        return true;
      });
    };
    skipSpace();
    if (!f.has(pos) || f.at(pos++) != '{') return std::nullopt;
    skipSpace();
    if (f.has(pos) && f.at(pos) == '}') return std::nullopt;  // no "patches" or "curves": the message comes later
    while (true) {
      skipSpace();
      const std::optional<size_t> keyEnd = valueEnd(f, pos, 1);
      if (!keyEnd || f.at(pos) != '"') return std::nullopt;
      const std::string key(f.view(pos + 1, *keyEnd - 1));
      pos = *keyEnd;
      skipSpace();
      if (!f.has(pos) || f.at(pos++) != ':') return std::nullopt;
      skipSpace();
      if (key == "patches" && !seenPatches) {
        seenPatches = true;
        if (!readArray(model.patches, [&](const SimdValue& v, size_t i) { return reader.patchAt(v, i); }))
          return std::nullopt;
      } else if (key == "curves" && !seenCurves) {
        seenCurves = true;
        if (!readArray(model.curves, [&](const SimdValue& v, size_t i) { return reader.curveAt(v, i); }))
          return std::nullopt;
      } else if ((key == "brep" && !seenBRep) || (key == "$schema" && !seenSchema)) {
        (key == "brep" ? seenBRep : seenSchema) = true;
        const std::optional<size_t> end = valueEnd(f, pos, 1);
        if (!end) return std::nullopt;
        if (key == "brep") brepText = f.view(pos, *end);
        if (key == "$schema" && !parsed(pos, *end)) return std::nullopt;  // not read, but it must be JSON
        pos = *end;
        f.release(pos);
      } else {
        return std::nullopt;  // unknown or repeated: the other routes say which
      }
      skipSpace();
      if (!f.has(pos)) return std::nullopt;
      const char c = f.at(pos++);
      if (c == '}') break;
      if (c != ',') return std::nullopt;
    }
    skipSpace();
    if (f.has(pos) || f.failed() || (!seenPatches && !seenCurves)) return std::nullopt;
    if (seenBRep) {
      simdjson::dom::element b;
      if (brepText.find("\\u") != std::string::npos ||
          parser.parse(brepText.data(), brepText.size(), true).get(b) != simdjson::SUCCESS)
        return std::nullopt;
      if (!reader.addBRep(SimdValue(b), model)) return std::nullopt;
    }
    return model;
  } catch (const std::exception&) {
    return std::nullopt;  // out of memory: the other routes say what they could not build
  }
}

std::optional<Model> detail::readModelJsonStreamed(const std::filesystem::path& file, std::string_view source) {
  return streamedRoute(file, source);
}

std::optional<Model> detail::parseModelJsonFast(std::string_view text, std::string_view source) {
  return fastRoute(text.data(), text.size(), false, nullptr, source);
}

Result<Model> parseModelJson(std::string_view text, std::string_view source) {
  if (std::optional<Model> model = detail::parseModelJsonFast(text, source)) return std::move(*model);
  return detail::parseModelJsonNlohmann(text, source);
}

Status checkJsonText(std::string_view text, std::string_view source) { return scanJsonText(text, source); }

Result<Model> readModelJson(const std::filesystem::path& file) {
  if (std::optional<Model> model = streamedRoute(file, file.string())) return std::move(*model);
  Result<std::string> text = readFile(file);
  if (!text) return text.status();
  const size_t size = text->size();
  try {
    text->append(simdjson::SIMDJSON_PADDING, '\0');  // simdjson reads past the end: parsed in place, not copied
  } catch (const std::bad_alloc&) {
    return outOfMemory(file.string(), fmt::format("reading its text ({} bytes)", size));
  }
  if (std::optional<Model> model = fastRoute(text->data(), size, true, &*text, file.string()))
    return std::move(*model);
  // Declined: the nlohmann route, on the text (read again when the fast route freed it after parsing).
  if (text->size() == size + simdjson::SIMDJSON_PADDING) {
    text->resize(size);
  } else {
    text = readFile(file);
    if (!text) return text.status();
  }
  return detail::parseModelJsonNlohmann(*text, file.string());
}

namespace {

/// The model's JSON text in pieces of about kJsonPieceBytes (emit is called with each, in order, then with the
/// rest): a writer passes them on to the file as they come, so the whole text is never held.
constexpr size_t kJsonPieceBytes = size_t{1} << 20;

void modelJsonPieces(const Model& model, const std::function<void(std::string_view)>& emit) {
  std::string out = "{\n  \"patches\": [";
  auto pass = [&] {
    if (out.size() < kJsonPieceBytes) return;
    emit(out);
    out.clear();
  };
  for (size_t k = 0; k < model.patches.size(); ++k) {
    out += k == 0 ? "\n" : ",\n";
    appendPatch(out, model.patches[k]);
    pass();
  }
  out += model.patches.empty() ? "]" : "\n  ]";
  if (!model.curves.empty()) {
    out += ",\n  \"curves\": [";
    for (size_t k = 0; k < model.curves.size(); ++k) {
      out += k == 0 ? "\n" : ",\n";
      appendCurve(out, model.curves[k]);
      pass();
    }
    out += "\n  ]";
  }
  if (model.brep) appendBRep(out, model, *model.brep);
  out += "\n}\n";
  emit(out);
}

}  // namespace

std::string modelToJson(const Model& model) {
  std::string text;
  modelJsonPieces(model, [&](std::string_view piece) { text += piece; });
  return text;
}

Status writeModelJson(const Model& model, const std::filesystem::path& file) {
  if (Status st = checkNoTrimsLost(model, file.string(), /*keepsBRep=*/true); !st) return st;
  return writeFileAtomically(file, [&](const std::function<void(std::string_view)>& emit) {
    modelJsonPieces(model, emit);
  });
}

}  // namespace seam::io
