// The QGIS mesh layer style of a UGRID file (see qgis_style.hpp): the XML QGIS 3.22 writes with
// saveNamedStyle (QgsMeshRendererSettings::writeXml), trimmed to the depth group's symbology.
#include "qgis_style.hpp"

#include <cstdio>
#include <sstream>

namespace globemesh::io {

namespace {

/// QGIS's "Blues" ramp (ColorBrewer): the position of each colour stop and its colour.
struct Stop {
    double at;
    int r, g, b;
};
constexpr Stop blues[] = {{0, 247, 251, 255},    {0.13, 222, 235, 247}, {0.26, 198, 219, 239},
                          {0.39, 158, 202, 225}, {0.52, 107, 174, 214}, {0.65, 66, 146, 198},
                          {0.78, 33, 113, 181},  {0.9, 8, 81, 156},     {1, 8, 48, 107}};

std::string rgb(const Stop &s) {
    return std::to_string(s.r) + "," + std::to_string(s.g) + "," + std::to_string(s.b) + ",255";
}

std::string hex(const Stop &s) {
    char text[8];
    std::snprintf(text, sizeof text, "#%02x%02x%02x", s.r, s.g, s.b);
    return text;
}

/// The gradient as QGIS stores it: the end colours and the inner stops "at;r,g,b,a:...".
std::string ramp_xml() {
    std::string stops;
    for (std::size_t i = 1; i + 1 < std::size(blues); ++i) {
        char at[16];
        std::snprintf(at, sizeof at, "%g;", blues[i].at);
        stops += std::string(i > 1 ? ":" : "") + at + rgb(blues[i]);
    }
    return "<colorramp name=\"[source]\" type=\"gradient\">"
           "<prop k=\"color1\" v=\"" +
           rgb(blues[0]) +
           "\"/>"
           "<prop k=\"color2\" v=\"" +
           rgb(blues[std::size(blues) - 1]) +
           "\"/>"
           "<prop k=\"discrete\" v=\"0\"/><prop k=\"rampType\" v=\"gradient\"/>"
           "<prop k=\"stops\" v=\"" +
           stops + "\"/></colorramp>\n";
}

} // namespace

std::string qgis_depth_style(int group, double max_depth) {
    std::ostringstream x;
    x.imbue(std::locale::classic());
    const std::string g = std::to_string(group);
    x << "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n"
      << qgis_style_mark << "\n"
      << "<qgis version=\"3.22\" styleCategories=\"Symbology\">\n"
      << " <mesh-renderer-settings>\n"
      << "  <active-dataset-group scalar=\"" << g << "\" vector=\"-1\"/>\n"
      << "  <scalar-settings group=\"" << g << "\" min-val=\"0\" max-val=\"" << max_depth
      << "\" opacity=\"1\" interpolation-method=\"none\">\n"
      << "   <colorrampshader colorRampType=\"INTERPOLATED\" classificationMode=\"1\" clip=\"0\" "
      << "minimumValue=\"0\" maximumValue=\"" << max_depth << "\" labelPrecision=\"0\">\n   "
      << ramp_xml();
    // The shader draws from its items (value, colour), the ramp only names where they came from.
    for (const Stop &s : blues) {
        const double v = s.at * max_depth;
        x << "    <item alpha=\"255\" value=\"" << v << "\" color=\"" << hex(s) << "\" label=\""
          << static_cast<long long>(v) << "\"/>\n";
    }
    x << "   </colorrampshader>\n  </scalar-settings>\n </mesh-renderer-settings>\n</qgis>\n";
    return x.str();
}

} // namespace globemesh::io
