// The PUT /api/v1/alarms/rules body parser (json_views.hpp): every bad body is an HttpError 400.
#include <gtest/gtest.h>

#include "json_views.hpp"
#include "query.hpp"

namespace telltale::shore {
namespace {

int status_of(const std::string& body) {
  try {
    (void)rules_from_body(body);
  } catch (const HttpError& e) {
    return e.status();
  }
  return 200;
}

TEST(RulesBody, AcceptsRulesWithDefaults) {
  const auto rules = rules_from_body(
      R"([{"id":"heel-max","quantity":"heel","min_deg":-25,"max_deg":25,"level":"alarm"},
          {"id":"pitch","scope":"group:ILCA7","quantity":"pitch","max_deg":10}])");
  ASSERT_EQ(rules.size(), 2u);
  EXPECT_EQ(rules[1].scope, "group:ILCA7");
  EXPECT_DOUBLE_EQ(rules[1].min_deg, -90.0);
}

TEST(RulesBody, EveryBadBodyIs400) {
  // "1e400" overflows a double: nlohmann throws out_of_range, not parse_error; it was a 500 until
  // tests/fuzz/fuzz_rest found it.
  for (const char* bad :
       {"", "{", "nan", "{}", "[1]", R"([{"id":"a","quantity":"heel","min_deg":1e400}])",
        R"([{"id":"a","quantity":"heel","min_deg":-1e400}])",
        R"([{"id":"a","quantity":"heel"},{"id":"a","quantity":"pitch"}])",
        R"([{"id":"a","quantity":"heel","extra":1}])", R"([{"id":"a","quantity":"yaw"}])",
        "[\"\xff\"]"}) {
    EXPECT_EQ(status_of(bad), 400) << bad;
  }
}

}  // namespace
}  // namespace telltale::shore
