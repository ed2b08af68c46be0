// The catalogue: every operation declared once (id, title, category, help, parameters and
// the function that runs it). The CLI, the MeshLab plugin and the Blender add-on generate
// their commands, filters and operators from this list and nothing else.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "hedge/build.h"
#include "hedge/mesh.h"
#include "hedge/progress.h"
#include "hedge/soup.h"

namespace hedge {

using Value = std::variant<bool, std::int64_t, double, std::string>;
std::string value_text(const Value& value);

//! vertex_channel: the name of a vertex attribute of the mesh (a Soup vertex channel), empty
//! for none; a value that names no channel is refused by the operation, which knows the mesh.
enum class ParamType { boolean, integer, real, choice, vertex_channel };
const char* param_type_name(ParamType type);

//! Where operations appear: MeshLab's filter classes, Blender's panel groups, `hedge list`.
enum class Category { measure, remeshing, smoothing, cleaning };
//! Every category, in the order front ends list them.
inline constexpr Category kCategories[] = {Category::measure, Category::remeshing, Category::smoothing,
                                           Category::cleaning};
//! "Measure", "Remeshing", "Smoothing", "Cleaning".
const char* category_name(Category category);

//! The values an integer or real parameter takes: min to max, both included. No max means
//! no upper limit (a length, a count), which front ends show as an open field, not a slider.
struct Range {
  double min = 0;
  std::optional<double> max;
  bool contains(double x) const { return x >= min && (!max || x <= *max); }
};
inline Range between(double min, double max) { return {min, max}; }
inline Range at_least(double min) { return {min, std::nullopt}; }

//! One parameter. Ids are snake_case and identical in every front end (CLI flags use
//! dashes: --target-ratio). Operations declare them by binding an options field
//! (src/operations/binding.h), which gives the type and the default.
struct ParamSpec {
  std::string id;
  std::string label;  //!< short name for UIs, e.g. "Target ratio"
  std::string help;
  ParamType type = ParamType::real;
  Value default_value;               //!< of the parameter's type; a choice's default is its name
  Range range;                       //!< integer and real
  std::vector<std::string> choices;  //!< for choice

  //! The default's index in choices (choice parameters).
  std::size_t default_choice() const;
  //! The default as text, as a user would type it.
  std::string default_text() const;
  //! "0 to 1", "one of loop, catmull_clark", "true or false", "a vertex attribute's name".
  std::string range_text() const;
};

//! JSON text of a string (quoted and escaped) and of a value (a non-finite number is null).
std::string json_string(const std::string& s);
std::string json_value(const Value& value);

//! One JSON object, keys in the order added: {"a": 1, "b": "x"}. The one way the core and
//! the CLI write JSON, so every string is escaped.
class JsonObject {
 public:
  JsonObject& add(const std::string& key, const Value& value) { return raw(key, json_value(value)); }
  template <class T>
  requires std::is_arithmetic_v<T> JsonObject& add(const std::string& key, T x) {
    if constexpr (std::is_same_v<T, bool>)
      return add(key, Value(x));
    else if constexpr (std::is_integral_v<T>)
      return add(key, Value(static_cast<std::int64_t>(x)));
    else
      return add(key, Value(static_cast<double>(x)));
  }
  JsonObject& add(const std::string& key, const char* s) { return add(key, Value(std::string(s))); }
  //! A value already in JSON (a nested object or array).
  JsonObject& raw(const std::string& key, const std::string& json) {
    text_ += (text_.size() > 1 ? ", " : "") + json_string(key) + ": " + json;
    return *this;
  }
  std::string str() const { return text_ + "}"; }

 private:
  std::string text_ = "{";
};

//! JSON of a list of strings, and of a parameter (id, label, type, default, min and max for
//! numbers, max null when unbounded, choices, range_text, help).
std::string json_list(const std::vector<std::string>& items);
JsonObject param_json(const ParamSpec& p);

//! Checked parameter values of one run: every parameter of the operation is present.
class ParamValues {
 public:
  bool get_bool(const std::string& id) const;
  std::int64_t get_int(const std::string& id) const;
  double get_real(const std::string& id) const;
  const std::string& get_choice(const std::string& id) const;
  const std::string& get_text(const std::string& id) const;  //!< vertex_channel
  void set(const std::string& id, Value value) { values_[id] = std::move(value); }
  const std::map<std::string, Value>& all() const { return values_; }

 private:
  const Value& at(const std::string& id) const;
  std::map<std::string, Value> values_;
};

//! What an operation did, in order: counts, measured errors, time. Hosts show it; the CLI
//! prints it (or as JSON).
struct OperationReport {
  std::vector<std::pair<std::string, Value>> entries;
  std::vector<std::string> messages;

  void add(std::string key, Value value) { entries.emplace_back(std::move(key), std::move(value)); }
  const Value* find(const std::string& key) const;
  std::string to_text() const;
  std::string to_json() const;
};

struct Operation {
  std::string id;     //!< snake_case: "decimate"
  std::string title;  //!< "Decimate": MeshLab shows "Hedge: Decimate"
  Category category = Category::measure;
  std::string help;  //!< what it does, when to use it, the paper it follows
  std::vector<ParamSpec> params;
  //! The report's keys, in order (some appear only when they apply).
  std::vector<std::string> results;
  bool changes_mesh = true;  //!< false for report-only operations
  std::function<OperationReport(Mesh&, const ParamValues&, Progress&)> run;

  const ParamSpec* find_param(const std::string& id) const;
};

//! Every operation, in menu order.
const std::vector<Operation>& catalogue();
//! Throws Error listing the known ids when there is no such operation.
const Operation& find_operation(const std::string& id);
//! Every operation and its parameters as one JSON object {"operations": [...]}, for scripts
//! (`hedge list --json`): ids, titles, categories, help, and per parameter its type, default,
//! limits (integer and real), choices and range text.
std::string catalogue_json();

//! Turns text values (CLI, scripts) into checked values; parameters not given take their
//! defaults. Unknown ids, wrong types and out-of-range values throw Error naming the
//! parameter and what is allowed.
ParamValues resolve_params(const Operation& op, const std::map<std::string, std::string>& given);
//! Same for typed values (MeshLab, Blender).
ParamValues resolve_params(const Operation& op, const std::map<std::string, Value>& given);

struct RunResult {
  Soup soup;               //!< the result; empty for report-only operations (changes_mesh false)
  OperationReport report;  //!< the operation's report, after the build report's entries
  BuildReport build;
};

//! The whole pipeline the hosts call: build, run, validate, extract. Throws Error (or
//! Cancelled) and leaves `input` untouched on failure.
RunResult run_operation(const Operation& op, const Soup& input, const ParamValues& params, Progress& progress);

}  // namespace hedge
