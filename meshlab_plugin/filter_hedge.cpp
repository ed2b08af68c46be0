// MeshLab 2020.09 filters from the catalogue: names, Rich parameters, and applyFilter turning
// every failure into errorMessage plus a log line (meshlabserver prints only the log).
#include "filter_hedge.h"

#include <exception>
#include <map>
#include <string>

#include "hedge/catalogue.h"
#include "hedge_filters.h"

namespace {

using hedge::meshlab::RichKind;

static_assert(MeshFilterInterface::Cleaning == 0x00002 && MeshFilterInterface::Remeshing == 0x00004 &&
                  MeshFilterInterface::Smoothing == 0x00080 && MeshFilterInterface::Measure == 0x10000,
              "hedge_filters.cpp's FilterClass values");

const hedge::Operation& operation_of(int id) { return hedge::catalogue().at(static_cast<std::size_t>(id)); }

// The Rich parameters' values as hedge values; resolve_params then checks them against the
// catalogue, so scripts get the same refusals as the CLI. Parameters a caller left out take
// their defaults there.
std::map<std::string, hedge::Value> given_values(const hedge::Operation& op, const RichParameterList& parameters) {
  std::map<std::string, hedge::Value> given;
  for (const hedge::ParamSpec& spec : op.params) {
    const QString name = QString::fromStdString(spec.id);
    if (!parameters.hasParameter(name)) continue;
    const ::Value& value = parameters.getParameterByName(name).value();
    if (value.isBool())
      given[spec.id] = value.getBool();
    else if (value.isEnum() || value.isInt())
      given[spec.id] = static_cast<std::int64_t>(value.getInt());
    else if (value.isFloat())
      given[spec.id] = hedge::meshlab::real_from_float(value.getFloat());
    else
      given[spec.id] = value.typeName().toStdString();  // a type hedge never declares: refused by name
  }
  return given;
}

}  // namespace

FilterHedgePlugin::FilterHedgePlugin() {
  for (std::size_t i = 0; i < hedge::catalogue().size(); ++i) typeList << static_cast<FilterIDType>(i);
  for (FilterIDType id : types()) actionList << new QAction(filterName(id), this);
}

QString FilterHedgePlugin::pluginName() const { return "FilterHedge"; }

QString FilterHedgePlugin::filterName(FilterIDType filter) const {
  return hedge::meshlab::filter_name(operation_of(filter));
}

QString FilterHedgePlugin::filterInfo(FilterIDType filter) const {
  return hedge::meshlab::filter_info(operation_of(filter));
}

MeshFilterInterface::FilterClass FilterHedgePlugin::getClass(QAction* action) {
  return static_cast<FilterClass>(hedge::meshlab::filter_class(operation_of(ID(action))));
}

MeshFilterInterface::FILTER_ARITY FilterHedgePlugin::filterArity(QAction*) const { return SINGLE_MESH; }

int FilterHedgePlugin::getPreConditions(QAction*) const { return MeshModel::MM_FACENUMBER; }

int FilterHedgePlugin::postCondition(QAction* action) const {
  // The mesh is rebuilt. Attribute changes need no bits here: MeshLab compares the data masks
  // before and after, and colour bits would make the GUI render colours the mesh may not have.
  return operation_of(ID(action)).changes_mesh ? MeshModel::MM_GEOMETRY_AND_TOPOLOGY_CHANGE : MeshModel::MM_NONE;
}

void FilterHedgePlugin::initParameterSet(QAction* action, MeshModel&, RichParameterList& parameters) {
  for (const hedge::ParamSpec& spec : operation_of(ID(action)).params) {
    const QString name = QString::fromStdString(spec.id), label = QString::fromStdString(spec.label);
    const QString tooltip = hedge::meshlab::param_tooltip(spec);
    switch (hedge::meshlab::rich_kind(spec)) {
      case RichKind::boolean:
        parameters.addParam(RichBool(name, spec.default_value != 0, label, tooltip));
        break;
      case RichKind::integer:
        parameters.addParam(RichInt(name, hedge::meshlab::int_bound(spec.default_value), label, tooltip));
        break;
      case RichKind::real:
        parameters.addParam(RichFloat(name, static_cast<float>(spec.default_value), label, tooltip));
        break;
      case RichKind::bounded_real:
        parameters.addParam(RichDynamicFloat(name, static_cast<float>(spec.default_value), static_cast<float>(spec.min),
                                             static_cast<float>(spec.max), label, tooltip));
        break;
      case RichKind::choice: {
        QStringList choices;
        for (const std::string& choice : spec.choices) choices << QString::fromStdString(choice);
        parameters.addParam(RichEnum(name, static_cast<int>(spec.default_value), choices, label, tooltip));
        break;
      }
    }
  }
}

bool FilterHedgePlugin::applyFilter(QAction* action, MeshDocument& document, const RichParameterList& parameters,
                                    vcg::CallBackPos* cb) {
  const hedge::Operation& op = operation_of(ID(action));
  errorMessage.clear();
  try {
    if (document.mm() == nullptr) throw hedge::Error(op.id + ": there is no mesh to work on");
    const QStringList lines = hedge::meshlab::run_on_model(op, given_values(op, parameters), *document.mm(), cb);
    for (const QString& line : lines) Log(GLLogStream::FILTER, line.toStdString());
    return true;
  } catch (const std::exception& e) {
    // Catch everything: an exception escaping a plugin ends MeshLab (the GUI catches only bad_alloc).
    errorMessage = QString::fromUtf8(e.what());
  } catch (...) {
    errorMessage = "unknown error";
  }
  Log(GLLogStream::WARNING, (hedge::meshlab::filter_name(op) + " failed: " + errorMessage).toStdString());
  return false;
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterHedgePlugin)
