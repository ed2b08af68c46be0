// The catalogue: every operation well declared, parameters checked with messages that
// name the parameter, and the build -> run -> extract pipeline.
#include "hedge/catalogue.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <regex>
#include <set>

#include "hedge/error.h"

namespace hedge {
namespace {

using ::testing::HasSubstr;

Soup two_triangles() {
  Soup s;
  s.positions = {Point{{0, 0, 0}}, Point{{1, 0, 0}}, Point{{1, 1, 0}}, Point{{0, 1, 0}}};
  s.add_face({0, 1, 2});
  s.add_face({0, 2, 3});
  return s;
}

TEST(Catalogue, EveryOperationIsWellDeclared) {
  std::set<std::string> ids;
  const std::regex snake("[a-z][a-z0-9_]*");
  for (const Operation& op : catalogue()) {
    EXPECT_TRUE(std::regex_match(op.id, snake)) << op.id;
    EXPECT_TRUE(ids.insert(op.id).second) << "duplicate " << op.id;
    EXPECT_FALSE(op.title.empty()) << op.id;
    EXPECT_FALSE(op.category.empty()) << op.id;
    EXPECT_GT(op.help.size(), 40u) << op.id << " needs real help text";
    ASSERT_TRUE(op.run) << op.id;
    std::set<std::string> params;
    for (const ParamSpec& p : op.params) {
      EXPECT_TRUE(std::regex_match(p.id, snake)) << op.id << "." << p.id;
      EXPECT_TRUE(params.insert(p.id).second) << op.id << " repeats " << p.id;
      EXPECT_FALSE(p.help.empty()) << op.id << "." << p.id;
      EXPECT_FALSE(p.label.empty()) << op.id << "." << p.id;
      if (p.type == ParamType::integer || p.type == ParamType::real) {
        EXPECT_LE(p.min, p.default_value) << op.id << "." << p.id;
        EXPECT_LE(p.default_value, p.max) << op.id << "." << p.id;
      }
      if (p.type == ParamType::choice) {
        EXPECT_FALSE(p.choices.empty());
        EXPECT_LT(p.default_value, double(p.choices.size()));
      }
    }
    // Defaults always resolve.
    EXPECT_NO_THROW(resolve_params(op, std::map<std::string, std::string>{})) << op.id;
  }
  EXPECT_TRUE(ids.count("report"));
}

TEST(Catalogue, UnknownOperationListsTheKnownOnes) {
  try {
    find_operation("nonsense");
    FAIL();
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("nonsense"));
    EXPECT_THAT(e.what(), HasSubstr("report"));
  }
}

// Checks each parameter of every operation: out-of-range and wrongly typed values are
// refused with a message naming the parameter and the allowed range.
TEST(Catalogue, ParametersAreChecked) {
  for (const Operation& op : catalogue()) {
    EXPECT_THROW(resolve_params(op, std::map<std::string, std::string>{{"no_such_parameter", "1"}}), Error);
    for (const ParamSpec& p : op.params) {
      std::vector<std::string> bad;
      switch (p.type) {
        case ParamType::boolean: bad = {"maybe", "2"}; break;
        case ParamType::integer: bad = {"1.5", "abc", std::to_string(static_cast<long long>(p.max) + 1), "-999999999999"}; break;
        case ParamType::real: bad = {"abc", "nan", "1e400"}; if (p.min > -1e300) bad.push_back("-1e299"); break;
        case ParamType::choice: bad = {"no_such_choice"}; break;
      }
      for (const auto& value : bad) {
        if (p.type == ParamType::integer && value == std::to_string(static_cast<long long>(p.max) + 1) && p.max >= 9e15) continue;
        try {
          resolve_params(op, std::map<std::string, std::string>{{p.id, value}});
          ADD_FAILURE() << op.id << "." << p.id << " accepted " << value;
        } catch (const Error& e) {
          EXPECT_THAT(e.what(), HasSubstr(p.id));
          EXPECT_THAT(e.what(), HasSubstr(p.range_text()));
        }
      }
      // The default, given explicitly as text, is accepted.
      EXPECT_NO_THROW(resolve_params(op, std::map<std::string, std::string>{{p.id, p.default_text()}})) << op.id << "." << p.id;
    }
  }
}

TEST(Catalogue, TypedValuesResolve) {
  Operation op;
  op.id = "demo";
  op.params = {ParamSpec::real("ratio", "Ratio", 0.5, 0, 1, "a ratio"), ParamSpec::integer("count", "Count", 3, 1, 10, "n"),
               ParamSpec::boolean("flag", "Flag", true, "f"), ParamSpec::choice("mode", "Mode", {"a", "b"}, 1, "m")};
  ParamValues v = resolve_params(op, std::map<std::string, Value>{{"ratio", std::int64_t(1)}, {"mode", std::string("a")}});
  EXPECT_EQ(v.get_real("ratio"), 1.0);
  EXPECT_EQ(v.get_int("count"), 3);
  EXPECT_TRUE(v.get_bool("flag"));
  EXPECT_EQ(v.get_choice("mode"), "a");
  EXPECT_THROW(resolve_params(op, std::map<std::string, Value>{{"ratio", 1.5}}), Error);
  EXPECT_THROW(resolve_params(op, std::map<std::string, Value>{{"count", 2.5}}), Error);
  EXPECT_THROW(resolve_params(op, std::map<std::string, Value>{{"mode", std::string("c")}}), Error);
  EXPECT_EQ(op.params[0].range_text(), "a number from 0 to 1");
  EXPECT_EQ(op.params[3].range_text(), "one of a, b");
}

TEST(Catalogue, ReportRunsWithoutChangingAnything) {
  const Operation& op = find_operation("report");
  EXPECT_FALSE(op.changes_mesh);
  Soup input = two_triangles();
  RunResult r = run_operation(op, input, resolve_params(op, std::map<std::string, std::string>{}), Progress::none());
  ASSERT_NE(r.report.find("faces"), nullptr);
  EXPECT_EQ(std::get<std::int64_t>(*r.report.find("faces")), 2);
  EXPECT_EQ(std::get<std::int64_t>(*r.report.find("boundary_loops")), 1);
  EXPECT_EQ(std::get<std::int64_t>(*r.report.find("euler_characteristic")), 1);
  EXPECT_THAT(r.report.to_json(), HasSubstr("\"faces\": 2"));
  EXPECT_TRUE(r.soup.positions.empty());
}

TEST(Catalogue, ProgressCanCancel) {
  const Operation& op = find_operation("report");
  Progress stop([](double, const std::string&) { return false; });
  EXPECT_THROW(run_operation(op, two_triangles(), resolve_params(op, std::map<std::string, std::string>{}), stop), Cancelled);
}

TEST(Catalogue, BadSoupIsRefusedWithItsReason) {
  const Operation& op = find_operation("report");
  Soup bad = two_triangles();
  bad.corners[4] = 9;
  try {
    run_operation(op, bad, resolve_params(op, std::map<std::string, std::string>{}), Progress::none());
    FAIL();
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("face 1"));
    EXPECT_THAT(e.what(), HasSubstr("9"));
  }
}

}  // namespace
}  // namespace hedge
