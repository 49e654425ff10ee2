# The module graph, checked on the source's include lines (house style: data flows one way).
#
#   mesh/ ─► param/ ─► gimage/ ─► codec/ ─► morph/ ─► stream_viewer/
#                                                     └► wasm/ (the WASM decoder's C API; web/ is JS)
#                                   baselines/ (beside codec/)            tools/ wires them (not the viewer)
#
# Each module may include its own headers and those of the modules listed for it below, nothing else of
# geomip. Run at configure time (included from the top CMakeLists.txt) and as the CTest test
# `module_graph` (cmake -DGEOMIP_ROOT=... -P cmake/GeomipModuleGraph.cmake), so a new include that breaks a
# boundary fails both the configure and the test suite, naming the file, the line and the rule.
if(NOT GEOMIP_ROOT)
  if(PROJECT_SOURCE_DIR)
    set(GEOMIP_ROOT "${PROJECT_SOURCE_DIR}")
  else()
    get_filename_component(GEOMIP_ROOT "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
  endif()
endif()

set(_geomip_modules mesh param gimage codec baselines morph stream_viewer tools wasm)
set(_geomip_allowed_mesh mesh)
set(_geomip_allowed_param mesh param)
set(_geomip_allowed_gimage mesh param gimage)
set(_geomip_allowed_codec codec)
set(_geomip_allowed_baselines mesh codec baselines)
set(_geomip_allowed_morph codec morph)
set(_geomip_allowed_stream_viewer codec morph stream_viewer)
set(_geomip_allowed_tools mesh param gimage codec baselines morph tools)
set(_geomip_allowed_wasm codec morph wasm)

set(_geomip_violations "")
foreach(module IN LISTS _geomip_modules)
  file(GLOB _files "${GEOMIP_ROOT}/${module}/*.h" "${GEOMIP_ROOT}/${module}/*.cpp")
  foreach(file IN LISTS _files)
    file(STRINGS "${file}" _includes REGEX "^[ \t]*#[ \t]*include[ \t]+\"[a-z_]+/")
    foreach(line IN LISTS _includes)
      string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]+\"([a-z_]+)/.*" "\\1" _target "${line}")
      list(FIND _geomip_modules "${_target}" _is_module)
      if(_is_module EQUAL -1)
        continue()  # not a geomip module (e.g. "tests/...")
      endif()
      list(FIND _geomip_allowed_${module} "${_target}" _ok)
      if(_ok EQUAL -1)
        file(RELATIVE_PATH _rel "${GEOMIP_ROOT}" "${file}")
        string(STRIP "${line}" line)
        string(REPLACE ";" " " _allowed "${_geomip_allowed_${module}}")
        list(APPEND _geomip_violations
             "${_rel}: ${line} — ${module}/ may include only: ${_allowed}")
      endif()
    endforeach()
  endforeach()
endforeach()

if(_geomip_violations)
  list(JOIN _geomip_violations "\n  " _msg)
  message(FATAL_ERROR "module graph broken:\n  ${_msg}")
endif()
