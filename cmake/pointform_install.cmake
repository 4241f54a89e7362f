# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors

include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

get_property(pf_targets GLOBAL PROPERTY PF_MODULE_TARGETS)
install(TARGETS ${pf_targets} pointform pointform_warnings EXPORT pointformTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY include/pointform DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT pointformTargets NAMESPACE pointform:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pointform)
configure_package_config_file(cmake/pointformConfig.cmake.in
  ${PROJECT_BINARY_DIR}/pointformConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pointform)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/pointformConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/pointformConfig.cmake ${PROJECT_BINARY_DIR}/pointformConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pointform)
