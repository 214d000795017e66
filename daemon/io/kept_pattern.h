#pragma once

#include <cstdint>
#include <filesystem>

#include <opencv2/core/mat.hpp>

namespace everytouch::io {

// The code pattern of `seed` at `size` (0 or 1 per projector pixel, CV_8UC1) for a projector output of the
// daemon's own. Generating it takes a minute at 1920x1080, so once generated it is kept in `directory`
// (pattern-seedS-WxH.png, 255 on 1-bits) and read from there at the next start; a kept file that is not a
// pattern of that size is generated again and replaced. An empty directory keeps nothing.
cv::Mat keptPattern(std::uint64_t seed, cv::Size size, const std::filesystem::path& directory);

}  // namespace everytouch::io
