#pragma once
// The report's 3-D view: web/viewer.js bundled with three.js (cmake/SeamReportViewer.cmake generates the definition).

namespace seam::report::detail {

/// The minified script (three.js + the view), inlined into every HTML report; empty when the build had no
/// web/node_modules (the report then keeps its 2-D drawing only).
extern const char* const kViewerJs;

}  // namespace seam::report::detail
