# The build for MeshLab 2025.07 as PyMeshLab 2025.7.post1 carries it (VBRDF_MESHLAB=2025.07):
# MeshLab's headers and vcglib from the 2025.07 source (.ci/setup-pymeshlab.sh fetches Debian's
# source package into build/deps2025/, never committed), linked against the wheel's own
# libmeshlab-common.so and its Qt, OpenMP and TBB, so that no shared library the wheel carries is
# loaded in a second version. OpenCV is linked statically, without imgcodecs (its GDAL -> libcurl
# chain clashes with the wheel's libnghttp2): photos are decoded with Qt's QImageReader
# (plugin/meshlab_2025/image_codec_qt.cpp). Why: docs/pymeshlab.md#image-decoding.

# MeshLab builds 2025.07 with C++17; its version string gets a "d" with double precision
# (src/common/CMakeLists.txt), and the host refuses a plugin of another precision.
set(CMAKE_CXX_STANDARD 17)
set(CMAKE_CXX_STANDARD_REQUIRED ON)
set(CMAKE_CXX_EXTENSIONS ON)
set(VBRDF_IMAGE_CODEC_SOURCE "${CMAKE_SOURCE_DIR}/filter_vertex_brdf/plugin/meshlab_2025/image_codec_qt.cpp")
set(VBRDF_MESHLAB_VERSION_STRING "2025.07d")
set(VBRDF_MESHLAB_SCALAR double)

set(MESHLAB_SOURCE_DIR "${CMAKE_SOURCE_DIR}/build/deps2025/meshlab-2025.07" CACHE PATH
    "MeshLab 2025.07 source tree (Debian's meshlab 2025.07 source package)")
if(NOT EXISTS "${MESHLAB_SOURCE_DIR}/src/common/plugins/interfaces/filter_plugin.h")
  message(FATAL_ERROR "MeshLab 2025.07 sources not found in ${MESHLAB_SOURCE_DIR}: run .ci/setup-pymeshlab.sh")
endif()
set(VCGLIB_DIR "${MESHLAB_SOURCE_DIR}/src/vcglib")

set(PYMESHLAB_DIR "" CACHE PATH "The installed pymeshlab package (site-packages/pymeshlab) whose lib/ the plugin links")
set(PYMESHLAB_LIB_DIR "${PYMESHLAB_DIR}/lib")
if(NOT EXISTS "${PYMESHLAB_LIB_DIR}/libmeshlab-common.so")
  message(FATAL_ERROR "libmeshlab-common.so not found in '${PYMESHLAB_LIB_DIR}': set PYMESHLAB_DIR to the pymeshlab "
                      "package folder of a virtual environment with pymeshlab==2025.7.post1 (.ci/setup-pymeshlab.sh makes one)")
endif()

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(OpenMP REQUIRED)
find_package(Qt5 REQUIRED COMPONENTS Core Gui Widgets OpenGL Xml)
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc mcc)

# Qt's headers and moc are Debian's (5.15.8); the binaries linked are the wheel's (5.15.2, the same
# ABI): --no-undefined then checks every symbol against the library that will be loaded.
foreach(module Core Gui Widgets OpenGL Xml)
  set(wheel_qt "${PYMESHLAB_LIB_DIR}/libQt5${module}.so.5")
  if(NOT EXISTS "${wheel_qt}")
    message(FATAL_ERROR "${wheel_qt} missing: not a pymeshlab 2025.7 wheel")
  endif()
  set_target_properties(Qt5::${module} PROPERTIES IMPORTED_LOCATION_RELEASE "${wheel_qt}"
                        IMPORTED_LOCATION "${wheel_qt}" IMPORTED_SONAME_RELEASE "libQt5${module}.so.5")
endforeach()
set_property(TARGET OpenMP::OpenMP_CXX PROPERTY INTERFACE_LINK_LIBRARIES "${PYMESHLAB_LIB_DIR}/libgomp.so.1")

add_library(meshlab_common SHARED IMPORTED GLOBAL)
set_target_properties(meshlab_common PROPERTIES IMPORTED_LOCATION "${PYMESHLAB_LIB_DIR}/libmeshlab-common.so")

# OpenCV's static archives (Debian's libopencv-dev and libopencv-contrib-dev ship them), in link
# order, then what they need: TBB from the wheel, the rest from Debian (not carried by the wheel).
set(OpenCV_LIBS "")
foreach(module mcc dnn calib3d features2d flann imgproc core)
  list(APPEND OpenCV_LIBS "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/libopencv_${module}.a")
endforeach()
find_library(VBRDF_PROTOBUF NAMES libprotobuf.so.32 protobuf REQUIRED)
find_library(VBRDF_LAPACK NAMES liblapack.so.3 lapack REQUIRED)
find_library(VBRDF_BLAS NAMES libblas.so.3 blas REQUIRED)
find_library(VBRDF_GLX NAMES libGLX.so.0 GLX REQUIRED)  # OpenCV core's OpenGL interop (glvnd)
find_package(ZLIB REQUIRED)
list(APPEND OpenCV_LIBS "${VBRDF_PROTOBUF}" "${PYMESHLAB_LIB_DIR}/libtbb.so.12" "${VBRDF_LAPACK}" "${VBRDF_BLAS}"
     "${VBRDF_GLX}" ZLIB::ZLIB ${CMAKE_DL_LIBS} pthread)
include_directories(SYSTEM ${OpenCV_INCLUDE_DIRS})
# The wheel's libraries find each other through their RUNPATH at run time; at link time ld needs this.
add_link_options("-Wl,-rpath-link,${PYMESHLAB_LIB_DIR}")

# vcglib's PLY reader/writer (the core's result PLYs).
add_library(vcg_ply STATIC "${VCGLIB_DIR}/wrap/ply/plylib.cpp")
target_include_directories(vcg_ply PUBLIC "${VCGLIB_DIR}")
target_compile_options(vcg_ply PRIVATE -w)
