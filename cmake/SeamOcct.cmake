# OpenCASCADE toolkits for STEP/IGES (Debian: libocct-data-exchange-dev, libocct-modeling-algorithms-dev,
# libocct-modeling-data-dev, libocct-foundation-dev). Found library by library: Debian's OpenCASCADEConfig.cmake
# requires every OCCT package (visualization, Draw, ...) to be installed, which seam does not need.
find_path(OCCT_INCLUDE_DIR Standard_Version.hxx PATH_SUFFIXES opencascade REQUIRED)
set(SEAM_OCCT_TOOLKITS
  TKernel TKMath TKG2d TKG3d TKGeomBase TKBRep TKGeomAlgo TKTopAlgo TKPrim TKShHealing TKBO TKBool TKMesh
  TKXSBase TKSTEPBase TKSTEPAttr TKSTEP209 TKSTEP TKIGES
  TKCDF TKLCAF TKCAF TKXCAF TKXDESTEP TKXDEIGES)  # XDE: names, colours and layers kept by convert and heal
add_library(seam_occt_toolkits INTERFACE)
target_include_directories(seam_occt_toolkits SYSTEM INTERFACE ${OCCT_INCLUDE_DIR})
foreach(tk IN LISTS SEAM_OCCT_TOOLKITS)
  find_library(OCCT_${tk}_LIBRARY ${tk} REQUIRED)
  target_link_libraries(seam_occt_toolkits INTERFACE ${OCCT_${tk}_LIBRARY})
endforeach()
