# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors

# Warnings live in an INTERFACE target that every pointform target links PRIVATE.
add_library(pointform_warnings INTERFACE)
target_compile_options(pointform_warnings INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
     -Wcast-align -Wunused -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion
     -Wimplicit-fallthrough -Wno-missing-field-initializers>
     $<$<CXX_COMPILER_ID:GNU>:-Wno-restrict>)
if(PF_WERROR)
  target_compile_options(pointform_warnings INTERFACE $<$<CXX_COMPILER_ID:GNU,Clang>:-Werror>)
endif()

# pf_add_module(NAME SOURCES ... DEPENDS ...): one library target per module, pointform::NAME.
function(pf_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  add_library(pointform_${name} ${ARG_SOURCES})
  add_library(pointform::${name} ALIAS pointform_${name})
  set_target_properties(pointform_${name} PROPERTIES EXPORT_NAME ${name} POSITION_INDEPENDENT_CODE ON)
  target_compile_features(pointform_${name} PUBLIC cxx_std_20)
  target_include_directories(pointform_${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
  target_link_libraries(pointform_${name} PUBLIC ${ARG_DEPENDS} PRIVATE ${ARG_PRIVATE_DEPENDS} pointform_warnings)
  set_property(GLOBAL APPEND PROPERTY PF_MODULE_TARGETS pointform_${name})
endfunction()
