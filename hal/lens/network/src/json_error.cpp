// SAX pass that locates a JSON syntax error; see json_error.h.
#include "json_error.h"

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace camhead::hal::lens::detail {
namespace {

using nlohmann::json;

// nlohmann's parse_error id for "number overflow": a literal that is not a
// finite double. The DOM parser rejects it rather than storing infinity.
constexpr int kNumberOverflow = 406;

// Builds nothing: it only tracks the key path so that the error can name the
// field the sender got wrong.
class ErrorLocator : public nlohmann::json_sax<json> {
public:
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t &) override { return true; }
  bool string(string_t &) override { return true; }
  bool binary(binary_t &) override { return true; }
  bool start_object(std::size_t) override { return push(""); }
  bool key(string_t &k) override {
    if (!path_.empty()) {
      path_.back() = k;
    }
    return true;
  }
  bool end_object() override { return pop(); }
  bool start_array(std::size_t) override { return push("[]"); }
  bool end_array() override { return pop(); }
  bool parse_error(std::size_t position, const std::string &token,
                   const nlohmann::detail::exception &ex) override {
    overflow_ = ex.id == kNumberOverflow;
    position_ = position;
    token_ = clip(token); // the lexer has already escaped control characters

    return false;
  }

  [[nodiscard]] OpenTrackIoParseResult result() const {
    std::string field;
    for (const std::string &part : path_) {
      if (!part.empty()) {
        field += field.empty() || part == "[]" ? part : "." + part;
      }
    }
    field = clip(std::move(field));
    if (overflow_) {
      return OpenTrackIoParseResult{std::nullopt, OpenTrackIoError::non_finite,
                                    (field.empty() ? "payload" : field) + ": number '" + token_ +
                                        "' is not a finite double"};
    }
    return OpenTrackIoParseResult{std::nullopt, OpenTrackIoError::malformed_json,
                                  "payload: malformed JSON at byte " + std::to_string(position_) +
                                      " near '" + token_ + "'" +
                                      (field.empty() ? "" : " (in " + field + ")")};
  }

private:
  // A 32 KiB garbage token or a 16k-deep key path must not become the log
  // line: keep the start, which is where the reader looks.
  static std::string clip(std::string text) {
    constexpr std::size_t kMax = 60;
    if (text.size() > kMax) {
      text.resize(kMax);
      text += "...";
    }
    return text;
  }

  bool push(std::string part) {
    path_.push_back(std::move(part));
    return true;
  }
  bool pop() {
    if (!path_.empty()) {
      path_.pop_back();
    }
    return true;
  }

  std::vector<std::string> path_;
  bool overflow_ = false;
  std::size_t position_ = 0;
  std::string token_;
};

} // namespace

OpenTrackIoParseResult describe_json_error(std::span<const std::uint8_t> payload) {
  ErrorLocator locator;
  // The result is false by construction: this only runs on invalid payloads.
  (void)json::sax_parse(payload.begin(), payload.end(), &locator);
  return locator.result();
}

} // namespace camhead::hal::lens::detail
