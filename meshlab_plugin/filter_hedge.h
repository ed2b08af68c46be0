// The MeshLab 2020.09 glue: one MeshFilterInterface filter per catalogue operation. All that
// is specific to this plugin API lives here and in filter_hedge.cpp; the 2021.05+ FilterPlugin
// glue (2022.02, 2025.07) is filter_plugin_hedge.{h,cpp}, and both share hedge_filters and
// cmesh_soup.
#pragma once

#include <common/interfaces.h>

class FilterHedgePlugin : public QObject, public MeshFilterInterface {
  Q_OBJECT
  MESHLAB_PLUGIN_IID_EXPORTER(MESH_FILTER_INTERFACE_IID)
  Q_INTERFACES(MeshFilterInterface)

 public:
  FilterHedgePlugin();

  QString pluginName() const override;
  QString filterName(FilterIDType filter) const override;
  QString filterInfo(FilterIDType filter) const override;
  FilterClass getClass(QAction* action) override;
  FILTER_ARITY filterArity(QAction* action) const override;
  int getPreConditions(QAction* action) const override;
  int postCondition(QAction* action) const override;
  void initParameterSet(QAction* action, MeshModel& model, RichParameterList& parameters) override;
  bool applyFilter(QAction* action, MeshDocument& document, const RichParameterList& parameters,
                   vcg::CallBackPos* cb) override;
};
