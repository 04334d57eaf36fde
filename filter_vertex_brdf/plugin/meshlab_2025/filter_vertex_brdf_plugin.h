#pragma once
// MeshLab 2025.07 filter plugin "Vertex BRDF" (PyMeshLab 2025.7): registration and dispatch only,
// as the 2020.09 plugin (meshlab_2020/) does for MeshFilterInterface. What differs from 2020.09 is
// here and in meshlab_host.h: FilterPlugin's signatures, failures thrown as MLException, the
// figures returned to scripts, no GL context unless asked for, and the 'Project file' parameter
// (PyMeshLab leaves the document's path empty).
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <QObject>

#include "meshlab_host.h"
#include "plugin_filter.h"

class FilterVertexBrdfPlugin : public QObject, public FilterPlugin {
  Q_OBJECT
  MESHLAB_PLUGIN_IID_EXPORTER(FILTER_PLUGIN_IID)
  Q_INTERFACES(FilterPlugin)

public:
  FilterVertexBrdfPlugin();
  ~FilterVertexBrdfPlugin() override;

  QString pluginName() const override;
  QString filterName(ActionIDType id) const override;
  QString filterInfo(ActionIDType id) const override;
  FilterClass getClass(const QAction *action) const override;
  FilterArity filterArity(const QAction *action) const override;
  int getRequirements(const QAction *action) override;
  int getPreConditions(const QAction *action) const override;
  int postCondition(const QAction *action) const override;
  bool requiresGLContext(const QAction *action) const override;

  RichParameterList initParameterList(const QAction *action, const MeshDocument &md) override;
  std::map<std::string, QVariant> applyFilter(const QAction *action, const RichParameterList &params,
                                              MeshDocument &md, unsigned int &postConditionMask,
                                              vcg::CallBackPos *cb) override;

private:
  const vbrdf_plugin::PluginFilter &filterOf(const QAction *action) const;

  // Index = ActionIDType.
  std::vector<std::unique_ptr<vbrdf_plugin::PluginFilter>> filters_;
};
