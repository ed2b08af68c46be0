// The MeshLab 2021.05+ glue (FilterPlugin: 2022.02, 2025.07): one filter per catalogue
// operation. The 2020.09 MeshFilterInterface glue is filter_hedge.{h,cpp}; both hand the work to
// hedge_filters (names, parameters, the run) and cmesh_soup (the mesh translation).
#pragma once

#include <common/plugins/interfaces/filter_plugin.h>

class FilterHedgePlugin : public QObject, public FilterPlugin {
  Q_OBJECT
  MESHLAB_PLUGIN_IID_EXPORTER(FILTER_PLUGIN_IID)
  Q_INTERFACES(FilterPlugin)

 public:
  FilterHedgePlugin();

  QString pluginName() const override;
  QString vendor() const override;
  QString filterName(ActionIDType filter) const override;
  QString pythonFilterName(ActionIDType filter) const override;
  QString filterInfo(ActionIDType filter) const override;
  FilterClass getClass(const QAction* action) const override;
  FilterArity filterArity(const QAction* action) const override;
  int getPreConditions(const QAction* action) const override;
  int postCondition(const QAction* action) const override;
  RichParameterList initParameterList(const QAction* action, const MeshModel& model) override;
  std::map<std::string, QVariant> applyFilter(const QAction* action, const RichParameterList& parameters,
                                              MeshDocument& document, unsigned int& postConditionMask,
                                              vcg::CallBackPos* cb) override;
};
