// MeshLab 2020.09 filters from the catalogue: names, Rich parameters, and applyFilter turning
// every failure into errorMessage plus a log line (meshlabserver prints only the log).
#include "filter_hedge.h"

#include <exception>

#include "hedge/catalogue.h"
#include "hedge_filters.h"

static_assert(MeshFilterInterface::Cleaning == 0x00002 && MeshFilterInterface::Remeshing == 0x00004 &&
                  MeshFilterInterface::Smoothing == 0x00080 && MeshFilterInterface::Measure == 0x10000,
              "hedge_filters.cpp's FilterClass values");

FilterHedgePlugin::FilterHedgePlugin() {
  for (std::size_t i = 0; i < hedge::catalogue().size(); ++i) typeList << static_cast<FilterIDType>(i);
  for (FilterIDType id : types()) actionList << new QAction(filterName(id), this);
}

QString FilterHedgePlugin::pluginName() const { return "FilterHedge"; }

QString FilterHedgePlugin::filterName(FilterIDType filter) const {
  return hedge::meshlab::filter_name(hedge::meshlab::operation_at(filter));
}

QString FilterHedgePlugin::filterInfo(FilterIDType filter) const {
  return hedge::meshlab::filter_info(hedge::meshlab::operation_at(filter));
}

MeshFilterInterface::FilterClass FilterHedgePlugin::getClass(QAction* action) {
  return static_cast<FilterClass>(hedge::meshlab::filter_class(hedge::meshlab::operation_at(ID(action))));
}

MeshFilterInterface::FILTER_ARITY FilterHedgePlugin::filterArity(QAction*) const { return SINGLE_MESH; }

int FilterHedgePlugin::getPreConditions(QAction* action) const {
  return hedge::meshlab::precondition_mask(hedge::meshlab::operation_at(ID(action)));
}

int FilterHedgePlugin::postCondition(QAction* action) const {
  return hedge::meshlab::postcondition_mask(hedge::meshlab::operation_at(ID(action)));
}

void FilterHedgePlugin::initParameterSet(QAction* action, MeshModel&, RichParameterList& parameters) {
  hedge::meshlab::add_parameters(hedge::meshlab::operation_at(ID(action)), parameters);
}

bool FilterHedgePlugin::applyFilter(QAction* action, MeshDocument& document, const RichParameterList& parameters,
                                    vcg::CallBackPos* cb) {
  const hedge::Operation& op = hedge::meshlab::operation_at(ID(action));
  errorMessage.clear();
  try {
    if (document.mm() == nullptr) throw hedge::Error(op.id + ": there is no mesh to work on");
    const auto run = hedge::meshlab::run_on_model(op, hedge::meshlab::given_values(op, parameters), *document.mm(), cb);
    for (const QString& line : run.lines) Log(GLLogStream::FILTER, line.toStdString());
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
