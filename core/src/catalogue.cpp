// The catalogue of operations, parameter checking, and the build -> run -> extract
// pipeline shared by every front end.
#include "hedge/catalogue.h"

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "hedge/error.h"
#include "hedge/validate.h"
#include "operations/list.h"

namespace hedge {

const char* param_type_name(ParamType type) {
  switch (type) {
    case ParamType::boolean:
      return "bool";
    case ParamType::integer:
      return "int";
    case ParamType::real:
      return "float";
    case ParamType::choice:
      return "enum";
    case ParamType::vertex_channel:
      return "vertex_channel";
  }
  return "unknown";
}

const char* category_name(Category category) {
  switch (category) {
    case Category::measure:
      return "Measure";
    case Category::cleaning:
      return "Cleaning";
    case Category::remeshing:
      return "Remeshing";
    case Category::smoothing:
      return "Smoothing";
  }
  return "Other";
}

namespace {
std::string number_text(double x) {
  char buffer[64];
  auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, x);
  return ec == std::errc() ? std::string(buffer, end) : std::to_string(x);
}
}  // namespace

std::size_t ParamSpec::default_choice() const {
  for (std::size_t i = 0; i < choices.size(); ++i)
    if (Value(choices[i]) == default_value) return i;
  return 0;
}

std::string ParamSpec::default_text() const { return value_text(default_value); }

std::string ParamSpec::range_text() const {
  const bool integral = type == ParamType::integer;
  auto bound = [&](double x) { return integral ? std::to_string(static_cast<std::int64_t>(x)) : number_text(x); };
  switch (type) {
    case ParamType::boolean:
      return "true or false";
    case ParamType::integer:
    case ParamType::real: {
      const std::string what = integral ? "an integer " : "a number ";
      if (!range.max) return what + bound(range.min) + " or more";
      return what + "from " + bound(range.min) + " to " + bound(*range.max);
    }
    case ParamType::choice: {
      std::string out = "one of";
      for (std::size_t i = 0; i < choices.size(); ++i) out += (i ? ", " : " ") + choices[i];
      return out;
    }
    case ParamType::vertex_channel:
      return "a vertex attribute's name, or empty for none";
  }
  return "";
}

std::string value_text(const Value& value) {
  return std::visit(
      [](const auto& v) -> std::string {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>)
          return v ? "true" : "false";
        else if constexpr (std::is_same_v<T, std::int64_t>)
          return std::to_string(v);
        else if constexpr (std::is_same_v<T, double>)
          return number_text(v);
        else
          return v;
      },
      value);
}

const Value& ParamValues::at(const std::string& id) const {
  auto it = values_.find(id);
  if (it == values_.end()) throw Error("internal: parameter '" + id + "' was not resolved");
  return it->second;
}
bool ParamValues::get_bool(const std::string& id) const { return std::get<bool>(at(id)); }
std::int64_t ParamValues::get_int(const std::string& id) const { return std::get<std::int64_t>(at(id)); }
double ParamValues::get_real(const std::string& id) const { return std::get<double>(at(id)); }
const std::string& ParamValues::get_choice(const std::string& id) const { return std::get<std::string>(at(id)); }
const std::string& ParamValues::get_text(const std::string& id) const { return std::get<std::string>(at(id)); }

const Value* OperationReport::find(const std::string& key) const {
  for (const auto& [k, v] : entries)
    if (k == key) return &v;
  return nullptr;
}

std::string OperationReport::to_text() const {
  std::ostringstream out;
  for (const auto& [key, value] : entries) out << key << ": " << value_text(value) << "\n";
  for (const auto& m : messages) out << m << "\n";
  return out.str();
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buffer[8];
          std::snprintf(buffer, sizeof buffer, "\\u%04x", c);
          out += buffer;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string json_value(const Value& value) {
  if (const auto* s = std::get_if<std::string>(&value)) return json_string(*s);
  if (const auto* d = std::get_if<double>(&value)) return std::isfinite(*d) ? number_text(*d) : "null";
  return value_text(value);
}

std::string OperationReport::to_json() const {
  JsonObject out;
  for (const auto& [key, value] : entries) out.add(key, value);
  std::string list = "[";
  for (std::size_t i = 0; i < messages.size(); ++i) list += (i ? ", " : "") + json_string(messages[i]);
  return out.raw("messages", list + "]").str();
}

const ParamSpec* Operation::find_param(const std::string& id) const {
  for (const auto& p : params)
    if (p.id == id) return &p;
  return nullptr;
}

const std::vector<Operation>& catalogue() {
#define HEDGE_LIST_OPERATION(name) name##_operation(),
  static const std::vector<Operation> operations = {HEDGE_OPERATIONS(HEDGE_LIST_OPERATION)};
#undef HEDGE_LIST_OPERATION
  return operations;
}

std::string json_list(const std::vector<std::string>& items) {
  std::string out = "[";
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + json_string(items[i]);
  return out + "]";
}

JsonObject param_json(const ParamSpec& p) {
  JsonObject out;
  out.add("id", p.id)
      .add("label", p.label)
      .add("type", param_type_name(p.type))
      .raw("default", json_value(p.default_value));
  if (p.type == ParamType::integer) {
    out.add("min", static_cast<std::int64_t>(p.range.min));
    out.raw("max", p.range.max ? json_value(static_cast<std::int64_t>(*p.range.max)) : "null");
  }
  if (p.type == ParamType::real)
    out.add("min", p.range.min).raw("max", p.range.max ? json_value(*p.range.max) : "null");
  return out.raw("choices", json_list(p.choices)).add("range_text", p.range_text()).add("help", p.help);
}

std::string catalogue_json() {
  std::string out = "{\"operations\": [";
  bool first_op = true;
  for (const Operation& op : catalogue()) {
    std::string params = "[";
    for (std::size_t i = 0; i < op.params.size(); ++i)
      params += (i ? ",\n  " : "\n  ") + param_json(op.params[i]).str();
    JsonObject entry;
    entry.add("id", op.id).add("title", op.title).add("category", category_name(op.category));
    entry.add("changes_mesh", op.changes_mesh).add("help", op.help).raw("params", params + "]");
    entry.raw("results", json_list(op.results));
    out += std::string(first_op ? "" : ",") + "\n " + entry.str();
    first_op = false;
  }
  return out + "\n]}\n";
}

const Operation& find_operation(const std::string& id) {
  for (const auto& op : catalogue())
    if (op.id == id) return op;
  std::string known;
  for (const auto& op : catalogue()) known += (known.empty() ? "" : ", ") + op.id;
  throw Error("unknown operation '" + id + "'; the operations are: " + known);
}

namespace {

[[noreturn]] void refuse(const Operation& op, const ParamSpec& p, const std::string& given) {
  throw Error(op.id + ": parameter " + p.id + " must be " + p.range_text() + ", got '" + given + "'");
}

Value check_value(const Operation& op, const ParamSpec& p, const Value& value) {
  const std::string text = value_text(value);
  switch (p.type) {
    case ParamType::boolean:
      if (const auto* b = std::get_if<bool>(&value)) return *b;
      if (const auto* i = std::get_if<std::int64_t>(&value); i && (*i == 0 || *i == 1)) return *i == 1;
      refuse(op, p, text);
    case ParamType::integer: {
      std::int64_t i = 0;
      if (const auto* pi = std::get_if<std::int64_t>(&value))
        i = *pi;
      else if (const auto* pd = std::get_if<double>(&value);
               pd && std::isfinite(*pd) && std::floor(*pd) == *pd && std::fabs(*pd) < 9e15)
        i = static_cast<std::int64_t>(*pd);
      else
        refuse(op, p, text);
      if (!p.range.contains(double(i))) refuse(op, p, text);
      return i;
    }
    case ParamType::real: {
      double d = 0;
      if (const auto* pd = std::get_if<double>(&value))
        d = *pd;
      else if (const auto* pi = std::get_if<std::int64_t>(&value))
        d = double(*pi);
      else
        refuse(op, p, text);
      if (!std::isfinite(d) || !p.range.contains(d)) refuse(op, p, text);
      return d;
    }
    case ParamType::choice: {
      if (const auto* s = std::get_if<std::string>(&value))
        for (const auto& c : p.choices)
          if (c == *s) return c;
      if (const auto* i = std::get_if<std::int64_t>(&value); i && *i >= 0 && std::size_t(*i) < p.choices.size())
        return p.choices[std::size_t(*i)];
      refuse(op, p, text);
    }
    case ParamType::vertex_channel:
      if (const auto* s = std::get_if<std::string>(&value)) return *s;
      refuse(op, p, text);
  }
  refuse(op, p, text);
}

Value parse_text(const Operation& op, const ParamSpec& p, const std::string& text) {
  switch (p.type) {
    case ParamType::boolean:
      if (text == "true" || text == "1" || text == "yes" || text == "on") return true;
      if (text == "false" || text == "0" || text == "no" || text == "off") return false;
      refuse(op, p, text);
    case ParamType::integer: {
      std::int64_t i = 0;
      auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), i);
      if (ec != std::errc() || end != text.data() + text.size()) refuse(op, p, text);
      return i;
    }
    case ParamType::real: {
      double d = 0;
      auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), d);
      if (ec != std::errc() || end != text.data() + text.size()) refuse(op, p, text);
      return d;
    }
    case ParamType::choice:
    case ParamType::vertex_channel:
      return text;
  }
  refuse(op, p, text);
}

template <class Given, class Convert>
ParamValues resolve(const Operation& op, const Given& given, Convert convert) {
  for (const auto& [id, value] : given)
    if (!op.find_param(id)) {
      std::string known;
      for (const auto& p : op.params) known += (known.empty() ? "" : ", ") + p.id;
      throw Error(op.id + ": unknown parameter '" + id + "'" +
                  (known.empty() ? "; it takes none" : "; its parameters are: " + known));
    }
  ParamValues values;
  for (const auto& p : op.params) {
    auto it = given.find(p.id);
    Value v = it == given.end() ? p.default_value : convert(p, it->second);
    values.set(p.id, check_value(op, p, v));
  }
  return values;
}

}  // namespace

ParamValues resolve_params(const Operation& op, const std::map<std::string, std::string>& given) {
  return resolve(op, given, [&](const ParamSpec& p, const std::string& text) { return parse_text(op, p, text); });
}

ParamValues resolve_params(const Operation& op, const std::map<std::string, Value>& given) {
  return resolve(op, given, [](const ParamSpec&, const Value& v) { return v; });
}

RunResult run_operation(const Operation& op, const Soup& input, const ParamValues& params, Progress& progress) {
  using Clock = std::chrono::steady_clock;
  auto start = Clock::now();
  progress.update(0.0, "building the half-edge mesh");
  BuildResult built = build(input);
  RunResult result;
  result.build = built.report;
  result.report = op.run(built.mesh, params, progress);
  if (op.changes_mesh) {
    check_valid(built.mesh, op.id);
    progress.update(1.0, "writing the result");
    ExtractReport extracted;
    ExtractOptions options;
    options.input = &input;
    result.soup = extract(built.mesh, options, &extracted);
    if (extracted.copies_kept_apart)
      result.report.messages.push_back("kept " + std::to_string(extracted.copies_kept_apart) +
                                       " copies of non-manifold vertices apart: welding them back would have made "
                                       "a defect the input did not have (a face using one vertex twice, a "
                                       "non-manifold edge or vertex, a duplicate face)");
  }
  double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  result.report.add("seconds", seconds);
  for (const auto& m : built.report.messages) result.report.messages.push_back("input: " + m);
  return result;
}

}  // namespace hedge
