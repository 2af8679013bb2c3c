// Preset files (--preset-file): a JSON object of `--set` keys read by one typed rule (spellTyped),
// which Python's values follow too.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "input_file.h"
#include "params.h"

namespace tender {

std::optional<std::string> spellTyped(const std::string& key, ValueType type, const std::string& text,
                                      std::string& out) {
  const auto info = paramInfo(key);
  if (!info) return "unknown parameter '" + key + "' (see --help for the keys)";
  const bool numeric = info->lo != info->hi;
  std::string expected;
  if (info->on_off)
    expected = "true or false";
  else if (!numeric)
    expected = "a name";
  else if (info->whole)
    expected = "a whole number";
  else
    expected = "a number";
  bool fits = false;
  switch (type) {
  case ValueType::Text:
    fits = true;
    break;
  case ValueType::Bool:
    fits = info->on_off;
    break;
  case ValueType::Whole:
    fits = numeric;
    break;
  case ValueType::Number:
    fits = numeric && !info->whole;
    break;
  }
  if (!fits) return key + ": expected " + expected + ", got " + text;
  out = type == ValueType::Bool ? (text == "true" ? "on" : "off") : text;
  return std::nullopt;
}

namespace {

/// Reads a preset file's JSON: one object of scalar values, each key once, numbers as written.
class PresetReader : public nlohmann::json_sax<nlohmann::json> {
public:
  struct Entry {
    std::string key;
    ValueType type = ValueType::Text;
    std::string text;
  };
  std::vector<Entry> entries;
  std::string error;

  bool null() override { return refuse("null"); }
  bool boolean(bool v) override { return value(ValueType::Bool, v ? "true" : "false"); }
  bool number_integer(number_integer_t v) override { return value(ValueType::Whole, std::to_string(v)); }
  bool number_unsigned(number_unsigned_t v) override { return value(ValueType::Whole, std::to_string(v)); }
  bool number_float(number_float_t, const string_t& s) override {
    // An integer too large for 64 bits is still a whole number, as written.
    const bool digits = !s.empty() && s.find_first_not_of("-0123456789") == std::string::npos;
    return value(digits ? ValueType::Whole : ValueType::Number, s);
  }
  bool string(string_t& v) override { return value(ValueType::Text, v); }
  bool binary(binary_t&) override { return refuse("binary data"); }
  bool start_object(std::size_t) override {
    if (depth_++ == 0) return true;
    return refuse("an object");
  }
  bool end_object() override { return --depth_, true; }
  bool start_array(std::size_t) override { return depth_ == 0 ? top("an array") : refuse("an array"); }
  bool end_array() override { return true; }
  bool key(string_t& k) override {
    for (const Entry& e : entries)
      if (e.key == k) return fail(k + ": given twice");
    key_ = k;
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) override {
    std::string why = e.what();
    if (auto close = why.find("] "); why.rfind("[json.exception", 0) == 0 && close != std::string::npos)
      why = why.substr(close + 2);
    return fail("malformed JSON: " + why);
  }

private:
  bool value(ValueType type, const std::string& text) {
    if (depth_ == 0) return top("a single value");
    entries.push_back({key_, type, text});
    return true;
  }
  bool refuse(const std::string& what) {
    if (depth_ == 0) return top(what);
    return fail(key_ + ": expected a number, a string or true/false, got " + what);
  }
  bool top(const std::string&) {
    return fail("expected a JSON object of parameters (as `tender presets --dump NAME` prints)");
  }
  bool fail(const std::string& why) {
    if (error.empty()) error = why;
    return false;
  }
  int depth_ = 0;
  std::string key_;
};

} // namespace

std::optional<std::string> applyPresetText(const std::string& text, const std::string& origin,
                                           const std::optional<std::string>& base, SimParams& out) {
  if (text.find('\0') != std::string::npos) return origin + ": holds a NUL byte (a preset file is JSON text)";
  PresetReader reader;
  if (!nlohmann::json::sax_parse(text, &reader) || !reader.error.empty())
    return origin + ": " + (reader.error.empty() ? std::string("malformed JSON") : reader.error);

  std::optional<std::string> from = base;
  for (const auto& e : reader.entries)
    if (e.key == "preset") {
      if (e.type != ValueType::Text) return origin + ": preset: expected the name of a preset";
      from = e.text;
    }
  SimParams p = out;
  if (from) {
    std::optional<SimParams> named = presetParams(*from);
    if (!named) return origin + ": " + unknownPreset(*from);
    p = *named;
  }
  for (const auto& e : reader.entries) {
    if (e.key == "preset") continue;
    std::string spelled;
    if (auto err = spellTyped(e.key, e.type, e.text, spelled)) return origin + ": " + *err;
    if (auto err = applyOverride(p, e.key + "=" + spelled)) return origin + ": " + *err;
  }
  out = p;
  return std::nullopt;
}

std::optional<std::string> loadPresetFile(const std::string& path, SimParams& out) {
  std::string text;
  if (auto why = readInputFile(path, kMaxPresetFileBytes, text)) return path + ": cannot read: " + *why;
  return applyPresetText(text, path, "tender", out);
}

} // namespace tender
