"""The package files :func:`stewart.io.capi.export` writes beside the model's C: a CMake project
and package, and a pkg-config file, so that a C or C++ program links the model without Python.

In the exported directory ``DIR``:

- ``CMakeLists.txt`` -- the installable project: ``cmake -S DIR -B build``, ``cmake --build
  build``, ``cmake --install build --prefix PREFIX`` installs ``libstewart.a``, ``libstewart.so``
  (versioned), the headers in ``include/stewart/``, the CMake package in
  ``lib/cmake/stewart/`` and ``lib/pkgconfig/stewart.pc``;
- ``stewart.cmake`` -- the library's targets, which both the project and the source-tree
  package include: the model's units compiled once (position-independent, with the model's
  rounding flags and ``-O3`` (``STEWART_OPTIMIZE``), for the CPU that builds: ``STEWART_MARCH``) into a static and a
  shared library, each named ``stewart``;
- ``stewartConfig.cmake`` and ``stewartConfigVersion.cmake`` -- the package found in the source
  tree: ``find_package(stewart CONFIG REQUIRED)`` with ``stewart_DIR=DIR`` compiles the library
  inside the consumer's build (with the consumer's C compiler);
- ``stewart.pc.in`` -- the pkg-config file the install writes (``stewart.pc``);
- ``stewart.map`` -- the shared library's version script: the functions of ``stewart_model.h``
  global, every other symbol local.

Either way the consumer gets ``stewart::stewart`` (the static library) and ``stewart::shared``,
whose include path holds ``stewart_model.h`` and ``stewart_platform_params.h``, and the
variable ``stewart_ROUNDING_FLAGS`` (``STEWART_ROUNDING_FLAGS`` of the header, for a consumer's
own code that must round as the model does).
"""

from __future__ import annotations

import re

__all__ = ["package_files", "public_functions", "PROJECT", "TARGETS", "CONFIG", "CONFIG_VERSION", "PKG_CONFIG",
           "VERSION_SCRIPT"]

PROJECT = "CMakeLists.txt"
TARGETS = "stewart.cmake"
CONFIG = "stewartConfig.cmake"
CONFIG_VERSION = "stewartConfigVersion.cmake"
PKG_CONFIG = "stewart.pc.in"
VERSION_SCRIPT = "stewart.map"

_PROJECT = """\
# CMakeLists.txt -- the Stewart platform model @VERSION@ as a C library (written by `stewart c-export`).
#
#   cmake -S DIR -B build -DCMAKE_BUILD_TYPE=Release
#   cmake --build build
#   cmake --install build --prefix PREFIX
#
# installs libstewart.a and libstewart.so.@VERSION@, the headers in PREFIX/include/stewart, the
# CMake package (find_package(stewart CONFIG REQUIRED) with CMAKE_PREFIX_PATH=PREFIX:
# stewart::stewart, the static library, and stewart::shared) and PREFIX/lib/pkgconfig/stewart.pc.
# Without installing, find_package(stewart CONFIG REQUIRED) with stewart_DIR=DIR compiles the
# library in the consumer's build (stewartConfig.cmake).
cmake_minimum_required(VERSION 3.16)
project(stewart VERSION @VERSION@ LANGUAGES C)

include(GNUInstallDirs)
include(${CMAKE_CURRENT_SOURCE_DIR}/stewart.cmake)

set(STEWART_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/stewart)
install(TARGETS stewart_static stewart_shared EXPORT stewartTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/stewart)
install(FILES ${STEWART_PUBLIC_HEADERS} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/stewart)
install(EXPORT stewartTargets NAMESPACE stewart:: DESTINATION ${STEWART_INSTALL_CMAKEDIR})
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/stewartConfig.cmake
     "# The installed Stewart platform model @VERSION@: stewart::stewart (static), stewart::shared.\\n"
     "include(\\"\\${CMAKE_CURRENT_LIST_DIR}/stewartTargets.cmake\\")\\n"
     "set(stewart_ROUNDING_FLAGS ${STEWART_ROUNDING_FLAGS})\\n")
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/stewartConfig.cmake ${CMAKE_CURRENT_SOURCE_DIR}/stewartConfigVersion.cmake
        DESTINATION ${STEWART_INSTALL_CMAKEDIR})
# stewart.pc finds the prefix from where it lies (pkg-config's pcfiledir): relocatable.
string(REGEX REPLACE "[^/]+" ".." STEWART_PC_PREFIX "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
configure_file(${CMAKE_CURRENT_SOURCE_DIR}/stewart.pc.in ${CMAKE_CURRENT_BINARY_DIR}/stewart.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/stewart.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
"""

_TARGETS = """\
# stewart.cmake -- the targets of the Stewart platform model @VERSION@ (written by `stewart c-export`;
# included by CMakeLists.txt and by stewartConfig.cmake).
#
# stewart_static and stewart_shared (both named stewart: libstewart.a, libstewart.so), aliased
# stewart::stewart and stewart::shared, compiled from the model's units once. The units are
# compiled with the model's rounding flags (STEWART_ROUNDING_FLAGS of stewart_model.h: every
# operation as written, none fused) and STEWART_OPTIMIZE (-O3), and for STEWART_MARCH: by default, on x86-64, the
# best of the levels of setup.py's copies (x86-64-v4, x86-64-v3, x86-64) that this CPU runs;
# elsewhere the compiler's default target. The results are the same bits on every level;
# -DSTEWART_MARCH=x86-64 builds a library for every x86-64 CPU, -DSTEWART_MARCH=none
# leaves the target to the compiler. The shared library exports the functions of
# stewart_model.h only (stewart.map).
if(TARGET stewart_static)
  return()
endif()
enable_language(C)
set(STEWART_VERSION @VERSION@)
set(_stewart_dir ${CMAKE_CURRENT_LIST_DIR})

file(STRINGS ${_stewart_dir}/stewart_model.h _stewart_line REGEX "^#define STEWART_ROUNDING_FLAGS ")
string(REGEX REPLACE "^#define STEWART_ROUNDING_FLAGS \\"(.*)\\"$" "\\\\1" _stewart_flags "${_stewart_line}")
separate_arguments(STEWART_ROUNDING_FLAGS UNIX_COMMAND "${_stewart_flags}")
set(stewart_ROUNDING_FLAGS ${STEWART_ROUNDING_FLAGS})

set(STEWART_MARCH "" CACHE STRING "-march of the model's units (empty: the best x86-64 level this CPU runs; none: the compiler's default)")
set(_stewart_march "${STEWART_MARCH}")
if(_stewart_march STREQUAL "" AND CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$" AND NOT CMAKE_CROSSCOMPILING)
  include(CheckCSourceRuns)
  set(_stewart_march x86-64)
  foreach(_stewart_level x86-64-v4 x86-64-v3)
    string(REPLACE "-" "_" _stewart_var "STEWART_RUNS_${_stewart_level}")
    set(CMAKE_REQUIRED_FLAGS "-march=${_stewart_level}")
    set(CMAKE_REQUIRED_QUIET ON)
    check_c_source_runs("int main(void) { __builtin_cpu_init(); return !__builtin_cpu_supports(\\"${_stewart_level}\\"); }"
                        ${_stewart_var})
    unset(CMAKE_REQUIRED_FLAGS)
    unset(CMAKE_REQUIRED_QUIET)
    if(${_stewart_var})
      set(_stewart_march ${_stewart_level})
      break()
    endif()
  endforeach()
endif()
set(STEWART_OPTIMIZE -O3 CACHE STRING "the optimization of the model's units (the results are the same bits at every level)")
set(_stewart_target_flags)
if(NOT _stewart_march STREQUAL "" AND NOT _stewart_march STREQUAL "none")
  set(_stewart_target_flags -march=${_stewart_march})
endif()
set(STEWART_TARGET_FLAGS ${_stewart_target_flags})

file(GLOB _stewart_sources ${_stewart_dir}/stewart_model*.c)
set(STEWART_PUBLIC_HEADERS ${_stewart_dir}/stewart_model.h)
if(EXISTS ${_stewart_dir}/stewart_platform_params.h)
  list(APPEND STEWART_PUBLIC_HEADERS ${_stewart_dir}/stewart_platform_params.h)
endif()

add_library(stewart_objects OBJECT ${_stewart_sources})
set_target_properties(stewart_objects PROPERTIES POSITION_INDEPENDENT_CODE ON C_STANDARD 99 C_STANDARD_REQUIRED ON)
target_include_directories(stewart_objects PRIVATE ${_stewart_dir})
target_compile_options(stewart_objects PRIVATE ${STEWART_OPTIMIZE} ${STEWART_ROUNDING_FLAGS} ${_stewart_target_flags})

foreach(_stewart_kind static shared)
  string(TOUPPER ${_stewart_kind} _stewart_type)
  add_library(stewart_${_stewart_kind} ${_stewart_type} $<TARGET_OBJECTS:stewart_objects>)
  target_include_directories(stewart_${_stewart_kind} INTERFACE
                             $<BUILD_INTERFACE:${_stewart_dir}> $<INSTALL_INTERFACE:include/stewart>)
  target_link_libraries(stewart_${_stewart_kind} PUBLIC m)
  set_target_properties(stewart_${_stewart_kind} PROPERTIES OUTPUT_NAME stewart VERSION ${STEWART_VERSION})
endforeach()
set_target_properties(stewart_static PROPERTIES EXPORT_NAME stewart)
string(REGEX MATCH "^[0-9]+\\\\.[0-9]+" _stewart_soversion ${STEWART_VERSION})
set_target_properties(stewart_shared PROPERTIES EXPORT_NAME shared SOVERSION ${_stewart_soversion}
                      LINK_DEPENDS ${_stewart_dir}/stewart.map)
target_link_options(stewart_shared PRIVATE "LINKER:--version-script=${_stewart_dir}/stewart.map")
add_library(stewart::stewart ALIAS stewart_static)
add_library(stewart::shared ALIAS stewart_shared)
"""

_CONFIG = """\
# stewartConfig.cmake -- the Stewart platform model @VERSION@ found in the directory `stewart c-export`
# wrote: find_package(stewart CONFIG REQUIRED) with stewart_DIR (or CMAKE_PREFIX_PATH) at this
# directory compiles the library in the consumer's build and gives stewart::stewart (static)
# and stewart::shared, and stewart_ROUNDING_FLAGS (see stewart.cmake).
include(${CMAKE_CURRENT_LIST_DIR}/stewart.cmake)
"""

_CONFIG_VERSION = """\
# stewartConfigVersion.cmake -- the version of the Stewart platform model's package (written by
# `stewart c-export`): a request for @VERSION@ or an older version of the same major and minor
# version is compatible (0.x: of the same minor version).
set(PACKAGE_VERSION "@VERSION@")
string(REGEX MATCH "^[0-9]+\\\\.[0-9]+" _stewart_series "${PACKAGE_VERSION}")
string(REGEX MATCH "^[0-9]+\\\\.[0-9]+" _stewart_asked "${PACKAGE_FIND_VERSION}")
if(PACKAGE_FIND_VERSION VERSION_GREATER PACKAGE_VERSION OR NOT _stewart_asked STREQUAL _stewart_series)
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
else()
  set(PACKAGE_VERSION_COMPATIBLE TRUE)
  if(PACKAGE_FIND_VERSION STREQUAL PACKAGE_VERSION)
    set(PACKAGE_VERSION_EXACT TRUE)
  endif()
endif()
"""

_PKG_CONFIG = """\
# stewart.pc -- the Stewart platform model @VERSION@ for pkg-config (written by its CMake install).
prefix=${pcfiledir}/@STEWART_PC_PREFIX@
libdir=${prefix}/@CMAKE_INSTALL_LIBDIR@
includedir=${prefix}/@CMAKE_INSTALL_INCLUDEDIR@/stewart

Name: stewart
Description: The complete dynamic model of a 6-DOF Stewart platform, generated C
Version: @VERSION@
Cflags: -I${includedir}
Libs: -L${libdir} -lstewart
Libs.private: -lm
"""

#: A function declared in the header: a line that starts with its return type, not a macro
#: or a typedef.
_DECLARATION = re.compile(r"^(?!typedef\b)[A-Za-z_][\w \t]*?[\s*](stewart_\w+)\s*\(", re.MULTILINE)


def public_functions(header: str) -> list[str]:
    """The names of the functions ``header`` (the text of ``stewart_model.h``) declares, sorted."""
    return sorted(set(_DECLARATION.findall(header)))


def package_files(version: str, header: str) -> dict[str, str]:
    """{file name: text} of the package files for the model of ``header`` (the text of
    ``stewart_model.h``), at the package's ``version``."""
    functions = public_functions(header)
    if not functions:
        raise ValueError("stewart_model.h declares no stewart_* function")
    script = ("/* stewart.map -- the symbols libstewart.so exports: the functions of stewart_model.h. */\n"
              "{\n  global:\n"
              + "".join(f"    {name};\n" for name in functions) + "  local:\n    *;\n};\n")
    templates = {PROJECT: _PROJECT, TARGETS: _TARGETS, CONFIG: _CONFIG, CONFIG_VERSION: _CONFIG_VERSION,
                 PKG_CONFIG: _PKG_CONFIG}
    files = {name: text.replace("@VERSION@", version) for name, text in templates.items()}
    files[VERSION_SCRIPT] = script
    return files
