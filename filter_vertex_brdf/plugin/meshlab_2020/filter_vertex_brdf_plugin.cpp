#include "filter_vertex_brdf_plugin.h"

#include <string>

#include "filter_failure.h"
#include "plugin_filters.h"

using vbrdf_plugin::PluginFilter;

FilterVertexBrdfPlugin::FilterVertexBrdfPlugin() : filters_(vbrdf_plugin::make_plugin_filters()) {

  for (size_t id = 0; id < filters_.size(); ++id) {
    typeList << FilterIDType(id);
    actionList << new QAction(filters_[id]->name(), this);
  }
}

FilterVertexBrdfPlugin::~FilterVertexBrdfPlugin() = default;

QString FilterVertexBrdfPlugin::pluginName() const { return "FilterVertexBrdf"; }

QString FilterVertexBrdfPlugin::filterName(FilterIDType id) const {
  return (id >= 0 && size_t(id) < filters_.size()) ? filters_[id]->name() : QString();
}

QString FilterVertexBrdfPlugin::filterInfo(FilterIDType id) const {
  return (id >= 0 && size_t(id) < filters_.size()) ? filters_[id]->info() : QString();
}

const PluginFilter &FilterVertexBrdfPlugin::filterOf(QAction *action) const {
  return *filters_.at(size_t(ID(action)));
}

MeshFilterInterface::FilterClass FilterVertexBrdfPlugin::getClass(QAction *action) {
  return filterOf(action).filterClass();
}

MeshFilterInterface::FILTER_ARITY FilterVertexBrdfPlugin::filterArity(QAction *action) const {
  return filterOf(action).arity();
}

int FilterVertexBrdfPlugin::getRequirements(QAction *action) { return filterOf(action).requirements(); }

int FilterVertexBrdfPlugin::getPreConditions(QAction *action) const { return filterOf(action).preConditions(); }

int FilterVertexBrdfPlugin::postCondition(QAction *action) const { return filterOf(action).postConditions(); }

void FilterVertexBrdfPlugin::initParameterSet(QAction *action, MeshDocument &md, RichParameterList &params) {
  // Never dereference md.mm() here: meshlabserver's -d dump calls this on an empty document.
  filterOf(action).initParameters(md, params);
}

bool FilterVertexBrdfPlugin::applyFilter(QAction *action, MeshDocument &md, const RichParameterList &params,
                                         vcg::CallBackPos *cb) {
  const PluginFilter &filter = filterOf(action);
  errorMessage.clear();
  vbrdf_plugin::FilterRun run{md, params, cb, glContext,
                              [this](GLLogStream::Levels level, const std::string &line) { Log(level, line); },
                              {}};
  const std::string failure = vbrdf_plugin::apply_filter(filter, run);
  if (failure.empty()) return true;
  errorMessage = QString::fromStdString(failure);
  // meshlabserver never prints errorMsg(), only the log: put the reason there too so that
  // headless runs say why they failed (the GUI shows errorMessage in its failure dialog).
  Log(GLLogStream::WARNING, filter.name().toStdString() + " failed: " + failure);
  return false;
}
