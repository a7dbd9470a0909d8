#pragma once
// Internals shared by the report's source files (not installed, not for callers).

#include "isohex/quality/report.hpp"

#include <string>
#include <string_view>

namespace isohex::report_detail {

/// The viewer's binary blob (points, quads, sides, centroids, sj; little-endian 32-bit
/// words, in that order), zlib-compressed and base64-encoded for a <script> element.
std::string viewer_payload(const ViewerMesh& v);
/// The blob's layout and the facts the page states about the embedded data.
nlohmann::json viewer_info(const ViewerMesh& v);

/// Standard base64 (RFC 4648, with padding).
std::string base64_encode(std::string_view bytes);

/// The page's stylesheet, and the viewer's markup and script (report_viewer.cpp).
extern const char* const kReportCss;
extern const char* const kViewerHtml;
extern const char* const kViewerJs;

}  // namespace isohex::report_detail
