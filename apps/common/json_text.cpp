#include "json_text.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <charconv>
#include <cmath>
#include <cstdint>

namespace seam::cli {

namespace {

/// nlohmann's text of a double (dump_float): its own shortest round-trip conversion, so that the bytes equal those
/// of OrderedJson(x).dump().
constexpr size_t kNumberBuffer = 64;  // nlohmann's serializer buffer

void appendSpaces(std::string& out, int count) { out.append(static_cast<size_t>(count), ' '); }

bool isScalar(const OrderedJson& v) { return !v.is_object() && !v.is_array(); }

void appendScalar(std::string& out, const OrderedJson& v) {
  switch (v.type()) {
    case OrderedJson::value_t::null: out += "null"; return;
    case OrderedJson::value_t::boolean: out += v.get<bool>() ? "true" : "false"; return;
    case OrderedJson::value_t::number_integer: appendJsonInteger(out, static_cast<long long>(v.get<std::int64_t>())); return;
    case OrderedJson::value_t::number_unsigned:
      appendJsonInteger(out, static_cast<unsigned long long>(v.get<std::uint64_t>()));
      return;
    case OrderedJson::value_t::number_float: appendJsonNumber(out, v.get<double>()); return;
    case OrderedJson::value_t::string: appendJsonString(out, v.get_ref<const std::string&>()); return;
    default: out += v.dump(-1, ' ', false, OrderedJson::error_handler_t::replace); return;  // binary: never printed
  }
}

}  // namespace

void appendJsonNumber(std::string& out, double x) {
  if (!std::isfinite(x)) {
    out += "null";
    return;
  }
  std::array<char, kNumberBuffer> buffer{};
  char* end = nlohmann::detail::to_chars(buffer.data(), buffer.data() + buffer.size(), x);
  out.append(buffer.data(), end);
}

void appendJsonInteger(std::string& out, long long x) {
  std::array<char, kNumberBuffer> buffer{};
  const auto [end, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), x);
  out.append(buffer.data(), end);
}

void appendJsonInteger(std::string& out, unsigned long long x) {
  std::array<char, kNumberBuffer> buffer{};
  const auto [end, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), x);
  out.append(buffer.data(), end);
}

void appendJsonString(std::string& out, std::string_view s) {
  // Printable ASCII without quotes or backslashes (every key, edge and verdict name, most patch names) is its own
  // text; anything else goes through nlohmann's escaping.
  constexpr unsigned char kFirstPrintable = 0x20, kDelete = 0x7f;
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (u < kFirstPrintable || u >= kDelete || c == '"' || c == '\\') {
      out += OrderedJson(std::string(s)).dump(-1, ' ', false, OrderedJson::error_handler_t::replace);
      return;
    }
  }
  out += '"';
  out += s;
  out += '"';
}

void appendJsonText(std::string& out, const OrderedJson& v, int indent) {
  if (v.is_object()) {
    if (v.empty()) {
      out += "{}";
      return;
    }
    out += "{\n";
    bool first = true;
    for (auto it = v.begin(); it != v.end(); ++it) {
      if (!first) out += ",\n";
      first = false;
      appendSpaces(out, indent + 2);
      appendJsonString(out, it.key());
      out += ": ";
      appendJsonText(out, it.value(), indent + 2);
    }
    out += '\n';
    appendSpaces(out, indent);
    out += '}';
  } else if (v.is_array()) {
    if (std::all_of(v.begin(), v.end(), isScalar)) {
      out += '[';
      bool first = true;
      for (const OrderedJson& x : v) {
        if (!first) out += ", ";
        first = false;
        appendScalar(out, x);
      }
      out += ']';
      return;
    }
    out += "[\n";
    bool first = true;
    for (const OrderedJson& x : v) {
      if (!first) out += ",\n";
      first = false;
      appendSpaces(out, indent + 2);
      appendJsonText(out, x, indent + 2);
    }
    out += '\n';
    appendSpaces(out, indent);
    out += ']';
  } else {
    appendScalar(out, v);
  }
}

// ---- JsonTextWriter ------------------------------------------------------------------------------------------

void JsonTextWriter::beforeValue() {
  if (afterKey_) {
    afterKey_ = false;
    return;
  }
  if (stack_.empty()) return;  // the document itself
  Level& level = stack_.back();
  assert(!level.object && "a member of an object needs key() first");
  out_ += level.empty ? "\n" : ",\n";
  level.empty = false;
  appendSpaces(out_, indent());
}

void JsonTextWriter::key(std::string_view name) {
  assert(!stack_.empty() && stack_.back().object && !afterKey_);
  Level& level = stack_.back();
  out_ += level.empty ? "\n" : ",\n";
  level.empty = false;
  appendSpaces(out_, indent());
  appendJsonString(out_, name);
  out_ += ": ";
  afterKey_ = true;
}

void JsonTextWriter::beginObject() {
  beforeValue();
  out_ += '{';
  stack_.push_back({true, true});
}

void JsonTextWriter::beginArray() {
  beforeValue();
  out_ += '[';
  stack_.push_back({false, true});
}

void JsonTextWriter::endObject() {
  assert(!stack_.empty() && stack_.back().object && !afterKey_);
  close('}');
}

void JsonTextWriter::endArray() {
  assert(!stack_.empty() && !stack_.back().object);
  close(']');
}

void JsonTextWriter::close(char bracket) {
  const bool empty = stack_.back().empty;
  stack_.pop_back();
  if (!empty) {
    out_ += '\n';
    appendSpaces(out_, indent());
  }
  out_ += bracket;
  maybeFlush();
}

void JsonTextWriter::value(double x) {
  beforeValue();
  appendJsonNumber(out_, x);
}

void JsonTextWriter::value(bool x) {
  beforeValue();
  out_ += x ? "true" : "false";
}

void JsonTextWriter::value(std::string_view s) {
  beforeValue();
  appendJsonString(out_, s);
}

void JsonTextWriter::value(std::nullptr_t) {
  beforeValue();
  out_ += "null";
}

void JsonTextWriter::value(const OrderedJson& v) {
  beforeValue();
  appendJsonText(out_, v, indent());
  maybeFlush();
}

void JsonTextWriter::numbers(std::span<const double> xs) {
  beforeValue();
  out_ += '[';
  for (size_t k = 0; k < xs.size(); ++k) {
    if (k > 0) out_ += ", ";
    appendJsonNumber(out_, xs[k]);
  }
  out_ += ']';
}

void JsonTextWriter::strings(std::span<const std::string> xs) {
  beforeValue();
  out_ += '[';
  for (size_t k = 0; k < xs.size(); ++k) {
    if (k > 0) out_ += ", ";
    appendJsonString(out_, xs[k]);
  }
  out_ += ']';
}

void JsonTextWriter::maybeFlush() {
  constexpr size_t kChunk = size_t{1} << 20;
  if (sink_ != nullptr && out_.size() >= kChunk) flush();
}

void JsonTextWriter::flush() {
  if (sink_ == nullptr) return;
  sink_->write(out_.data(), static_cast<std::streamsize>(out_.size()));
  out_.clear();
}

}  // namespace seam::cli
