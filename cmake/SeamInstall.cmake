include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
install(TARGETS seam EXPORT seamTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
if(SEAM_WITH_OCCT)
  install(TARGETS seam_occt seam_occt_toolkits EXPORT seamTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endif()
install(DIRECTORY include/seam DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/generated/seam/version.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/seam)
install(EXPORT seamTargets NAMESPACE seam:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/seam)
configure_package_config_file(cmake/seamConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/seamConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/seam)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/seamConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/seamConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/seamConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/seam)
