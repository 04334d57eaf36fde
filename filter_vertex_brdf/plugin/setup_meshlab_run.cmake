# Build-time script (cmake -P): a private meshlabserver that loads the built plugin.
#   RUN_DIR/meshlab/meshlabserver      copy of SYSTEM_SERVER (a symlink would resolve to /usr/bin
#                                      and load only the system plugins)
#   RUN_DIR/meshlab/meshlab            copy of SYSTEM_GUI when given and present (the GUI, for
#                                      tests/gui and trying the build without installing it)
#   RUN_DIR/meshlab/plugins/*.so       links to every system plugin, plus PLUGIN_FILE and
#                                      RENDER_PLUGIN_FILE (the render plugin; optional)
#   RUN_DIR/lib/<arch>/meshlab         link to SYSTEM_LIB_DIR: the binary's RUNPATH is
#                                      $ORIGIN/../lib/<arch>/meshlab
#   RUN_DIR/run_meshlabserver.sh       wrapper (from WRAPPER_TEMPLATE)
cmake_minimum_required(VERSION 3.16)  # IN_LIST
foreach(var RUN_DIR SYSTEM_SERVER SYSTEM_LIB_DIR PLUGIN_FILE WRAPPER_TEMPLATE)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "setup_meshlab_run.cmake: ${var} not set")
  endif()
endforeach()
if(NOT EXISTS "${SYSTEM_SERVER}")
  message(FATAL_ERROR "${SYSTEM_SERVER} not found: install Debian's meshlab package")
endif()

set(server_dir "${RUN_DIR}/meshlab")
set(plugin_dir "${server_dir}/plugins")
file(MAKE_DIRECTORY "${plugin_dir}")
file(COPY "${SYSTEM_SERVER}" DESTINATION "${server_dir}")
if(DEFINED SYSTEM_GUI AND EXISTS "${SYSTEM_GUI}")
  file(COPY "${SYSTEM_GUI}" DESTINATION "${server_dir}")
endif()

# Rebuild the links each time: system plugins may have changed.
file(GLOB old_links "${plugin_dir}/*")
if(old_links)
  file(REMOVE ${old_links})
endif()
set(our_files "${PLUGIN_FILE}")
if(DEFINED RENDER_PLUGIN_FILE AND NOT RENDER_PLUGIN_FILE STREQUAL "")
  list(APPEND our_files "${RENDER_PLUGIN_FILE}")
endif()
set(our_names "")
foreach(f IN LISTS our_files)
  get_filename_component(name "${f}" NAME)
  list(APPEND our_names "${name}")
endforeach()
file(GLOB system_plugins "${SYSTEM_LIB_DIR}/plugins/*.so")
foreach(p IN LISTS system_plugins)
  get_filename_component(name "${p}" NAME)
  if(NOT name IN_LIST our_names)  # an installed copy of ours must not shadow the build's
    file(CREATE_LINK "${p}" "${plugin_dir}/${name}" SYMBOLIC)
  endif()
endforeach()
foreach(f IN LISTS our_files)
  get_filename_component(name "${f}" NAME)
  file(CREATE_LINK "${f}" "${plugin_dir}/${name}" SYMBOLIC)
endforeach()

# Recreate the relative library path of the binary's RUNPATH.
get_filename_component(lib_parent "${SYSTEM_LIB_DIR}" DIRECTORY)   # /usr/lib/<arch>
get_filename_component(arch "${lib_parent}" NAME)
file(MAKE_DIRECTORY "${RUN_DIR}/lib/${arch}")
if(NOT EXISTS "${RUN_DIR}/lib/${arch}/meshlab")
  file(CREATE_LINK "${SYSTEM_LIB_DIR}" "${RUN_DIR}/lib/${arch}/meshlab" SYMBOLIC)
endif()

configure_file("${WRAPPER_TEMPLATE}" "${RUN_DIR}/run_meshlabserver.sh" @ONLY)
execute_process(COMMAND chmod 755 "${RUN_DIR}/run_meshlabserver.sh")
