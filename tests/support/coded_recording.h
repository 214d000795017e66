#pragma once

#include <cstdint>
#include <filesystem>

#include <opencv2/core/mat.hpp>

#include "io/rig_description.h"

namespace everytouch::test {

// A small rig (camera 162x122) for tests that need many frames quickly.
io::RigDescription smallRig();

// The two camera images a recording made by writeCodedRecording alternates: a gray table showing a random
// code of amplitude `delta` (seeded), as O+P and O-P.
struct CodedImages {
    cv::Mat positive;
    cv::Mat negative;
};
CodedImages codedImages(const cv::Size& size, int delta, unsigned seed = 7);

// Writes a recording of `frames` frames `intervalUs` apart, alternating polarity, of codedImages() at the
// rig's camera size.
void writeCodedRecording(const std::filesystem::path& directory, const io::RigDescription& rig,
                         std::uint64_t frames, std::int64_t intervalUs);

}  // namespace everytouch::test
