#pragma once

#include <cstddef>
#include <mutex>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace everytouch::service {

// The images of frames the pipeline is done with, given back for the camera thread to write the next frames
// into: a steady stream then allocates no frame memory (a 648 x 488 colour frame is almost a megabyte, 120
// times a second). Safe to use from any thread.
class FramePool {
public:
    explicit FramePool(std::size_t capacity);

    // A buffer to write the next frame into; empty when none is spare.
    cv::Mat take();
    // Keeps `image`'s memory when nothing else shares it (a snapshot's copy, a recording being written) and
    // the pool has room; otherwise it is let go as usual.
    void giveBack(cv::Mat&& image);

    std::size_t spares() const;

private:
    mutable std::mutex mutex_;
    std::vector<cv::Mat> spares_;  // reserved at construction: taking and giving back allocate nothing
    std::size_t capacity_;
};

}  // namespace everytouch::service
