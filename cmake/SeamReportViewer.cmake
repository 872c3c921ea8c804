# The 3-D view of the HTML report (docs/report.md): web/viewer.js bundled with three.js by esbuild (pinned in
# web/package-lock.json, installed by `npm ci` in web/, which scripts/setup.sh runs) and embedded into the library
# as a string. Without node or web/node_modules the report keeps its 2-D drawing only (SEAM_REPORT_HAS_3D = 0).
set(SEAM_WEB_DIR ${PROJECT_SOURCE_DIR}/web)
set(SEAM_VIEWER_GEN ${PROJECT_BINARY_DIR}/generated/report)
file(MAKE_DIRECTORY ${SEAM_VIEWER_GEN})
find_program(SEAM_NODE_EXECUTABLE node)
if(SEAM_NODE_EXECUTABLE AND EXISTS ${SEAM_WEB_DIR}/node_modules/three/package.json
   AND EXISTS ${SEAM_WEB_DIR}/node_modules/esbuild/package.json)
  set(SEAM_REPORT_HAS_3D ON)
  add_custom_command(
    OUTPUT ${SEAM_VIEWER_GEN}/report_viewer.js
    COMMAND ${SEAM_NODE_EXECUTABLE} ${SEAM_WEB_DIR}/build.mjs ${SEAM_VIEWER_GEN}/report_viewer.js
    DEPENDS ${SEAM_WEB_DIR}/viewer.js ${SEAM_WEB_DIR}/build.mjs ${SEAM_WEB_DIR}/package-lock.json
    COMMENT "Bundling the report's 3-D view (three.js, esbuild)"
    VERBATIM)
  add_custom_command(
    OUTPUT ${SEAM_VIEWER_GEN}/report_viewer_js.cpp
    COMMAND ${CMAKE_COMMAND} -DIN=${SEAM_VIEWER_GEN}/report_viewer.js -DOUT=${SEAM_VIEWER_GEN}/report_viewer_js.cpp
            -DNAME=kViewerJs -P ${PROJECT_SOURCE_DIR}/cmake/EmbedText.cmake
    DEPENDS ${SEAM_VIEWER_GEN}/report_viewer.js ${PROJECT_SOURCE_DIR}/cmake/EmbedText.cmake
    VERBATIM)
  message(STATUS "seam: the report's 3-D view is bundled from web/ (three.js)")
else()
  set(SEAM_REPORT_HAS_3D OFF)
  file(WRITE ${SEAM_VIEWER_GEN}/empty.js "")
  execute_process(COMMAND ${CMAKE_COMMAND} -DIN=${SEAM_VIEWER_GEN}/empty.js
                          -DOUT=${SEAM_VIEWER_GEN}/report_viewer_js.cpp -DNAME=kViewerJs
                          -P ${PROJECT_SOURCE_DIR}/cmake/EmbedText.cmake)
  message(STATUS "seam: no node or web/node_modules (run `npm ci` in web/): the report has its 2-D drawing only")
endif()
target_sources(seam PRIVATE ${SEAM_VIEWER_GEN}/report_viewer_js.cpp)
if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  # One string of about 0.6 MB: longer than the 4095 characters ISO C++ requires compilers to support.
  set_source_files_properties(${SEAM_VIEWER_GEN}/report_viewer_js.cpp PROPERTIES COMPILE_OPTIONS -Wno-overlength-strings)
endif()
