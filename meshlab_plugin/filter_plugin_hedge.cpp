// MeshLab 2021.05+ filters from the catalogue. A failure throws MLException with hedge's
// message (MeshLab's GUI shows it in its failure box, pymeshlab raises it) after logging it;
// the document is untouched then (run_on_model writes nothing before the result is complete).
#include "filter_plugin_hedge.h"

#include <common/mlexception.h>

#include <exception>

#include "hedge/catalogue.h"
#include "hedge_filters.h"

static_assert(FilterPlugin::Cleaning == 0x00002 && FilterPlugin::Remeshing == 0x00004 &&
                  FilterPlugin::Smoothing == 0x00080 && FilterPlugin::Measure == 0x10000,
              "hedge_filters.cpp's FilterClass values");

FilterHedgePlugin::FilterHedgePlugin() {
  for (std::size_t i = 0; i < hedge::catalogue().size(); ++i) typeList.push_back(static_cast<ActionIDType>(i));
  for (ActionIDType id : types()) actionList.push_back(new QAction(filterName(id), this));
}

QString FilterHedgePlugin::pluginName() const { return "FilterHedge"; }

QString FilterHedgePlugin::vendor() const { return "hedge"; }

QString FilterHedgePlugin::filterName(ActionIDType filter) const {
  return hedge::meshlab::filter_name(hedge::meshlab::operation_at(filter));
}

QString FilterHedgePlugin::pythonFilterName(ActionIDType filter) const {
  return hedge::meshlab::python_filter_name(hedge::meshlab::operation_at(filter));
}

QString FilterHedgePlugin::filterInfo(ActionIDType filter) const {
  return hedge::meshlab::filter_info(hedge::meshlab::operation_at(filter));
}

FilterPlugin::FilterClass FilterHedgePlugin::getClass(const QAction* action) const {
  return static_cast<FilterClass>(hedge::meshlab::filter_class(hedge::meshlab::operation_at(ID(action))));
}

FilterPlugin::FilterArity FilterHedgePlugin::filterArity(const QAction*) const { return SINGLE_MESH; }

int FilterHedgePlugin::getPreConditions(const QAction* action) const {
  return hedge::meshlab::precondition_mask(hedge::meshlab::operation_at(ID(action)));
}

int FilterHedgePlugin::postCondition(const QAction* action) const {
  return hedge::meshlab::postcondition_mask(hedge::meshlab::operation_at(ID(action)));
}

RichParameterList FilterHedgePlugin::initParameterList(const QAction* action, const MeshModel&) {
  RichParameterList parameters;
  hedge::meshlab::add_parameters(hedge::meshlab::operation_at(ID(action)), parameters);
  return parameters;
}

std::map<std::string, QVariant> FilterHedgePlugin::applyFilter(const QAction* action,
                                                               const RichParameterList& parameters,
                                                               MeshDocument& document, unsigned int& postConditionMask,
                                                               vcg::CallBackPos* cb) {
  const hedge::Operation& op = hedge::meshlab::operation_at(ID(action));
  QString error;
  try {
    if (document.mm() == nullptr) throw hedge::Error(op.id + ": there is no mesh to work on");
    auto run = hedge::meshlab::run_on_model(op, hedge::meshlab::given_values(op, parameters), *document.mm(), cb);
    for (const QString& line : run.lines) log(GLLogStream::FILTER, line.toStdString());
    postConditionMask = static_cast<unsigned int>(hedge::meshlab::postcondition_mask(op));
    return std::move(run.report);
  } catch (const std::exception& e) {
    // Only MLException may leave a plugin: MeshLab catches that one (and bad_alloc) and nothing else.
    error = QString::fromUtf8(e.what());
  } catch (...) {
    error = "unknown error";
  }
  log(GLLogStream::WARNING, (hedge::meshlab::filter_name(op) + " failed: " + error).toStdString());
  throw MLException(error);
}
