// Catalogue -> MeshLab filters, independent of the plugin API version. See hedge_filters.h.
#include "hedge_filters.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <climits>
#include <cmath>
#include <new>
#include <type_traits>
#include <variant>

#include "cmesh_soup.h"
#include "hedge/error.h"

namespace hedge::meshlab {

const Operation& operation_at(int id) { return catalogue().at(static_cast<std::size_t>(id)); }

QString filter_name(const Operation& op) { return QString::fromStdString("Hedge: " + op.title); }

QString python_filter_name(const Operation& op) { return QString::fromStdString("hedge_" + op.id); }

QString filter_info(const Operation& op) {
  QString html = QString::fromStdString(op.help).toHtmlEscaped();
  html.replace("\n", "<br>");
  return html;
}

int filter_class(const Operation& op) {
  // MeshLab's FilterClass bits (interfaces.h in 2020.09, filter_plugin.h in 2022+).
  switch (op.category) {
    case Category::cleaning:
      return 0x00002;
    case Category::remeshing:
      return 0x00004;
    case Category::smoothing:
      return 0x00080;
    case Category::measure:
      return 0x10000;
  }
  return 0x00000;  // Generic
}

int precondition_mask(const Operation&) { return MeshModel::MM_FACENUMBER; }

int postcondition_mask(const Operation& op) {
  // The mesh is rebuilt. Attribute changes need no bits here: MeshLab compares the data masks
  // before and after, and colour bits would make the GUI render colours the mesh may not have.
  return op.changes_mesh ? MeshModel::MM_GEOMETRY_AND_TOPOLOGY_CHANGE : MeshModel::MM_NONE;
}

RichKind rich_kind(const ParamSpec& spec) {
  switch (spec.type) {
    case ParamType::boolean:
      return RichKind::boolean;
    case ParamType::integer:
      return RichKind::integer;
    case ParamType::choice:
      return RichKind::choice;
    case ParamType::vertex_channel:
      return RichKind::text;
    case ParamType::real:
      // A slider needs both ends; an open range (a length, a distance) is a plain field.
      return spec.range.max ? RichKind::bounded_real : RichKind::real;
  }
  return RichKind::real;
}

const char* rich_type_name(RichKind kind) {
  switch (kind) {
    case RichKind::boolean:
      return "RichBool";
    case RichKind::integer:
      return "RichInt";
    case RichKind::real:
      return "RichFloat";
    case RichKind::bounded_real:
      return "RichDynamicFloat";
    case RichKind::choice:
      return "RichEnum";
    case RichKind::text:
      return "RichString";
  }
  return "RichFloat";
}

QString param_tooltip(const ParamSpec& spec) {
  return QString::fromStdString(spec.help + " [" + spec.id + ": " + spec.range_text() + ", default " +
                                spec.default_text() + "]");
}

int int_bound(double bound) { return static_cast<int>(std::clamp(bound, double(INT_MIN), double(INT_MAX))); }

void add_parameters(const Operation& op, RichParameterList& parameters) {
  for (const ParamSpec& spec : op.params) {
    const QString name = QString::fromStdString(spec.id), label = QString::fromStdString(spec.label);
    const QString tooltip = param_tooltip(spec);
    switch (rich_kind(spec)) {
      case RichKind::boolean:
        parameters.addParam(RichBool(name, std::get<bool>(spec.default_value), label, tooltip));
        break;
      case RichKind::integer:
        parameters.addParam(
            RichInt(name, int_bound(double(std::get<std::int64_t>(spec.default_value))), label, tooltip));
        break;
      case RichKind::real:
        parameters.addParam(RichFloat(name, static_cast<float>(std::get<double>(spec.default_value)), label, tooltip));
        break;
      case RichKind::bounded_real:
        parameters.addParam(RichDynamicFloat(name, static_cast<float>(std::get<double>(spec.default_value)),
                                             static_cast<float>(spec.range.min), static_cast<float>(*spec.range.max),
                                             label, tooltip));
        break;
      case RichKind::choice: {
        QStringList choices;
        for (const std::string& choice : spec.choices) choices << QString::fromStdString(choice);
        parameters.addParam(RichEnum(name, static_cast<int>(spec.default_choice()), choices, label, tooltip));
        break;
      }
      case RichKind::text:
        parameters.addParam(
            RichString(name, QString::fromStdString(std::get<std::string>(spec.default_value)), label, tooltip));
        break;
    }
  }
}

std::map<std::string, Value> given_values(const Operation& op, const RichParameterList& parameters) {
  std::map<std::string, Value> given;
  for (const ParamSpec& spec : op.params) {
    const QString name = QString::fromStdString(spec.id);
    if (!parameters.hasParameter(name)) continue;
    const ::Value& value = parameters.getParameterByName(name).value();
#if HEDGE_MESHLAB_FILTER_PLUGIN
    const bool integer = value.isInt();  // 2022+ holds an enum's index as an int value
#else
    const bool integer = value.isEnum() || value.isInt();
#endif
    if (value.isBool())
      given[spec.id] = value.getBool();
    else if (integer)
      given[spec.id] = static_cast<std::int64_t>(value.getInt());
    else if (value.isFloat())
      given[spec.id] = real_from_float(value.getFloat());
    else if (value.isString())
      given[spec.id] = value.getString().toStdString();
    else
      given[spec.id] = value.typeName().toStdString();  // a type hedge never declares: refused by name
  }
  return given;
}

double real_from_float(float value) {
  char text[32];
  auto written = std::to_chars(text, text + sizeof text, value);
  double exact = value;
  if (written.ec == std::errc()) std::from_chars(text, written.ptr, exact);
  return exact;
}

namespace {

QVariant variant_of(const Value& value) {
  return std::visit(
      [](const auto& v) -> QVariant {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::string>)
          return QString::fromStdString(v);
        else if constexpr (std::is_same_v<T, std::int64_t>)
          return QVariant(static_cast<qlonglong>(v));
        else
          return QVariant(v);
      },
      value);
}

}  // namespace

ModelRun run_on_model(const Operation& op, const std::map<std::string, Value>& given, MeshModel& model,
                      vcg::CallBackPos* cb) {
  const QString name = filter_name(op);
  const ParamValues values = resolve_params(op, given);  // refuses out-of-range values before any work

  // MeshLab's callback takes whole percents and a C string that must outlive the call. It is
  // called when the stage changes and every 5 % within one: the GUI redraws on each call, and
  // meshlabserver prints each (without a newline), so finer steps only add noise.
  std::string text;
  int last_percent = -1;
  std::string last_stage;
  Progress progress([&](double fraction, const std::string& stage) {
    if (cb == nullptr) return true;
    const int percent = std::clamp(static_cast<int>(fraction * 100.0), 0, 100);
    if (stage == last_stage && percent < last_percent + 5) return true;
    last_percent = percent;
    last_stage = stage;
    text = name.toStdString() + ": " + stage;
    return cb(percent, text.c_str());
  });

  using Clock = std::chrono::steady_clock;
  const auto seconds_since = [](Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  auto start = Clock::now();
  const Soup input = soup_from_mesh(model);
  const double read_seconds = seconds_since(start);
  RunResult result = run_operation(op, input, values, progress);
  double write_seconds = 0;

  ModelRun run;
  auto line = [&](const std::string& s) { run.lines << name + ": " + QString::fromStdString(s); };
  if (op.changes_mesh) {
    MeshWriteReport written;
    try {
      start = Clock::now();
      written = write_soup_to_mesh(result.soup, input, model);
      write_seconds = seconds_since(start);
    } catch (const std::bad_alloc&) {
      // Only allocation can fail while writing; put the input back, which needs no more memory than it had.
      result = {};
      try {
        write_soup_to_mesh(input, input, model);
      } catch (const std::bad_alloc&) {
        throw Error("out of memory while writing the result into MeshLab; the mesh could not be restored");
      }
      throw Error("out of memory while writing the result into MeshLab; the mesh was restored");
    }
    if (written.polygons_triangulated)
      line(std::to_string(written.polygons_triangulated) + " polygons stored as triangle fans with faux edges");
    if (written.edges_dropped) line(std::to_string(written.edges_dropped) + " edge elements (wireframe) dropped");
  }
  for (const auto& [key, value] : result.report.entries) {
    line(key + " = " + value_text(value));
    run.report[key] = variant_of(value);
  }
  QStringList messages;
  for (const auto& message : result.report.messages) {
    line(message);
    messages << QString::fromStdString(message);
  }
  if (!messages.isEmpty()) run.report["messages"] = messages;
  // The cost of the translation CMeshO <-> Soup, next to the operation's own "seconds".
  line("meshlab_read_seconds = " + value_text(read_seconds));
  run.report["meshlab_read_seconds"] = read_seconds;
  if (op.changes_mesh) {
    line("meshlab_write_seconds = " + value_text(write_seconds));
    run.report["meshlab_write_seconds"] = write_seconds;
  }
  return run;
}

}  // namespace hedge::meshlab
