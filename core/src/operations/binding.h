// How an operation enters the catalogue: its function, then one line per option field and
// one per report field. The field gives the type and, from `Options{}`, the default; the
// binding gives the id, label, range and help that every front end shows. Nothing else
// names a parameter or a report key: the CLI, MeshLab, Blender and JSON read the table.
//
//   return Binding<DecimateOptions, DecimateReport>("decimate", "Decimate", Category::remeshing, help, run)
//       .option(&DecimateOptions::target_ratio, "target_ratio", "Target ratio", between(0, 1), "Fraction ...")
//       .result(&DecimateReport::faces_after, "faces_after");
#pragma once

#include <algorithm>
#include <concepts>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "hedge/catalogue.h"
#include "hedge/error.h"
#include "list.h"
#include "selection.h"

namespace hedge {

//! An option or report field as a catalogue value: bool, any integer, any real, text.
template <class T>
Value field_value(const T& x) {
  if constexpr (std::is_same_v<T, bool>)
    return x;
  else if constexpr (std::is_integral_v<T>)
    return static_cast<std::int64_t>(x);
  else if constexpr (std::is_floating_point_v<T>)
    return static_cast<double>(x);
  else
    return std::string(x);
}

template <class Options, class Report>
class Binding {
 public:
  using Function = std::function<Report(Mesh&, const Options&, Progress&)>;
  //! What a report field shows, or nothing when it does not apply to this run.
  using Getter = std::function<std::optional<Value>(const Options&, const Report&)>;

  Binding(std::string id, std::string title, Category category, std::string help, Function function)
      : state_(std::make_shared<State>()) {
    op_.id = std::move(id);
    op_.title = std::move(title);
    op_.category = category;
    op_.help = std::move(help);
    state_->function = std::move(function);
  }

  //! A bool option.
  Binding& option(bool Options::*field, std::string id, std::string label, std::string help) {
    add_param(ParamType::boolean, std::move(id), std::move(label), std::move(help), {}, Options{}.*field);
    state_->setters.push_back(
        [field, key = op_.params.back().id](Options& o, const ParamValues& v) { o.*field = v.get_bool(key); });
    return *this;
  }

  //! An integer or real option, within `range`.
  template <class T>
  requires(std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) Binding& option(T Options::*field, std::string id,
                                                                                std::string label, Range range,
                                                                                std::string help) {
    const T fallback = Options{}.*field;
    if (!range.contains(static_cast<double>(fallback)))
      throw Error("internal: default of " + op_.id + "." + id + " is out of its range");
    constexpr ParamType type = std::is_integral_v<T> ? ParamType::integer : ParamType::real;
    add_param(type, std::move(id), std::move(label), std::move(help), range, field_value(fallback));
    state_->setters.push_back([field, key = op_.params.back().id](Options& o, const ParamValues& v) {
      if constexpr (std::is_integral_v<T>)
        o.*field = static_cast<T>(v.get_int(key));
      else
        o.*field = static_cast<T>(v.get_real(key));
    });
    return *this;
  }

  //! An option taking one of an enum's values, listed in the order front ends show them and
  //! named by `name` (the enum's own naming function, which the CLI and reports share).
  template <class E>
  Binding& choice(E Options::*field, std::string id, std::string label, std::vector<E> values, const char* (*name)(E),
                  std::string help) {
    std::vector<std::string> choices;
    for (E value : values) choices.push_back(name(value));
    // A default users could not pick back would make the front ends disagree with the core.
    if (std::find(values.begin(), values.end(), Options{}.*field) == values.end())
      throw std::logic_error(op_.id + ": the default of " + id + " is not among its choices");
    add_param(ParamType::choice, std::move(id), std::move(label), std::move(help), {},
              std::string(name(Options{}.*field)));
    op_.params.back().choices = std::move(choices);
    state_->setters.push_back([field, values, name, key = op_.params.back().id](Options& o, const ParamValues& v) {
      for (E value : values)
        if (v.get_choice(key) == name(value)) o.*field = value;
    });
    return *this;
  }

  //! A vertex attribute picked by name (ParamType::vertex_channel), empty for none. The
  //! operation looks it up in the mesh and refuses a name it does not find.
  Binding& vertex_channel(std::string Options::*field, std::string id, std::string label, std::string help) {
    add_param(ParamType::vertex_channel, std::move(id), std::move(label), std::move(help), {},
              std::string(Options{}.*field));
    state_->setters.push_back(
        [field, key = op_.params.back().id](Options& o, const ParamValues& v) { o.*field = v.get_text(key); });
    return *this;
  }

  //! An option every catalogue run sets to `value`, not shown to users (e.g. no backup copy:
  //! run_operation's mesh is built for the run and dropped on failure).
  template <class T>
  Binding& fixed(T Options::*field, T value) {
    state_->setters.push_back([field, value](Options& o, const ParamValues&) { o.*field = value; });
    return *this;
  }

  //! A report field, always shown.
  template <class T>
  Binding& result(T Report::*field, std::string id) {
    return result(std::move(id),
                  [field](const Options&, const Report& r) -> std::optional<Value> { return field_value(r.*field); });
  }

  //! A report value computed from the run's options and report; shown when `get` gives one.
  Binding& result(std::string id, Getter get) {
    op_.results.push_back(id);
    state_->getters.emplace_back(std::move(id), std::move(get));
    return *this;
  }

  //! The report's notes for people (why it stopped early, what it left alone).
  Binding& messages(std::function<std::vector<std::string>(const Options&, const Report&)> get) {
    state_->messages = std::move(get);
    return *this;
  }
  Binding& messages(std::vector<std::string> Report::*field) {
    return messages([field](const Options&, const Report& r) { return r.*field; });
  }

  //! The selection_only option, with one id, label and message for every operation that has
  //! it (selection.h): a run with it on and nothing selected says so. `help` says what the
  //! selection limits in this operation.
  Binding& selection(bool Options::*field, std::string help) {
    option(field, "selection_only", "Selection only", std::move(help));
    state_->selection = field;
    return *this;
  }

  //! For a report-only operation: the mesh is measured, not changed.
  Binding& measures_only() {
    op_.changes_mesh = false;
    return *this;
  }

  operator Operation() const {
    Operation op = op_;
    op.run = [state = state_](Mesh& mesh, const ParamValues& values, Progress& progress) {
      Options options;
      for (const auto& set : state->setters) set(options, values);
      const bool nothing_selected = state->selection && options.*(state->selection) && !detail::has_selection(mesh);
      const Report r = state->function(mesh, options, progress);
      OperationReport report;
      for (const auto& [id, get] : state->getters)
        if (std::optional<Value> value = get(options, r)) report.add(id, std::move(*value));
      if (state->messages) report.messages = state->messages(options, r);
      if (nothing_selected) report.messages.push_back(detail::kNothingSelected);
      return report;
    };
    return op;
  }

 private:
  using Setter = std::function<void(Options&, const ParamValues&)>;
  struct State {
    Function function;
    std::vector<Setter> setters;
    std::vector<std::pair<std::string, Getter>> getters;
    std::function<std::vector<std::string>(const Options&, const Report&)> messages;
    bool Options::*selection = nullptr;
  };

  void add_param(ParamType type, std::string id, std::string label, std::string help, Range range, Value fallback) {
    for (const ParamSpec& p : op_.params)
      if (p.id == id) throw Error("internal: " + op_.id + " binds " + id + " twice");
    ParamSpec p;
    p.id = std::move(id);
    p.label = std::move(label);
    p.help = std::move(help);
    p.type = type;
    p.default_value = std::move(fallback);
    p.range = range;
    op_.params.push_back(std::move(p));
  }

  Operation op_;
  std::shared_ptr<State> state_;
};

}  // namespace hedge
