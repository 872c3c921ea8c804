#pragma once
// JSON text in the layout every seam command prints (cli_util.h's jsonText): objects indented by two spaces, one key
// per line; arrays of scalars on one line, other arrays one element per line; doubles in nlohmann's shortest
// round-trip form ("1.0", "0.1", "1e-05"), non-finite doubles as null; strings escaped as nlohmann does (invalid
// UTF-8 replaced). Written from a DOM (appendJsonText) or streamed value by value (JsonTextWriter) with the same
// bytes, so that a large document (`seam check --json` of 10 000 patches) is never built in memory.
#include <nlohmann/json.hpp>

#include <concepts>
#include <cstddef>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace seam::cli {

/// JSON with keys kept in insertion order (what the commands print).
using OrderedJson = nlohmann::ordered_json;

/// Appends a double: nlohmann's shortest text that reads back as the same double, or null when not finite.
void appendJsonNumber(std::string& out, double x);
/// Appends a signed / unsigned integer.
void appendJsonInteger(std::string& out, long long x);
void appendJsonInteger(std::string& out, unsigned long long x);
/// Appends a string in double quotes with nlohmann's escapes (invalid UTF-8 becomes U+FFFD).
void appendJsonString(std::string& out, std::string_view s);
/// Appends the text of `value` nested `indent` spaces deep (its first line not indented), no final newline.
void appendJsonText(std::string& out, const OrderedJson& value, int indent);

/// Writes one JSON document in appendJsonText's layout value by value. Open objects with beginObject, name each
/// member with key(), open arrays whose elements are objects or arrays with beginArray (an array of scalars is one
/// value: numbers(), strings()). Text goes to `sink` in chunks of about 1 MiB (flush() sends the rest), or stays in
/// text() when there is no sink. The caller writes a well-formed document (debug-checked).
class JsonTextWriter {
 public:
  explicit JsonTextWriter(std::ostream* sink = nullptr) : sink_(sink) {}

  void beginObject();
  void endObject();
  void beginArray();
  void endArray();
  /// The name of the next member of the current object.
  void key(std::string_view name);

  void value(double x);
  void value(bool x);
  void value(std::string_view s);
  void value(const std::string& s) { value(std::string_view(s)); }
  void value(const char* s) { value(std::string_view(s)); }
  void value(std::nullptr_t);
  template <std::integral T>
    requires(!std::same_as<T, bool>)
  void value(T x) {
    beforeValue();
    if constexpr (std::signed_integral<T>) {
      appendJsonInteger(out_, static_cast<long long>(x));
    } else {
      appendJsonInteger(out_, static_cast<unsigned long long>(x));
    }
  }
  /// Any DOM value, as appendJsonText prints it at this depth.
  void value(const OrderedJson& v);
  /// An array of numbers / strings on one line.
  void numbers(std::span<const double> xs);
  void strings(std::span<const std::string> xs);

  /// The text written so far and not yet sent to the sink.
  const std::string& text() const { return out_; }
  /// Sends the buffered text to the sink (nothing without one).
  void flush();

 private:
  struct Level {
    bool object = false;
    bool empty = true;
  };
  /// The separator and indentation before a value (an array element) or nothing (after key()).
  void beforeValue();
  void maybeFlush();
  /// Ends the innermost object or array with `bracket`, on its own line unless it was empty.
  void close(char bracket);
  int indent() const { return 2 * static_cast<int>(stack_.size()); }

  std::ostream* sink_ = nullptr;
  std::string out_;
  std::vector<Level> stack_;
  bool afterKey_ = false;
};

}  // namespace seam::cli
