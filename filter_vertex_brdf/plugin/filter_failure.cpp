#include "filter_failure.h"

#include <exception>
#include <new>

#include "core/base/errors.h"
#include "filter_parameters.h"

namespace vbrdf_plugin {

std::string apply_filter(const PluginFilter &filter, FilterRun &run) {
  std::string failure;
  try {
    filter.apply(run);
    return std::string();
  } catch (const vbrdf::InputError &e) {
    failure = e.what();
  } catch (const vbrdf::ProcessingError &e) {
    failure = std::string("processing failed: ") + e.what();
  } catch (const std::bad_alloc &) {
    failure = "out of memory: lower 'memoryBudgetMB' or simplify the mesh";
  } catch (const std::exception &e) {
    failure = std::string("unexpected error: ") + e.what();
  }
  // The labels of the filter's own declaration: a script's parameters (meshlabserver's .mlx,
  // PyMeshLab's arguments) come without them.
  RichParameterList declared;
  filter.initParameters(run.document, declared);
  return with_labels(failure, declared);
}

} // namespace vbrdf_plugin
