// The strict JSON reader: every check, as the scene, profile and board
// readers use it, fails on the first problem with "FILE: FIELD: REASON",
// and no text, however broken, gets anything else out of it.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "camhead/base/config_json.h"

#include <gtest/gtest.h>

namespace camhead::base {
namespace {

const char *kFile = "/rigs/cfg.json";

// The message of the first problem `read` finds in `text`.
std::string error_of(const std::string &text, const std::function<void(const JsonValue &)> &read) {
  try {
    const JsonFile f(text, kFile);
    read(f.root());
  } catch (const ConfigError &e) {
    return e.what();
  }
  return "(no error)";
}

// The message of checking the member "v" of {"v": VALUE} with `check`.
std::string value_error(const std::string &value,
                        const std::function<void(const JsonValue &)> &check) {
  return error_of("{\"v\": " + value + "}", [&](const JsonValue &r) { check(r.at("v")); });
}

TEST(ConfigJson, ErrorCarriesFileFieldAndReason) {
  try {
    const JsonFile f(R"({"a": {"b": [1, {"c": "x"}]}})", kFile);
    (void)f.root().at("a").at("b").elements()[1].at("c").number();
    FAIL() << "accepted";
  } catch (const ConfigError &e) {
    EXPECT_EQ(e.file(), kFile);
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.field(), "a.b[1].c");
    EXPECT_EQ(e.reason(), "must be a finite number");
    EXPECT_STREQ(e.what(), "/rigs/cfg.json: a.b[1].c: must be a finite number");
  }
}

TEST(ConfigJson, SyntaxErrorsAreOnTheJsonFieldWithLineAndColumn) {
  try {
    const JsonFile f("{\n  \"a\": 1,\n  \"b\": ]\n}", kFile);
    FAIL() << "accepted";
  } catch (const ConfigError &e) {
    EXPECT_EQ(e.field(), "(JSON)");
    EXPECT_EQ(e.reason().rfind("invalid JSON at line 3, column 8: syntax error", 0), 0u)
        << e.what();
    EXPECT_EQ(std::string(e.what()).find("json.exception"), std::string::npos) << e.what();
  }
  for (const char *text : {"", "{", "[1, 2", "nul", "{\"a\": 1,}", "\x01", "-NaN", "nan"})
    EXPECT_EQ(
        error_of(text, [](const JsonValue &) {}).rfind("/rigs/cfg.json: (JSON): invalid JSON", 0),
        0u)
        << text;
}

TEST(ConfigJson, ObjectNeedsRequiredKeysAndKnowsNoOthers) {
  const auto check = [](const JsonValue &r) { r.object({"a", "b"}, {"c"}); };
  EXPECT_EQ(error_of(R"({"a": 1, "b": 2, "c": 3})", check), "(no error)");
  EXPECT_EQ(error_of(R"({"a": 1, "b": 2})", check), "(no error)");
  EXPECT_EQ(error_of(R"([1])", check), "/rigs/cfg.json: (top level): must be an object");
  EXPECT_EQ(error_of(R"({"a": 1})", check), "/rigs/cfg.json: b: missing");
  // Missing comes before unknown; unknown fields are named in file order.
  EXPECT_EQ(error_of(R"({"z": 1, "a": 1})", check), "/rigs/cfg.json: b: missing");
  EXPECT_EQ(error_of(R"({"a": 1, "b": 2, "z": 3, "y": 4})", check),
            "/rigs/cfg.json: z: unknown field");
  EXPECT_EQ(value_error("3", [](const JsonValue &v) { v.object({}); }),
            "/rigs/cfg.json: v: must be an object");
}

TEST(ConfigJson, MembersElementsAndLookups) {
  const JsonFile f(R"({"m": {"z": 1, "a": [true, "s"]}, "n": null})", kFile);
  const JsonValue r = f.root();
  const auto members = r.at("m").members();
  ASSERT_EQ(members.size(), 2u);
  EXPECT_EQ(members[0].first, "z"); // file order, not sorted
  EXPECT_EQ(members[1].second.field(), "m.a");
  const auto elements = members[1].second.elements();
  ASSERT_EQ(elements.size(), 2u);
  EXPECT_EQ(elements[1].field(), "m.a[1]");
  EXPECT_TRUE(r.has("n"));
  EXPECT_FALSE(r.has("x"));
  EXPECT_FALSE(r.find("x").has_value());
  EXPECT_EQ(r.find("m")->field(), "m");
  EXPECT_FALSE(elements[0].has("x")); // not an object: has nothing
  const auto fail = [](const std::function<void(const JsonValue &)> &read) {
    return error_of(R"({"m": {"a": 1}, "t": 5})", read);
  };
  EXPECT_EQ(fail([](const JsonValue &v) { (void)v.at("m").at("b"); }),
            "/rigs/cfg.json: m.b: missing");
  EXPECT_EQ(fail([](const JsonValue &v) { (void)v.at("m").at("b", "sim or file"); }),
            "/rigs/cfg.json: m.b: missing (sim or file)");
  // A tagged value that is no object lacks its tag.
  EXPECT_EQ(fail([](const JsonValue &v) { (void)v.at("t").at("type"); }),
            "/rigs/cfg.json: t.type: missing");
  EXPECT_EQ(fail([](const JsonValue &v) { (void)v.at("t").members(); }),
            "/rigs/cfg.json: t: must be an object");
  EXPECT_EQ(fail([](const JsonValue &v) { (void)v.at("m").elements(); }),
            "/rigs/cfg.json: m: must be an array");
  EXPECT_EQ(fail([](const JsonValue &v) { (void)v.at("m").elements("output URIs"); }),
            "/rigs/cfg.json: m: must be an array of output URIs");
  EXPECT_EQ(fail([](const JsonValue &v) { v.at("m").fail("is wrong"); }),
            "/rigs/cfg.json: m: is wrong");
}

TEST(ConfigJson, Strings) {
  const auto s = [](const JsonValue &v) { (void)v.string(); };
  EXPECT_EQ(value_error(R"("x")", s), "(no error)");
  for (const char *bad : {R"("")", "1", "null", "[]", "true"})
    EXPECT_EQ(value_error(bad, s), "/rigs/cfg.json: v: must be a non-empty string") << bad;
  const auto choice = [](const JsonValue &v) { (void)v.string({"BOX", "TENT"}); };
  EXPECT_EQ(value_error(R"("TENT")", choice), "(no error)");
  EXPECT_EQ(value_error(R"("GAUSS")", choice), "/rigs/cfg.json: v: must be one of BOX, TENT");
  const auto text = [](const JsonValue &v) { (void)v.text(); };
  EXPECT_EQ(value_error(R"("")", text), "(no error)");
  EXPECT_EQ(value_error("3", text), "/rigs/cfg.json: v: must be a string");
  const JsonFile f(R"({"v": "a\"b"})", kFile);
  EXPECT_EQ(f.root().at("v").string(), "a\"b");
}

TEST(ConfigJson, Booleans) {
  const auto b = [](const JsonValue &v) { (void)v.boolean(); };
  EXPECT_EQ(value_error("false", b), "(no error)");
  for (const char *bad : {"1", "0", R"("true")", "null"})
    EXPECT_EQ(value_error(bad, b), "/rigs/cfg.json: v: must be true or false") << bad;
}

TEST(ConfigJson, NumbersAreFiniteAndInRange) {
  const auto any = [](const JsonValue &v) { (void)v.number(); };
  for (const char *ok : {"0", "-3", "2.5e3", "18446744073709551615", "1e300"})
    EXPECT_EQ(value_error(ok, any), "(no error)") << ok;
  for (const char *bad : {"\"1\"", "true", "null", "[1]", "NaN", "Infinity", "-Infinity"})
    EXPECT_EQ(value_error(bad, any), "/rigs/cfg.json: v: must be a finite number") << bad;
  const JsonFile f(R"({"v": -2.5})", kFile);
  EXPECT_EQ(f.root().at("v").number(), -2.5);

  const auto in = [](Range r) { return [r](const JsonValue &v) { (void)v.number(r); }; };
  EXPECT_EQ(value_error("0.001", in(Range::within(0.01, 100))),
            "/rigs/cfg.json: v: must be within 0.01 .. 100");
  EXPECT_EQ(value_error("100.5", in(Range::within(0.01, 100))),
            "/rigs/cfg.json: v: must be within 0.01 .. 100");
  EXPECT_EQ(value_error("100", in(Range::within(0.01, 100))), "(no error)");
  EXPECT_EQ(value_error("0", in(Range::above(0, 1e6))),
            "/rigs/cfg.json: v: must be > 0 and <= 1e+06");
  EXPECT_EQ(value_error("2e6", in(Range::above(0, 1e6))),
            "/rigs/cfg.json: v: must be > 0 and <= 1e+06");
  EXPECT_EQ(value_error("0", in(Range::above(0))), "/rigs/cfg.json: v: must be > 0");
  EXPECT_EQ(value_error("-1", in(Range::at_least(0))), "/rigs/cfg.json: v: must be >= 0");
  EXPECT_EQ(value_error("0", in(Range::at_least(0))), "(no error)");
  EXPECT_EQ(value_error("6", in(Range::at_most(5))), "/rigs/cfg.json: v: must be <= 5");
}

TEST(ConfigJson, HugeNumbersAndNonFiniteWordsFailOnTheirField) {
  // nlohmann refuses these while parsing (out_of_range.406 or a syntax
  // error), before the field is known; the reader names the field instead.
  const auto any = [](const JsonValue &v) { (void)v.number(); };
  const std::string digits400(400, '7');
  for (const std::string &bad : {std::string("1e999"), std::string("-1e999"), digits400,
                                 "-" + digits400, std::string("NaN4"), std::string("Infinity2"),
                                 std::string("NaNx"), std::string("1e99999999999999999999")}) {
    const std::string got = value_error(bad, any);
    EXPECT_EQ(got, "/rigs/cfg.json: v: must be a finite number") << bad.substr(0, 20);
  }
  // Inside arrays and after other members, and still nothing of nlohmann's.
  EXPECT_EQ(error_of(R"({"a": 1, "b": [0, 1e999, 2]})",
                     [](const JsonValue &r) { (void)r.at("b").numbers(3); }),
            "/rigs/cfg.json: b: must be an array of 3 finite numbers");
  EXPECT_EQ(error_of("{\"v\": 1e999e5}", any).find("json.exception"), std::string::npos);
  // In a string they are text.
  const JsonFile f(R"({"v": "NaN4 1e999 Infinity"})", kFile);
  EXPECT_EQ(f.root().at("v").string(), "NaN4 1e999 Infinity");
  // Small exponents underflow to zero, as in Python.
  const JsonFile g(R"({"v": 1e-999})", kFile);
  EXPECT_EQ(g.root().at("v").number(), 0.0);
}

TEST(ConfigJson, IntegersAreJsonIntegersInRange) {
  const auto port = [](const JsonValue &v) { (void)v.integer(1, 65535); };
  const std::string reason = "/rigs/cfg.json: v: must be an integer within 1 .. 65535";
  EXPECT_EQ(value_error("8", port), "(no error)");
  for (const std::string &bad :
       {std::string("8.0"), std::string("8.5"), std::string("8e0"), std::string("0"),
        std::string("70000"), std::string("-1"), std::string("\"8\""), std::string("true"),
        std::string("null"), std::string("18446744073709551615"),
        std::string("-9223372036854775808"), std::string(400, '9'), std::string("1e999"),
        std::string("NaN")})
    EXPECT_EQ(value_error(bad, port), reason) << bad.substr(0, 20);
  // The ends of the 64-bit range, and unsigned values beyond int64.
  const JsonFile f(R"({"a": -9223372036854775808, "b": 9223372036854775807,
                       "c": 9223372036854775808})",
                   kFile);
  constexpr auto lo = std::numeric_limits<std::int64_t>::min();
  constexpr auto hi = std::numeric_limits<std::int64_t>::max();
  EXPECT_EQ(f.root().at("a").integer(lo, hi), lo);
  EXPECT_EQ(f.root().at("b").integer(lo, hi), hi);
  EXPECT_EQ(
      value_error("9223372036854775808", [](const JsonValue &v) { (void)v.integer(0, 1 << 30); }),
      "/rigs/cfg.json: v: must be an integer within 0 .. 1073741824");
  EXPECT_EQ(value_error("5", [](const JsonValue &v) { (void)v.integer(-10, -1); }),
            "/rigs/cfg.json: v: must be an integer within -10 .. -1");
  EXPECT_EQ(value_error("3", [](const JsonValue &v) { (void)v.integer(5, 10); }),
            "/rigs/cfg.json: v: must be an integer within 5 .. 10");
}

TEST(ConfigJson, ArraysOfNumbers) {
  const auto three = [](const JsonValue &v) { (void)v.numbers(3, Range::within(0, 1)); };
  EXPECT_EQ(value_error("[0, 0.5, 1]", three), "(no error)");
  const std::string shape = "/rigs/cfg.json: v: must be an array of 3 finite numbers";
  for (const char *bad :
       {"[0, 1]", "[0, 0, 0, 0]", "[0, null, 0]", "[0, \"1\", 0]", "3", "[0, NaN, 0]", "{}"})
    EXPECT_EQ(value_error(bad, three), shape) << bad;
  EXPECT_EQ(value_error("[0, 1.5, 0]", three),
            "/rigs/cfg.json: v: components must be within 0 .. 1");
  EXPECT_EQ(value_error("[0, -1, 0]",
                        [](const JsonValue &v) { (void)v.numbers(3, Range::at_least(1e-9)); }),
            "/rigs/cfg.json: v: components must be >= 1e-09");
  const JsonFile f(R"({"v": [1, -2.5]})", kFile);
  EXPECT_EQ(f.root().at("v").numbers(2), (std::vector<double>{1.0, -2.5}));
}

TEST(ConfigJson, PathsAreRelativeToTheFile) {
  const JsonFile f(R"({"rel": "traces/a.csv", "up": "../x/./b.csv", "abs": "/data/c.csv",
                       "empty": ""})",
                   kFile);
  EXPECT_EQ(f.root().at("rel").path(), std::filesystem::path("/rigs/traces/a.csv"));
  EXPECT_EQ(f.root().at("up").path(), std::filesystem::path("/x/b.csv"));
  EXPECT_EQ(f.root().at("abs").path(), std::filesystem::path("/data/c.csv"));
  EXPECT_EQ(error_of(R"({"p": ""})", [](const JsonValue &r) { (void)r.at("p").path(); }),
            "/rigs/cfg.json: p: must be a non-empty string");
  // A file named relative to the working directory: its folder made absolute.
  const JsonFile g(R"({"p": "m.obj"})", "scenes/s.json");
  EXPECT_EQ(g.root().at("p").path(), std::filesystem::current_path() / "scenes" / "m.obj");
}

TEST(ConfigJson, APathHoldingANulOrAControlCharacterIsRefused) {
  // The C library would open "victim", not the file the string names.
  const auto path_of = [](const JsonValue &r) { (void)r.at("p").path(); };
  EXPECT_EQ(error_of(R"({"p": "victim\u0000.y4m"})", path_of),
            std::string(kFile) +
                R"(: p: holds a NUL character (\u0000) at position 6; a file name cannot)");
  EXPECT_EQ(error_of(R"({"p": "take\n.y4m"})", path_of),
            std::string(kFile) +
                R"(: p: holds a control character (\u000a) at position 4; a file name cannot)");
  EXPECT_EQ(error_of(R"({"p": "caf\u00e9 take.y4m"})", path_of), "(no error)");
}

TEST(ConfigJson, AKeyGivenTwiceInOneObjectIsRefusedOnItsField) {
  // Python's json would keep the last "camera" without a word.
  EXPECT_EQ(error_of(R"({"a": 1, "b": 2, "a": 3})", [](const JsonValue &) {}),
            std::string(kFile) + ": a: given twice in one object; only one would count: give it "
                                 "once");
  EXPECT_EQ(error_of(R"({"l": {"s": [{"p": 1}, [2, {}], {"t": {"x": 1}, "p": 2, "p": 3}]}})",
                     [](const JsonValue &) {}),
            std::string(kFile) +
                ": l.s[2].p: given twice in one object; only one would count: give it once");
  // An empty key is named as JSON spells it (the scene fuzzer found a blank
  // field here).
  EXPECT_EQ(error_of(R"({"": 1, "": 2})", [](const JsonValue &) {}),
            std::string(kFile) +
                ": \"\": given twice in one object; only one would count: give it once");
  EXPECT_EQ(error_of(R"({"": 1})", [](const JsonValue &v) { v.object({}, {"a"}); }),
            std::string(kFile) + ": \"\": unknown field");
  // The same key in different objects is no duplicate.
  EXPECT_EQ(error_of(R"({"a": {"k": 1}, "b": {"k": 2}, "c": [{"k": 3}, {"k": 4}]})",
                     [](const JsonValue &) {}),
            "(no error)");
}

TEST(ConfigJson, DamagedTextGivesAValueOrAConfigError) {
  const std::string good = R"({"a": [1, 2.5, -3e2], "b": {"c": "d", "e": true}, "f": null})";
  const auto read = [](const JsonValue &r) {
    r.object({"a", "b"}, {"f"});
    (void)r.at("a").numbers(3);
    r.at("b").object({"c", "e"});
    (void)r.at("b").at("c").string();
    (void)r.at("b").at("e").boolean();
  };
  EXPECT_EQ(error_of(good, read), "(no error)");
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (const char c : {'0', '"', '[', '}', ',', '-', 'e', 'N', '9', '\0', '\xff'}) {
      std::string t = good;
      t[i] = c;
      const std::string got = error_of(t, read);
      EXPECT_EQ(got.find("json.exception"), std::string::npos) << t << " gave " << got;
    }
    EXPECT_NE(error_of(good.substr(0, i), read), "(no error)") << i;
  }
  EXPECT_NE(error_of(std::string(100000, '['), read), "(no error)");
}

} // namespace
} // namespace camhead::base
