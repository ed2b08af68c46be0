// The catalogue: every operation well declared, parameters checked with messages that
// name the parameter, and the build -> run -> extract pipeline.
#include "hedge/catalogue.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <set>
#include <stdexcept>

#include "hedge/error.h"
#include "operations/binding.h"

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
    EXPECT_STRNE(category_name(op.category), "Other") << op.id;
    EXPECT_GT(op.help.size(), 40u) << op.id << " needs real help text";
    ASSERT_TRUE(op.run) << op.id;
    std::set<std::string> params;
    for (const ParamSpec& p : op.params) {
      EXPECT_TRUE(std::regex_match(p.id, snake)) << op.id << "." << p.id;
      EXPECT_TRUE(params.insert(p.id).second) << op.id << " repeats " << p.id;
      EXPECT_FALSE(p.help.empty()) << op.id << "." << p.id;
      EXPECT_FALSE(p.label.empty()) << op.id << "." << p.id;
      if (p.type == ParamType::integer) {
        EXPECT_TRUE(p.range.contains(double(std::get<std::int64_t>(p.default_value)))) << op.id << "." << p.id;
      }
      if (p.type == ParamType::real) {
        EXPECT_TRUE(p.range.contains(std::get<double>(p.default_value))) << op.id << "." << p.id;
      }
      if (p.type == ParamType::choice) {
        EXPECT_FALSE(p.choices.empty());
        EXPECT_EQ(p.choices.at(p.default_choice()), std::get<std::string>(p.default_value)) << op.id << "." << p.id;
      }
      if (p.type == ParamType::boolean) {
        EXPECT_TRUE(std::holds_alternative<bool>(p.default_value)) << op.id << "." << p.id;
      }
      if (p.type == ParamType::vertex_channel) {
        EXPECT_EQ(p.default_value, Value(std::string())) << op.id << "." << p.id << ": none by default";
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
        case ParamType::boolean:
          bad = {"maybe", "2"};
          break;
        case ParamType::integer:
          bad = {"1.5", "abc", "-999999999999"};
          if (p.range.max) bad.push_back(std::to_string(static_cast<long long>(*p.range.max) + 1));
          break;
        case ParamType::real:
          bad = {"abc", "nan", "1e400", "-1e299"};
          if (p.range.max) bad.push_back(value_text(std::nextafter(*p.range.max, 1e300)));
          break;
        case ParamType::choice:
          bad = {"no_such_choice"};
          break;
        case ParamType::vertex_channel:
          // Any name resolves; the operation refuses one its mesh lacks (Decimate.WeightAndLockNames*).
          EXPECT_THROW(resolve_params(op, std::map<std::string, Value>{{p.id, Value(1.5)}}), Error);
          break;
      }
      for (const auto& value : bad) {
        try {
          resolve_params(op, std::map<std::string, std::string>{{p.id, value}});
          ADD_FAILURE() << op.id << "." << p.id << " accepted " << value;
        } catch (const Error& e) {
          EXPECT_THAT(e.what(), HasSubstr(p.id));
          EXPECT_THAT(e.what(), HasSubstr(p.range_text()));
        }
      }
      // The default, given explicitly as text, is accepted.
      EXPECT_NO_THROW(resolve_params(op, std::map<std::string, std::string>{{p.id, p.default_text()}}))
          << op.id << "." << p.id;
    }
  }
}

namespace demo {
enum class Mode { a, b };
const char* mode_name(Mode m) { return m == Mode::a ? "a" : "b"; }
struct Options {
  double ratio = 0.5;
  int count = 3;
  bool flag = true;
  Mode mode = Mode::b;
  std::size_t limit = 7;
};
struct Report {
  std::size_t doubled = 0;
  std::string mode;
};
Operation operation() {
  auto run = [](Mesh&, const Options& o, Progress&) { return Report{2 * o.limit, mode_name(o.mode)}; };
  return Binding<Options, Report>("demo", "Demo", Category::measure, "a demo", run)
      .option(&Options::ratio, "ratio", "Ratio", between(0, 1), "a ratio")
      .option(&Options::count, "count", "Count", between(1, 10), "n")
      .option(&Options::flag, "flag", "Flag", "f")
      .choice(&Options::mode, "mode", "Mode", {Mode::a, Mode::b}, mode_name, "m")
      .option(&Options::limit, "limit", "Limit", at_least(0), "no upper limit")
      .result(&Report::doubled, "doubled")
      .result(&Report::mode, "mode");
}
}  // namespace demo

// The binding: types and defaults come from the options struct, ranges from the binding.
TEST(Catalogue, BindingTakesTypesAndDefaultsFromTheOptions) {
  const Operation op = demo::operation();
  ASSERT_EQ(op.params.size(), 5u);
  EXPECT_EQ(op.params[0].type, ParamType::real);
  EXPECT_EQ(op.params[0].default_value, Value(0.5));
  EXPECT_EQ(op.params[1].type, ParamType::integer);
  EXPECT_EQ(op.params[1].default_value, Value(std::int64_t(3)));
  EXPECT_EQ(op.params[2].default_value, Value(true));
  EXPECT_EQ(op.params[3].default_value, Value(std::string("b")));
  EXPECT_EQ(op.params[3].default_choice(), 1u);
  EXPECT_FALSE(op.params[4].range.max);
  EXPECT_EQ(op.params[4].range_text(), "an integer 0 or more");
  EXPECT_EQ(op.results, (std::vector<std::string>{"doubled", "mode"}));
  Mesh mesh;
  ParamValues values = resolve_params(op, std::map<std::string, std::string>{{"limit", "99999999999"}, {"mode", "a"}});
  OperationReport report = op.run(mesh, values, Progress::none());
  EXPECT_EQ(report.to_json(), "{\"doubled\": 199999999998, \"mode\": \"a\", \"messages\": []}");
}

TEST(Catalogue, TypedValuesResolve) {
  const Operation op = demo::operation();
  ParamValues v =
      resolve_params(op, std::map<std::string, Value>{{"ratio", std::int64_t(1)}, {"mode", std::string("a")}});
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

// A choice whose default users could not pick is a mistake in the binding, caught at once.
TEST(Catalogue, ChoiceRefusesADefaultOutsideItsValues) {
  auto bind = [] {
    auto run = [](Mesh&, const demo::Options&, Progress&) { return demo::Report{}; };
    return Binding<demo::Options, demo::Report>("demo", "Demo", Category::measure, "a demo", run)
        .choice(&demo::Options::mode, "mode", "Mode", {demo::Mode::a}, demo::mode_name, "m");
  };
  EXPECT_THROW(bind(), std::logic_error);
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
  EXPECT_THROW(run_operation(op, two_triangles(), resolve_params(op, std::map<std::string, std::string>{}), stop),
               Cancelled);
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
