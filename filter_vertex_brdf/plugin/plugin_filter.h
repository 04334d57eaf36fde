#pragma once
// One filter of the plugin. The plugin class (filter_vertex_brdf_plugin.h) only registers the
// filters and dispatches to them; each filter lives in its own small file and implements this.
// Adding a filter: write a class derived from PluginFilter and append it in make_plugin_filters
// (plugin_filters.h).
#include <functional>
#include <string>

#include "meshlab_host.h"

namespace vbrdf_plugin {

// What a filter gets for one application. Errors are reported by throwing vbrdf::InputError /
// vbrdf::ProcessingError; the plugin turns them into MeshLab's errorMessage and log.
struct FilterRun {
  MeshDocument &document;
  const RichParameterList &params;
  vcg::CallBackPos *progress;          // may be null
  MLPluginGLContext *gl_context;       // may be null (no view): filters fall back to the CPU
  std::function<void(GLLogStream::Levels, const std::string &)> log;
  // Numbers the host hands back to scripts (PyMeshLab's output dictionary); empty when it has none.
  std::function<void(const std::string &, double)> figure;
};

class PluginFilter {
public:
  virtual ~PluginFilter() = default;
  // Menu entry and .mlx name: never change it once released (scripts refer to it).
  virtual QString name() const = 0;
  virtual QString info() const = 0;  // HTML shown on top of the parameter dialog
  virtual host::FilterInterface::FilterClass filterClass() const = 0;
  virtual host::FilterArity arity() const { return host::FilterInterface::SINGLE_MESH; }
  virtual int requirements() const { return MeshModel::MM_NONE; }
  virtual int preConditions() const { return MeshModel::MM_NONE; }
  virtual int postConditions() const = 0;
  virtual void initParameters(const MeshDocument &document, RichParameterList &params) const = 0;
  virtual void apply(FilterRun &run) const = 0;
};

} // namespace vbrdf_plugin
