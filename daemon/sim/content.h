#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace everytouch::sim {

// Procedural display content (the image O the desktop draws).
enum class ContentKind {
    Grid35,  // the paper's Fig. 15(a): 35 circles with crosses at their centres
    Shapes,  // the paper's Fig. 17(a): a square, a right triangle and a circle to drag along
    Photo,  // photo-like: sky, hills, flowers, and skin-coloured faces (the hard case of colour segmentation)
    Ui,     // a desktop: windows, title bars, buttons, icons, text, a skin-coloured avatar
    Text,   // a page of text
    White,  // uniform white
    Gray,   // uniform mid-gray
};

std::optional<ContentKind> contentKindFromName(std::string_view name);
std::string contentKindName(ContentKind kind);

// Renders `kind` at the display's size as 8-bit BGR. `variant` picks one of many random layouts of the same
// kind (photo, ui, text), together with `seed`.
cv::Mat renderContent(ContentKind kind, cv::Size displaySize, std::uint64_t seed, int variant);

// Centres of the 35 circles of Grid35 (7 columns x 5 rows, row by row), display pixels: those of
// core/accuracy_grid.h, which everytouch-calib scores taps against.
std::vector<cv::Point2d> grid35Centres(cv::Size displaySize);

// Outlines of the Shapes content, each a closed polyline in display pixels, in the order square, right
// triangle, circle.
std::vector<std::vector<cv::Point2d>> dragShapes(cv::Size displaySize);

}  // namespace everytouch::sim
