// Scene text the texture and map tests build their files from (texture_import_test,
// normal_map_import_test, texture_render_test, normal_map_render_test): one copy of each.
#pragma once

#include <string>

namespace pathex::test {

// The head of an importer test's pbrt-v4 file (a camera and a point light) and Mitsuba 3 file.
inline const std::string kPbrtHead =
    "LookAt 0 1 3  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\nWorldBegin\nLightSource \"point\"\n";
inline const std::string kXmlHead = "<scene version=\"3.0.0\">\n<emitter type=\"point\"/>\n";

// A render test's pbrt-v4 head: a camera at z = −3 looking at the origin, fov 30 (it sees
// [−0.80, 0.80]² of the plane z = 0), 8 × 8 pixels.
inline const std::string kRenderHead =
    "LookAt 0 0 -3  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\nFilm \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n"
    "WorldBegin\n";
// The square [−2, 2]² of the plane z = 0, uv from 0 to 1 across it (dp/du = (4, 0, 0), dp/dv = (0, 4, 0)).
inline const std::string kWall =
    "Shape \"trianglemesh\" \"point3 P\" [-2 -2 0  2 -2 0  2 2 0  -2 2 0] \"integer indices\" [0 1 2  0 2 3] "
    "\"point2 uv\" [0 0  1 0  1 1  0 1]";

}  // namespace pathex::test
