#pragma once
// The project with the cameras that registration corrected (registration/registration.h), written
// beside the fit's result: the input project is never modified.
#include <string>
#include <vector>

#include "inputs/camera.h"
#include "registration/registration.h"

namespace vbrdf {

// The .mlp text: `project_path`'s own document (meshes, transforms, every raster, hidden ones too)
// with each raster's <VCGCamera> replaced where its viewpoint was corrected (registration.corrected_for)
// and every file name made absolute (the new project may live in another folder). Without a
// readable project (a document never saved as .mlp): one mesh, `mesh_path`, and `rasters`.
// Throws ProcessingError when the project cannot be parsed again.
std::string registered_project_text(const std::string &project_path, const std::string &mesh_path,
                                    const std::vector<Raster> &rasters, const RegistrationResult &registration);

} // namespace vbrdf
