#pragma once
// Reading back the JSON mixpilot writes (a sweep's plan and run reports, scores): a strict
// RFC 8259 reader into a plain tree, and the string quoting its writers share. Numbers keep
// their token as written, so a value is passed on (into a CSV table) exactly as it was
// written, 17 significant digits and all. Nesting is bounded (kMaxJsonDepth): the files are
// flat, and a hostile file must not exhaust the stack.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mixpilot {

inline constexpr int kMaxJsonDepth = 64;

struct JsonMember;

struct JsonValue {
  enum class Type { null, boolean, number, string, array, object };
  Type type = Type::null;
  bool boolean = false;
  double number = 0.0;  // a number's value (±inf beyond double's range)
  std::string text;     // a number's token as written; a string's decoded UTF-8
  std::vector<JsonValue> items;                             // an array's
  std::vector<JsonMember> members;  // an object's, in file order

  bool is(Type t) const { return type == t; }
  // The member `key` of an object (the first, should it repeat), or nullptr.
  const JsonValue* get(std::string_view key) const;
  // The member `key` when it is a string / a number, else nullptr.
  const std::string* string_at(std::string_view key) const;
  const JsonValue* number_at(std::string_view key) const;
};

struct JsonMember {
  std::string name;
  JsonValue value;
};

// The value of `text` (one value, surrounded by whitespace only); nullopt with
// "line L, column C: expected ..." in `error` otherwise.
std::optional<JsonValue> parse_json(std::string_view text, std::string& error);

// `s` as a JSON string literal: quotes, backslashes and control characters escaped.
std::string json_quote(std::string_view s);

}  // namespace mixpilot
