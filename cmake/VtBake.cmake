# vt_add_library(NAME [RUNTIME] PUBLIC_DEPS deps... PRIVATE_DEPS deps...)
# Every .cpp in DIR (not in subfolders) becomes part of NAME, so adding a capability is adding
# a file. A folder with no sources yet is an INTERFACE library so dependants still link.
# RUNTIME marks a library of the runtime side, the part an engine links: it follows
# BUILD_SHARED_LIBS (with SONAME and version), is installed as libvtbake_<name> and exported as
# vtbake::<name> (cmake/VtPackage.cmake). The baker's libraries stay static either way.
function(vt_add_library name)
  cmake_parse_arguments(ARG "RUNTIME" "" "PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/*.cpp" "${CMAKE_CURRENT_SOURCE_DIR}/*.c")
  if(sources)
    if(ARG_RUNTIME)
      add_library(${name} ${sources})
    else()
      add_library(${name} STATIC ${sources})
    endif()
    target_link_libraries(${name} PUBLIC vt_common ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  else()
    add_library(${name} INTERFACE)
    target_link_libraries(${name} INTERFACE vt_common ${ARG_PUBLIC_DEPS})
  endif()
  if(ARG_RUNTIME)
    vt_runtime_library(${name})
  endif()
endfunction()

# vt_add_test_suite(NAME DEPS...): one GoogleTest executable from every test_*.cpp in the folder.
function(vt_add_test_suite name)
  file(GLOB sources CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/test_*.cpp")
  if(NOT sources)
    return()
  endif()
  add_executable(${name} ${sources})
  target_link_libraries(${name} PRIVATE ${ARGN} GTest::gtest GTest::gtest_main Threads::Threads)
  target_compile_definitions(${name} PRIVATE VT_TEST_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)
endfunction()

# Removes include folders that do not exist from an imported target (broken package configs).
function(vt_drop_missing_include_dirs target)
  get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  set(kept)
  foreach(dir ${dirs})
    if(EXISTS "${dir}")
      list(APPEND kept "${dir}")
    endif()
  endforeach()
  set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${kept}")
endfunction()

# vt_add_areas(FOLDERS... TOOLS FOLDERS...): adds the runtime side's folders, and the TOOLS
# folders unless VTBAKE_RUNTIME_ONLY, for the sources and the tests alike.
function(vt_add_areas)
  cmake_parse_arguments(ARG "" "" "TOOLS" ${ARGN})
  set(areas ${ARG_UNPARSED_ARGUMENTS})
  if(NOT VTBAKE_RUNTIME_ONLY)
    list(APPEND areas ${ARG_TOOLS})
  endif()
  foreach(area IN LISTS areas)
    add_subdirectory(${area})
  endforeach()
endfunction()
