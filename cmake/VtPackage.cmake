# The runtime side as an installable package: the libraries an engine links, its public headers
# under one vtbake/ prefix, exported CMake targets, a pkg-config file, and the vtbake command with
# its man page. Components: `runtime` (what an engine needs) and `tools` (the command).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(VT_PACKAGE_DIR "${CMAKE_CURRENT_LIST_DIR}")
# Public headers are staged here as they are installed, so an add_subdirectory consumer includes
# <vtbake/...> exactly as an installed one does.
set(VT_STAGED_INCLUDE_DIR "${PROJECT_BINARY_DIR}/include")

# vt_runtime_library(TARGET): names, versions and exports a runtime-side library (vt_add_library
# RUNTIME calls it). vt_format becomes libvtbake_format.so.0.1 / libvtbake_format.a and
# vtbake::format, for installed and add_subdirectory consumers alike.
function(vt_runtime_library name)
  string(REGEX REPLACE "^vt_" "" short "${name}")
  get_target_property(type ${name} TYPE)
  if(NOT type STREQUAL "INTERFACE_LIBRARY")
    # 0.x: any minor release may break the ABI, so the SONAME carries the minor version.
    set_target_properties(${name} PROPERTIES OUTPUT_NAME vtbake_${short}
                                             VERSION ${PROJECT_VERSION}
                                             SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
  endif()
  set_target_properties(${name} PROPERTIES EXPORT_NAME ${short})
  add_library(vtbake::${short} ALIAS ${name})
  set_property(GLOBAL APPEND PROPERTY VT_RUNTIME_LIBRARIES ${name})
endfunction()

# vt_public_headers(TARGET target DIR folder HEADERS names...): marks headers of the runtime side
# as public. They are staged (and installed) as <vtbake/DIR/NAME>, their own includes of other
# public headers rewritten to the prefixed form; every header a public header includes must be
# public too (checked by vt_install_package).
function(vt_public_headers)
  cmake_parse_arguments(ARG "" "TARGET;DIR" "HEADERS" ${ARGN})
  set(outputs)
  foreach(header IN LISTS ARG_HEADERS)
    set(src "${PROJECT_SOURCE_DIR}/${ARG_DIR}/${header}")
    set(out "${VT_STAGED_INCLUDE_DIR}/vtbake/${ARG_DIR}/${header}")
    add_custom_command(OUTPUT "${out}"
                       COMMAND ${CMAKE_COMMAND} -DIN=${src} -DOUT=${out} -P
                               ${VT_PACKAGE_DIR}/StagePublicHeader.cmake
                       DEPENDS "${src}" "${VT_PACKAGE_DIR}/StagePublicHeader.cmake"
                       COMMENT "Staging public header vtbake/${ARG_DIR}/${header}" VERBATIM)
    list(APPEND outputs "${out}")
    file(STRINGS "${src}" includes REGEX "^#include \"(common|codec|format|runtime)/")
    foreach(line IN LISTS includes)
      string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" included "${line}")
      set_property(GLOBAL APPEND PROPERTY VT_PUBLIC_INCLUDES "${ARG_DIR}/${header}>${included}")
    endforeach()
    set_property(GLOBAL APPEND PROPERTY VT_PUBLIC_HEADERS "${ARG_DIR}/${header}")
  endforeach()
  add_custom_target(${ARG_TARGET}_${ARG_DIR}_headers DEPENDS ${outputs})
  add_dependencies(${ARG_TARGET} ${ARG_TARGET}_${ARG_DIR}_headers)
  install(FILES ${outputs} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vtbake/${ARG_DIR}
          COMPONENT runtime)
endfunction()

function(vt_check_public_header_closure)
  get_property(headers GLOBAL PROPERTY VT_PUBLIC_HEADERS)
  get_property(edges GLOBAL PROPERTY VT_PUBLIC_INCLUDES)
  foreach(edge IN LISTS edges)
    string(REPLACE ">" ";" pair "${edge}")
    list(GET pair 0 from)
    list(GET pair 1 to)
    if(NOT to IN_LIST headers)
      message(FATAL_ERROR "public header ${from} includes ${to}, which is not public: list it in "
                          "a vt_public_headers call or drop the include")
    endif()
  endforeach()
endfunction()

# The C API targets: the same libraries without the C++20 requirement (LINK_ONLY drops usage
# requirements), so C99 and C++17 code can link them.
function(vt_add_c_api_target name library)
  add_library(${name} INTERFACE)
  target_link_libraries(${name} INTERFACE $<LINK_ONLY:${library}>)
  target_include_directories(${name} INTERFACE $<BUILD_INTERFACE:${VT_STAGED_INCLUDE_DIR}>
                                               $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  string(REGEX REPLACE "^vt_" "" short "${name}")
  set_target_properties(${name} PROPERTIES EXPORT_NAME ${short})
  add_library(vtbake::${short} ALIAS ${name})
endfunction()

function(vt_install_pkg_config)
  # Relocatable: the prefix is found from the .pc file's own place (cmake --install --prefix).
  file(RELATIVE_PATH pc_to_prefix "/p/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/p")
  set(VT_PC_PREFIX "\${pcfiledir}/${pc_to_prefix}")
  string(REGEX REPLACE "/$" "" VT_PC_PREFIX "${VT_PC_PREFIX}")
  if(BUILD_SHARED_LIBS)
    set(VT_PC_REQUIRES "")
    set(VT_PC_REQUIRES_PRIVATE "libzstd libxxhash")
    set(VT_PC_LIBS_EXTRA "")
  else()
    # Static archives: a plain `pkg-config --libs` must give everything the link needs, the C++
    # standard library included (a C program links with cc).
    set(VT_PC_REQUIRES "libzstd libxxhash")
    set(VT_PC_REQUIRES_PRIVATE "")
    set(VT_PC_LIBS_EXTRA "-lstdc++ -lm -pthread")
  endif()
  configure_file("${VT_PACKAGE_DIR}/vtbake-runtime.pc.in"
                 "${PROJECT_BINARY_DIR}/vtbake-runtime.pc" @ONLY)
  install(FILES "${PROJECT_BINARY_DIR}/vtbake-runtime.pc"
          DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT runtime)
endfunction()

# The vtbake command and its man page (help2man over `vtbake --help`; skipped with a warning
# when help2man is missing, scripts/setup.sh installs it).
function(vt_install_tools)
  install(TARGETS vtbake RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT tools)
  find_program(HELP2MAN help2man)
  if(NOT HELP2MAN)
    message(WARNING "help2man not found: no man page for vtbake (scripts/setup.sh installs it)")
    return()
  endif()
  set(man "${PROJECT_BINARY_DIR}/vtbake.1")
  add_custom_command(OUTPUT "${man}"
                     COMMAND ${HELP2MAN} --no-info --no-discard-stderr
                             --version-string=${PROJECT_VERSION}
                             "--name=offline virtual-texture baker" -o ${man} $<TARGET_FILE:vtbake>
                     DEPENDS vtbake COMMENT "Generating the vtbake man page" VERBATIM)
  add_custom_target(vtbake_man ALL DEPENDS "${man}")
  install(FILES "${man}" DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT tools)
endfunction()

# Install rules and exports; called once at the end of the root CMakeLists.txt.
function(vt_install_package)
  vt_check_public_header_closure()
  vt_add_c_api_target(vt_format_c vt_format)
  vt_add_c_api_target(vt_runtime_c vt_runtime)
  get_property(libraries GLOBAL PROPERTY VT_RUNTIME_LIBRARIES)
  install(TARGETS vt_common ${libraries} vt_format_c vt_runtime_c EXPORT vtbakeTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
  set(cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/vtbake)
  install(EXPORT vtbakeTargets NAMESPACE vtbake:: DESTINATION ${cmake_dir} COMPONENT runtime)
  configure_package_config_file("${VT_PACKAGE_DIR}/vtbakeConfig.cmake.in"
                                "${PROJECT_BINARY_DIR}/vtbakeConfig.cmake"
                                INSTALL_DESTINATION ${cmake_dir})
  # 0.x: a minor release may break the API, so only the same minor version is compatible.
  write_basic_package_version_file("${PROJECT_BINARY_DIR}/vtbakeConfigVersion.cmake"
                                   COMPATIBILITY SameMinorVersion)
  install(FILES "${PROJECT_BINARY_DIR}/vtbakeConfig.cmake"
                "${PROJECT_BINARY_DIR}/vtbakeConfigVersion.cmake" "${VT_PACKAGE_DIR}/Findxxhash.cmake"
          DESTINATION ${cmake_dir} COMPONENT runtime)
  vt_install_pkg_config()
  install(FILES README.md docs/FORMAT.md docs/RUNTIME.md DESTINATION ${CMAKE_INSTALL_DOCDIR}
          COMPONENT runtime OPTIONAL)
  if(TARGET vtbake)
    vt_install_tools()
    install(FILES docs/JSON.md docs/ARCHITECTURE.md DESTINATION ${CMAKE_INSTALL_DOCDIR}
            COMPONENT tools OPTIONAL)
  endif()
endfunction()
