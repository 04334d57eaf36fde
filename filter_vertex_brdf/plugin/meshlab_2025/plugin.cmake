# The plugin for MeshLab 2025.07 as PyMeshLab 2025.7.post1 carries it (included by
# plugin/CMakeLists.txt when VBRDF_MESHLAB is 2025.07; the libraries: filter_vertex_brdf/cmake/meshlab_2025.cmake).
# The same filters as the 2020.09 plugin, under this folder's host adapter. No render plugin:
# PyMeshLab loads filter and I/O plugins only.
file(GLOB VBRDF_PLUGIN_SOURCES CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/*.cpp" "${CMAKE_CURRENT_SOURCE_DIR}/*.h")
set(VBRDF_HOST_DIR "${CMAKE_CURRENT_SOURCE_DIR}/meshlab_2025")
# relight_attributes and photo_lights serve the 2020.09 render plugin only; the web export is
# the 2020.09 build's (meshlab_2025/host_filters.cpp says why).
list(REMOVE_ITEM VBRDF_PLUGIN_SOURCES
     "${CMAKE_CURRENT_SOURCE_DIR}/relight_attributes.cpp" "${CMAKE_CURRENT_SOURCE_DIR}/relight_attributes.h"
     "${CMAKE_CURRENT_SOURCE_DIR}/photo_lights.cpp" "${CMAKE_CURRENT_SOURCE_DIR}/photo_lights.h"
     "${CMAKE_CURRENT_SOURCE_DIR}/web_export_filter.cpp" "${CMAKE_CURRENT_SOURCE_DIR}/web_export_filter.h")
list(APPEND VBRDF_PLUGIN_SOURCES "${VBRDF_HOST_DIR}/host_filters.cpp")

set(vbrdf_plugin_warnings -Wall -Wextra -Wno-unused-parameter -Wno-deprecated-copy -Wno-class-memaccess
    -Wno-ignored-qualifiers -Wno-deprecated-declarations -Wno-misleading-indentation)

set(CMAKE_AUTOMOC ON)
add_library(filter_vertex_brdf MODULE ${VBRDF_PLUGIN_SOURCES}
            "${VBRDF_HOST_DIR}/filter_vertex_brdf_plugin.cpp" "${VBRDF_HOST_DIR}/filter_vertex_brdf_plugin.h"
            "${VBRDF_HOST_DIR}/meshlab_host.h")
target_include_directories(filter_vertex_brdf PRIVATE "${MESHLAB_SOURCE_DIR}/src" "${CMAKE_CURRENT_SOURCE_DIR}"
                           "${VBRDF_HOST_DIR}")
# As MeshLab's own CMake defines them for a double-precision 2025.07 build: the host compares the
# precision and refuses a plugin of another.
target_compile_definitions(filter_vertex_brdf PRIVATE MESHLAB_VERSION=${VBRDF_MESHLAB_VERSION_STRING})
target_link_libraries(filter_vertex_brdf PRIVATE vbrdf_core meshlab_common
    Qt5::Core Qt5::Gui Qt5::Widgets Qt5::OpenGL Qt5::Xml)
target_compile_options(filter_vertex_brdf PRIVATE ${vbrdf_plugin_warnings})
target_link_options(filter_vertex_brdf PRIVATE -Wl,--no-undefined -Wl,--exclude-libs,ALL)
# No RUNPATH: the host process has loaded the wheel's libraries before it loads the plugin.
set_target_properties(filter_vertex_brdf PROPERTIES CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON
                      SKIP_BUILD_RPATH ON)
