#pragma once
// MeshLab 2020.09 filter plugin "Vertex BRDF": registration and dispatch only. The filters are
// PluginFilter objects (one file each); the algorithms live in the core library (vbrdf_core).
#include <memory>
#include <vector>

#include <QObject>
#include <common/interfaces.h>

#include "plugin_filter.h"

class FilterVertexBrdfPlugin : public QObject, public MeshFilterInterface {
  Q_OBJECT
  MESHLAB_PLUGIN_IID_EXPORTER(MESH_FILTER_INTERFACE_IID)
  Q_INTERFACES(MeshFilterInterface)

public:
  FilterVertexBrdfPlugin();
  ~FilterVertexBrdfPlugin() override;

  QString pluginName() const override;
  QString filterName(FilterIDType id) const override;
  QString filterInfo(FilterIDType id) const override;
  FilterClass getClass(QAction *action) override;
  FILTER_ARITY filterArity(QAction *action) const override;
  int getRequirements(QAction *action) override;
  int getPreConditions(QAction *action) const override;
  int postCondition(QAction *action) const override;

  using MeshFilterInterface::initParameterSet;
  void initParameterSet(QAction *action, MeshDocument &md, RichParameterList &params) override;
  bool applyFilter(QAction *action, MeshDocument &md, const RichParameterList &params,
                   vcg::CallBackPos *cb) override;

private:
  const vbrdf_plugin::PluginFilter &filterOf(QAction *action) const;

  // Index = FilterIDType.
  std::vector<std::unique_ptr<vbrdf_plugin::PluginFilter>> filters_;
};
